// Interrupting the globemesh executable (a subprocess, by its id) at many points of a run with
// three outputs: afterwards the run's folder holds either nothing at all, or all three outputs
// complete (the signal came after the run had finished). Never one or two of them, never a
// temporary file, whatever the stage the signal lands in: the coast, the mesher, a writer, the
// clean-up of a first signal (SIGINT twice), or the final renames.
#include <gtest/gtest.h>

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "support.hpp"

namespace fs = std::filesystem;
using globemesh::test::expect_mesh_verify;
using globemesh::test::fixture;
using globemesh::test::run_command;
using globemesh::test::TempDir;
using Clock = std::chrono::steady_clock;

namespace {

const std::string exe = GLOBEMESH_EXE;

/// The run: a global mesh of the 1:110m land at 100 km with a UGRID file, a GeoPackage and a
/// preview, written into the folder it runs in (about 45,000 nodes: a second or two).
std::vector<std::string> run_args() {
    return {exe,
            "mesh",
            "--coast",
            fixture("coast/ne_110m_land.gpkg").string(),
            "--coast-layer",
            "land",
            "--hmax",
            "100km",
            "-o",
            "o.nc",
            "--gpkg",
            "o.gpkg",
            "--preview",
            "o.png",
            "-q"};
}

struct Outcome {
    int wstatus = 0;
    std::string err;
};

/// Starts the run in `dir`, sends `signals` (each after its delay from the start, in order),
/// and waits for it to end. Stderr goes to a file beside the folder, not in it.
Outcome interrupt(const fs::path &dir, const std::vector<std::pair<int, double>> &signals) {
    std::vector<std::string> args = run_args();
    std::vector<char *> argv;
    for (auto &a : args)
        argv.push_back(a.data());
    argv.push_back(nullptr);
    const fs::path err_path = dir.parent_path() / (dir.filename().string() + ".err");
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, 1, "/dev/null", O_WRONLY, 0);
    posix_spawn_file_actions_addopen(&actions, 2, err_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC,
                                     0644);
    posix_spawn_file_actions_addchdir_np(&actions, dir.c_str());
    pid_t pid = 0;
    const auto start = Clock::now();
    const int spawned = posix_spawn(&pid, exe.c_str(), &actions, nullptr, argv.data(), environ);
    posix_spawn_file_actions_destroy(&actions);
    EXPECT_EQ(spawned, 0);
    Outcome outcome;
    if (spawned != 0)
        return outcome;
    for (const auto &[signal, at_s] : signals) {
        std::this_thread::sleep_until(start + std::chrono::duration<double>(at_s));
        kill(
            pid,
            signal); // a run that already ended is a zombie until waited for: never another process
    }
    EXPECT_EQ(waitpid(pid, &outcome.wstatus, 0), pid);
    std::stringstream err;
    err << std::ifstream(err_path).rdbuf();
    outcome.err = err.str();
    fs::remove(err_path);
    return outcome;
}

std::set<std::string> files_in(const fs::path &dir) {
    std::set<std::string> names;
    for (const auto &e : fs::directory_iterator(dir))
        names.insert(e.path().filename().string());
    return names;
}

/// The three outputs read by other tools agree: netCDF4's face count is the GeoPackage's
/// (sqlite3), and the PNG ends with its IEND chunk. Fails the test otherwise.
void expect_complete(const fs::path &dir) {
    std::ofstream(dir / ".check.py") << R"(
import netCDF4, sqlite3
nc = netCDF4.Dataset('o.nc')
faces = len(nc.dimensions['nMesh_face'])
gpkg = sqlite3.connect('o.gpkg')
assert gpkg.execute('PRAGMA integrity_check').fetchone()[0] == 'ok'
rows = gpkg.execute('SELECT COUNT(*) FROM faces').fetchone()[0]
png = open('o.png', 'rb').read()
assert png[:8] == b'\x89PNG\r\n\x1a\n' and png[-8:-4] == b'IEND', 'truncated PNG'
print('complete' if faces == rows and faces > 1000 else 'faces %d in the .nc, %d in the .gpkg' % (faces, rows))
)";
    std::string out;
    const int status = run_command("cd '" + dir.string() + "' && /usr/bin/python3 .check.py", out);
    fs::remove(dir / ".check.py");
    EXPECT_EQ(status, 0) << out;
    EXPECT_EQ(out, "complete\n");
}

const std::set<std::string> all_three = {"o.nc", "o.gpkg", "o.png"};

/// What any interrupted run must leave: nothing, or all three outputs complete (status 0).
/// Returns true when it was cancelled.
bool expect_nothing_or_everything(const fs::path &dir, const Outcome &o, const std::string &what) {
    SCOPED_TRACE(what);
    const std::set<std::string> left = files_in(dir);
    if (WIFEXITED(o.wstatus) && WEXITSTATUS(o.wstatus) == 0) {
        EXPECT_EQ(left, all_three) << o.err;
        expect_complete(dir);
        return false;
    }
    EXPECT_TRUE(left.empty()) << "left behind: " << *left.begin() << " (and " << left.size() - 1
                              << " more)";
    if (WIFSIGNALED(o.wstatus)) {
        // Before the handlers were installed, or a second signal: ended by it, nothing written.
        EXPECT_TRUE(WTERMSIG(o.wstatus) == SIGINT || WTERMSIG(o.wstatus) == SIGTERM)
            << WTERMSIG(o.wstatus);
    } else {
        EXPECT_EQ(WEXITSTATUS(o.wstatus), 1) << o.err;
        // One line, the cancellation (cli.hpp: status 1), and no stray progress.
        EXPECT_TRUE(o.err == "globemesh: cancelled, no output written\n" ||
                    o.err == "globemesh: cancelled by SIGTERM, no output written\n")
            << o.err;
    }
    return true;
}

} // namespace

TEST(Interrupt, signals_at_many_points_leave_no_output_or_all_of_them) {
    // The run's length on this machine, uninterrupted; the signals are spread over it.
    TempDir reference;
    const auto start = Clock::now();
    const Outcome whole = interrupt(reference.path(), {});
    const double run_s = std::chrono::duration<double>(Clock::now() - start).count();
    ASSERT_TRUE(WIFEXITED(whole.wstatus) && WEXITSTATUS(whole.wstatus) == 0) << whole.err;
    ASSERT_EQ(files_in(reference.path()), all_three);
    expect_complete(reference.path());
    expect_mesh_verify(reference.path() / "o.nc");

    // Fractions of the run's length, the last ones past its end; SIGINT twice (the second one
    // 1 to 100 ms after the first: during the stop or its clean-up) and SIGTERM at each.
    const double at[] = {0.03, 0.15, 0.3, 0.5, 0.7, 0.9, 1.0, 1.3};
    const double second_after_s[] = {0.001, 0.02, 0.1};
    int cancelled = 0, finished = 0, k = 0;
    for (const double f : at) {
        const double t = f * run_s;
        {
            TempDir dir;
            const double gap = second_after_s[k++ % std::size(second_after_s)];
            const Outcome o = interrupt(dir.path(), {{SIGINT, t}, {SIGINT, t + gap}});
            (expect_nothing_or_everything(dir.path(), o,
                                          "SIGINT twice at " + std::to_string(t) + " s")
                 ? cancelled
                 : finished)++;
        }
        {
            TempDir dir;
            const Outcome o = interrupt(dir.path(), {{SIGTERM, t}});
            (expect_nothing_or_everything(dir.path(), o, "SIGTERM at " + std::to_string(t) + " s")
                 ? cancelled
                 : finished)++;
        }
    }
    // Not asserted (it depends on the machine's load): how the signals fell.
    std::cout << "[  NOTE    ] run " << run_s << " s; " << cancelled << " runs cancelled, "
              << finished << " finished before the signal\n";
}

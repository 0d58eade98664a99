// Test support shared by every test file: fixture paths, a private temporary directory, and the
// independent checker ../shared/tools/mesh-verify. Where an outside tool a test needs is absent,
// the test is marked SKIPPED (ctest lists it), and under CI=true, where every tool must be
// there, it fails instead (tool_missing).
#pragma once

#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>
#include <vector>

namespace globemesh::test {

inline std::filesystem::path fixture(const std::string &rel) {
    return std::filesystem::path(GLOBEMESH_FIXTURES_DIR) / rel;
}

/// A fresh directory under the system temp folder, removed when the object dies.
class TempDir {
public:
    TempDir() {
        auto base = std::filesystem::temp_directory_path();
        std::string tmpl = (base / "globemesh-test-XXXXXX").string();
        if (!mkdtemp(tmpl.data()))
            throw std::runtime_error("mkdtemp failed");
        path_ = tmpl;
    }
    ~TempDir() {
        std::error_code ec;
        std::filesystem::remove_all(path_, ec);
    }
    TempDir(const TempDir &) = delete;
    TempDir &operator=(const TempDir &) = delete;
    const std::filesystem::path &path() const { return path_; }
    std::filesystem::path operator/(const std::string &name) const { return path_ / name; }

private:
    std::filesystem::path path_;
};

/// What the exception E that `f` throws says; a test failure (`what` names the call) and "" when
/// f returns instead. An exception of another type goes on to gtest, which reports it.
template <class E, class F>
std::string thrown_message(F &&f, const std::string &what = "the call") {
    try {
        f();
    } catch (const E &e) {
        return e.what();
    }
    ADD_FAILURE() << what << " threw nothing";
    return "";
}

/// Runs a shell command, returns its exit status and puts stdout+stderr in `output`.
inline int run_command(const std::string &command, std::string &output) {
    output.clear();
    FILE *pipe = popen((command + " 2>&1").c_str(), "r");
    if (!pipe)
        return -1;
    char buffer[4096];
    while (std::fgets(buffer, sizeof buffer, pipe))
        output += buffer;
    int status = pclose(pipe);
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

/// ECMAScript regular expressions (support_regex.cpp, compiled once for every test). True when
/// `pattern` matches part of `text` (regex_search) or all of it (regex_match); the groups of
/// the match go into `groups`, the whole match first.
bool regex_search(const std::string &text, const std::string &pattern,
                  std::vector<std::string> *groups = nullptr);
bool regex_match(const std::string &text, const std::string &pattern,
                 std::vector<std::string> *groups = nullptr);
/// Group `group` of every match of `pattern` in `text`, in order.
std::vector<std::string> regex_all(const std::string &text, const std::string &pattern,
                                   int group = 0);
/// `text` with every match of `pattern` replaced by `with` (std::regex_replace's format).
std::string regex_replace(const std::string &text, const std::string &pattern,
                          const std::string &with);

/// True under CI=true (as CI services set it), where every outside tool the tests use must be
/// installed: a missing one is a failure there, not a skip.
/// `s` in single quotes for the shell (the tests' paths and arguments hold none).
inline std::string shell_quote(const std::string &s) {
    return "'" + s + "'";
}

/// Runs the executable `exe` with `args`: its standard error into `err` (through a file in
/// `dir`), its standard output dropped. Returns the exit status as run_command does.
inline int run_exe_in(const std::string &exe, const std::vector<std::string> &args,
                      std::string &err, const std::filesystem::path &dir) {
    std::string command = shell_quote(exe);
    for (const auto &a : args)
        command += " " + shell_quote(a);
    const std::filesystem::path err_file = dir / ".stderr";
    std::string out;
    const int status =
        run_command("( " + command + " >/dev/null 2>" + shell_quote(err_file.string()) + " )", out);
    std::ifstream e(err_file);
    err.assign(std::istreambuf_iterator<char>(e), {});
    std::filesystem::remove(err_file);
    return status;
}

inline bool in_ci() {
    const char *ci = std::getenv("CI");
    return ci && std::string(ci) == "true";
}

/// `tool` (what is missing, and what the test therefore did not check) is absent: under CI a
/// test failure; elsewhere the running test is marked SKIPPED (from a helper too: its other
/// assertions still count, and a failure among them still fails it).
inline void tool_missing(const std::string &tool) {
    if (in_ci()) {
        ADD_FAILURE() << tool << " is missing, and CI=true requires it";
        return;
    }
    GTEST_SKIP() << tool << " is missing";
}

/// The checker: GLOBEMESH_MESH_VERIFY when set (the tests of the skip point it at a missing
/// file), else ../shared/tools/mesh-verify beside the clone.
inline std::filesystem::path mesh_verify_path() {
    if (const char *path = std::getenv("GLOBEMESH_MESH_VERIFY"))
        return path;
    return std::filesystem::path(GLOBEMESH_SHARED_DIR) / "tools" / "mesh-verify";
}

/// True when the independent checker can run here (the script, and its python modules).
inline bool mesh_verify_available() {
    static int available = -1;
    if (available < 0) {
        std::string out;
        available = std::filesystem::exists(mesh_verify_path()) &&
                    run_command("/usr/bin/python3 -c 'import numpy, scipy, netCDF4'", out) == 0;
    }
    return available == 1;
}

/// Marks the test skipped (a failure under CI) when the checker cannot run; true when it can.
inline bool need_mesh_verify() {
    if (mesh_verify_available())
        return true;
    tool_missing("mesh-verify (" + mesh_verify_path().string() +
                 ", or python3-numpy/scipy/netcdf4)");
    return false;
}

/// Runs mesh-verify on `mesh` with extra arguments; a failed check fails the test with its
/// report. Where the checker is absent the test is marked SKIPPED (need_mesh_verify).
inline void expect_mesh_verify(const std::filesystem::path &mesh, const std::string &args = "") {
    if (!need_mesh_verify())
        return;
    std::string out;
    int status =
        run_command(mesh_verify_path().string() + " " + mesh.string() + " --quiet " + args, out);
    EXPECT_EQ(status, 0) << "mesh-verify rejected " << mesh << ":\n" << out;
}

/// mesh-verify's JSON report on `mesh` (`--json -`, with extra arguments), into `json`; its exit
/// status (0 valid, 1 a check failed), or -1 when the checker is absent (the test then skipped).
inline int mesh_verify_json(const std::filesystem::path &mesh, const std::string &args,
                            std::string &json) {
    json.clear();
    if (!need_mesh_verify())
        return -1;
    return run_command("{ " + mesh_verify_path().string() + " " + mesh.string() + " --json - " +
                           args + " 2>/dev/null; }",
                       json);
}

} // namespace globemesh::test

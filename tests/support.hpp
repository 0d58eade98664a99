// Test support shared by every test file: fixture paths, a private temporary directory, and the
// independent checker ../shared/tools/mesh-verify (run when ../shared is present, as in CI;
// otherwise the test says clearly that it skipped the check).
#pragma once

#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace globemesh::test {

inline std::filesystem::path fixture(const std::string& rel) {
    return std::filesystem::path(GLOBEMESH_FIXTURES_DIR) / rel;
}

/// A fresh directory under the system temp folder, removed when the object dies.
class TempDir {
public:
    TempDir() {
        auto base = std::filesystem::temp_directory_path();
        std::string tmpl = (base / "globemesh-test-XXXXXX").string();
        if (!mkdtemp(tmpl.data())) throw std::runtime_error("mkdtemp failed");
        path_ = tmpl;
    }
    ~TempDir() {
        std::error_code ec;
        std::filesystem::remove_all(path_, ec);
    }
    TempDir(const TempDir&) = delete;
    TempDir& operator=(const TempDir&) = delete;
    const std::filesystem::path& path() const { return path_; }
    std::filesystem::path operator/(const std::string& name) const { return path_ / name; }

private:
    std::filesystem::path path_;
};

/// What the exception E that `f` throws says; a test failure (`what` names the call) and "" when
/// f returns instead. An exception of another type goes on to gtest, which reports it.
template <class E, class F>
std::string thrown_message(F&& f, const std::string& what = "the call") {
    try {
        f();
    } catch (const E& e) {
        return e.what();
    }
    ADD_FAILURE() << what << " threw nothing";
    return "";
}

/// Runs a shell command, returns its exit status and puts stdout+stderr in `output`.
inline int run_command(const std::string& command, std::string& output) {
    output.clear();
    FILE* pipe = popen((command + " 2>&1").c_str(), "r");
    if (!pipe) return -1;
    char buffer[4096];
    while (std::fgets(buffer, sizeof buffer, pipe)) output += buffer;
    int status = pclose(pipe);
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

/// ECMAScript regular expressions (support_regex.cpp, compiled once for every test). True when
/// `pattern` matches part of `text` (regex_search) or all of it (regex_match); the groups of
/// the match go into `groups`, the whole match first.
bool regex_search(const std::string& text, const std::string& pattern, std::vector<std::string>* groups = nullptr);
bool regex_match(const std::string& text, const std::string& pattern, std::vector<std::string>* groups = nullptr);
/// Group `group` of every match of `pattern` in `text`, in order.
std::vector<std::string> regex_all(const std::string& text, const std::string& pattern, int group = 0);
/// `text` with every match of `pattern` replaced by `with` (std::regex_replace's format).
std::string regex_replace(const std::string& text, const std::string& pattern, const std::string& with);

inline std::filesystem::path mesh_verify_path() {
    return std::filesystem::path(GLOBEMESH_SHARED_DIR) / "tools" / "mesh-verify";
}

/// True when the independent checker can run here (../shared beside the clone, python modules).
inline bool mesh_verify_available() {
    static int available = -1;
    if (available < 0) {
        std::string out;
        available = std::filesystem::exists(mesh_verify_path()) &&
                    run_command("/usr/bin/python3 -c 'import numpy, scipy, netCDF4'", out) == 0;
    }
    return available == 1;
}

/// Runs mesh-verify on `mesh` with extra arguments; a failed check fails the test with its
/// report. Where the checker is absent, records a clear skip message (the test goes on).
inline void expect_mesh_verify(const std::filesystem::path& mesh, const std::string& args = "") {
    if (!mesh_verify_available()) {
        std::cout << "[  NOTE    ] mesh-verify SKIPPED: " << mesh_verify_path()
                  << " not found (or python3-numpy/scipy/netcdf4 missing); "
                     "the mesh was not checked independently\n";
        return;
    }
    std::string out;
    int status = run_command(mesh_verify_path().string() + " " + mesh.string() + " --quiet " + args, out);
    EXPECT_EQ(status, 0) << "mesh-verify rejected " << mesh << ":\n" << out;
}

} // namespace globemesh::test

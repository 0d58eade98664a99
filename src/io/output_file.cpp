// Safe output files: see globemesh/output_file.hpp.
#include "globemesh/output_file.hpp"

#include <atomic>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <system_error>

#include <sys/statvfs.h>
#include <unistd.h>

#include "globemesh/error.hpp"

namespace globemesh {
namespace fs = std::filesystem;

namespace {

std::atomic<unsigned> temp_counter{0};

void remove_quietly(const fs::path& p) {
    std::error_code ec;
    fs::remove(p, ec);
}

} // namespace

OutputFile::OutputFile(fs::path target, bool overwrite, std::string what)
    : target_(std::move(target)), overwrite_(overwrite), what_(std::move(what)) {
    if (target_.filename().empty())
        throw IoError(what_ + " " + target_.string() + ": not a file name; give a path to a file");
    fs::path folder = target_.parent_path().empty() ? fs::path(".") : target_.parent_path();
    std::error_code ec;
    if (!fs::is_directory(folder, ec))
        throw IoError(what_ + " " + target_.string() + ": folder " + folder.string() +
                      " does not exist; create it first");
    if (fs::exists(target_, ec) && !overwrite_)
        throw IoError(what_ + " " + target_.string() + " already exists; use --overwrite to replace it");
    if (fs::is_directory(target_, ec))
        throw IoError(what_ + " " + target_.string() + " is a folder; give a file name");
    if (::access(folder.c_str(), W_OK | X_OK) != 0)
        throw IoError(what_ + " " + target_.string() + ": folder " + folder.string() +
                      " is not writable (" + std::strerror(errno) + ")");
    // Hidden, unique per process and call, with the target's extension last so drivers that
    // look at the extension (GDAL's PNG and GPKG) still recognise it.
    std::string name(".");
    name += target_.stem().string();
    name += ".tmp" + std::to_string(::getpid()) + "-" + std::to_string(temp_counter++);
    name += target_.extension().string();
    temp_ = folder / name;
    remove_quietly(temp_);
}

std::string OutputFile::full_disk_note(const fs::path& file) {
    const fs::path folder = file.parent_path().empty() ? fs::path(".") : file.parent_path();
    struct statvfs disk {};
    if (::statvfs(folder.c_str(), &disk) != 0) return "";
    return static_cast<double>(disk.f_bavail) * static_cast<double>(disk.f_frsize) < 1048576.0 ? " (the disk is full)" : "";
}

OutputFile::~OutputFile() {
    if (committed_) return;
    remove_quietly(temp_);
    for (const char* suffix : {".aux.xml", "-journal", "-wal", "-shm"})
        remove_quietly(fs::path(temp_.string() + suffix));
}

void OutputFile::commit() {
    std::error_code ec;
    if (!fs::is_regular_file(temp_, ec))
        throw IoError(what_ + " " + target_.string() + ": the writer produced no file");
    if (!overwrite_) {
        if (::link(temp_.c_str(), target_.c_str()) == 0) {
            remove_quietly(temp_);
            committed_ = true;
            return;
        }
        if (errno == EEXIST)
            throw IoError(what_ + " " + target_.string() + " already exists; use --overwrite to replace it");
        // File systems without hard links: check, then rename.
        if (fs::exists(target_, ec))
            throw IoError(what_ + " " + target_.string() + " already exists; use --overwrite to replace it");
    }
    fs::rename(temp_, target_, ec);
    if (ec) throw IoError(what_ + " " + target_.string() + ": cannot move the finished file in place (" + ec.message() + ")");
    committed_ = true;
}

void OutputFile::write_text(const fs::path& target, const std::string& text, bool overwrite) {
    OutputFile out(target, overwrite);
    {
        std::ofstream f(out.temp_path(), std::ios::binary);
        f << text;
        f.flush();
        if (!f) throw IoError("output " + target.string() + ": write failed" + full_disk_note(target));
    }
    out.commit();
}

} // namespace globemesh

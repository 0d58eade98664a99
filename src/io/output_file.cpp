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

bool OutputFile::is_stream(const fs::path& target) {
    std::error_code ec;
    const fs::file_status s = fs::status(target, ec); // through symbolic links
    return !ec && (s.type() == fs::file_type::character || s.type() == fs::file_type::fifo);
}

OutputFile::OutputFile(fs::path target, bool overwrite, std::string what)
    : target_(std::move(target)), overwrite_(overwrite), what_(std::move(what)) {
    if (target_.filename().empty())
        throw IoError(what_ + " " + target_.string() + ": not a file name; give a path to a file");
    std::error_code ec;
    // Through a symbolic link to the file it names, as GDAL and the shell write (the rename
    // would otherwise replace the link itself: /dev/stdout, a link in /dev, with --overwrite).
    real_ = target_;
    for (int hops = 0; fs::is_symlink(real_, ec) && hops < 40; ++hops) {
        const fs::path to = fs::read_symlink(real_, ec);
        if (ec) break;
        real_ = to.is_absolute() ? to : real_.parent_path() / to;
    }
    fs::path folder = real_.parent_path().empty() ? fs::path(".") : real_.parent_path();
    if (!fs::is_directory(folder, ec))
        throw IoError(what_ + " " + target_.string() + ": folder " + folder.string() +
                      " does not exist; create it first");
    if (fs::is_directory(real_, ec))
        throw IoError(what_ + " " + target_.string() + " is a folder; give a file name");
    if (fs::exists(real_, ec) && !fs::is_regular_file(real_, ec))
        throw IoError(what_ + " " + target_.string() + " is not a regular file (a device, pipe or socket); "
                      "give a file name");
    if (fs::exists(real_, ec) && !overwrite_)
        throw IoError(what_ + " " + target_.string() + " already exists; use --overwrite to replace it");
    if (::access(folder.c_str(), W_OK | X_OK) != 0)
        throw IoError(what_ + " " + target_.string() + ": folder " + folder.string() +
                      " is not writable (" + std::strerror(errno) + ")");
    // Hidden, unique per process and call, with the target's extension last so drivers that
    // look at the extension (GDAL's PNG and GPKG) still recognise it.
    std::string name(".");
    name += real_.stem().string();
    name += ".tmp" + std::to_string(::getpid()) + "-" + std::to_string(temp_counter++);
    name += real_.extension().string();
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
        if (::link(temp_.c_str(), real_.c_str()) == 0) {
            remove_quietly(temp_);
            committed_ = true;
            return;
        }
        if (errno == EEXIST)
            throw IoError(what_ + " " + target_.string() + " already exists; use --overwrite to replace it");
        // File systems without hard links: check, then rename.
        if (fs::exists(real_, ec))
            throw IoError(what_ + " " + target_.string() + " already exists; use --overwrite to replace it");
    }
    fs::rename(temp_, real_, ec);
    if (ec) throw IoError(what_ + " " + target_.string() + ": cannot move the finished file in place (" + ec.message() + ")");
    committed_ = true;
}

void OutputFile::write_text(const fs::path& target, const std::string& text, bool overwrite, const std::string& what) {
    if (is_stream(target)) {
        // A terminal or a pipe (/dev/stdout, /dev/stderr, a named pipe): written as it is.
        std::ofstream f(target, std::ios::binary | std::ios::app);
        f << text;
        f.flush();
        if (!f) throw IoError(what + " " + target.string() + ": write failed");
        return;
    }
    OutputFile out(target, overwrite, what);
    {
        std::ofstream f(out.temp_path(), std::ios::binary);
        f << text;
        f.flush();
        if (!f) throw IoError(what + " " + target.string() + ": write failed" + full_disk_note(target));
    }
    out.commit();
}

} // namespace globemesh

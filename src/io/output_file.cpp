// Safe output files: see globemesh/output_file.hpp.
#include "globemesh/output_file.hpp"

#include <atomic>
#include <cerrno>
#include <climits>
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

constexpr const char *sidecars[] = {".aux.xml", "-journal", "-wal", "-shm"};

void remove_quietly(const fs::path &p) {
    std::error_code ec;
    fs::remove(p, ec);
}

/// The temporary file and its sidecars (GDAL's .aux.xml, SQLite's journals).
void remove_with_sidecars(const fs::path &temp) {
    remove_quietly(temp);
    for (const char *suffix : sidecars)
        remove_quietly(fs::path(temp.string() + suffix));
}

// The temporary names alive, in a fixed table a signal handler can read without allocating:
// a slot is free (0), being changed (1) or holds a name (2); `generation` changes with each
// name, so a reader that raced a change skips the slot.
struct TempSlot {
    std::atomic<int> state{0};
    std::atomic<unsigned> generation{0};
    char path[PATH_MAX];
};
constexpr int slot_count = 64;
TempSlot temp_slots[slot_count];
std::atomic<bool> g_committing{false};
static_assert(std::atomic<int>::is_always_lock_free && std::atomic<bool>::is_always_lock_free);

/// Enters `path` in the table; -1 when it is full or the path too long (then only the
/// destructors remove the file).
int register_temp(const fs::path &path) {
    const std::string &text = path.native();
    if (text.size() + 16 >= PATH_MAX)
        return -1; // room for the longest sidecar suffix
    for (int i = 0; i < slot_count; ++i) {
        int expected = 0;
        if (!temp_slots[i].state.compare_exchange_strong(expected, 1))
            continue;
        std::memcpy(temp_slots[i].path, text.c_str(), text.size() + 1);
        temp_slots[i].generation.fetch_add(1);
        temp_slots[i].state.store(2);
        return i;
    }
    return -1;
}

void unregister_temp(int slot) {
    if (slot < 0)
        return;
    temp_slots[slot].state.store(1);
    temp_slots[slot].generation.fetch_add(1);
    temp_slots[slot].state.store(0);
}

} // namespace

void OutputFile::remove_temporaries() noexcept {
    if (g_committing.load())
        return;
    for (TempSlot &slot : temp_slots) {
        if (slot.state.load() != 2)
            continue;
        const unsigned generation = slot.generation.load();
        char name[PATH_MAX];
        std::memcpy(name, slot.path, sizeof name);
        name[PATH_MAX - 1] = '\0';
        if (slot.state.load() != 2 || slot.generation.load() != generation)
            continue;
        ::unlink(name);
        const std::size_t length = std::strlen(name);
        for (const char *suffix : sidecars) {
            std::memcpy(name + length, suffix, std::strlen(suffix) + 1);
            ::unlink(name);
        }
    }
    // Then the folders a writer created (rmdir fails, harmlessly, on the file names above and
    // on a folder that is not empty).
    for (TempSlot &slot : temp_slots) {
        if (slot.state.load() != 2)
            continue;
        const unsigned generation = slot.generation.load();
        char name[PATH_MAX];
        std::memcpy(name, slot.path, sizeof name);
        name[PATH_MAX - 1] = '\0';
        if (slot.state.load() == 2 && slot.generation.load() == generation)
            ::rmdir(name);
    }
}

bool OutputFile::committing() noexcept {
    return g_committing.load();
}

bool OutputFile::is_stream(const fs::path &target) {
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
        if (ec)
            break;
        real_ = to.is_absolute() ? to : real_.parent_path() / to;
    }
    fs::path folder = real_.parent_path().empty() ? fs::path(".") : real_.parent_path();
    if (!fs::is_directory(folder, ec))
        throw IoError(what_ + " " + target_.string() + ": folder " + folder.string() +
                      " does not exist; create it first");
    if (fs::is_directory(real_, ec))
        throw IoError(what_ + " " + target_.string() + " is a folder; give a file name");
    if (fs::exists(real_, ec) && !fs::is_regular_file(real_, ec))
        throw IoError(what_ + " " + target_.string() +
                      " is not a regular file (a device, pipe or socket); "
                      "give a file name");
    if (fs::exists(real_, ec) && !overwrite_)
        throw IoError(what_ + " " + target_.string() +
                      " already exists; use --overwrite to replace it");
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
    slot_ = register_temp(temp_);
}

std::string OutputFile::full_disk_note(const fs::path &file) {
    const fs::path folder = file.parent_path().empty() ? fs::path(".") : file.parent_path();
    struct statvfs disk {};
    // A file system of no blocks (proc, sysfs) is not full: it holds no files at all.
    if (::statvfs(folder.c_str(), &disk) != 0 || disk.f_blocks == 0)
        return "";
    return static_cast<double>(disk.f_bavail) * static_cast<double>(disk.f_frsize) < 1048576.0
               ? " (the disk is full)"
               : "";
}

OutputFile::~OutputFile() {
    if (committed_)
        return;
    remove_with_sidecars(temp_);
    unregister_temp(slot_);
}

namespace {
thread_local OutputBatch *active_batch = nullptr;
} // namespace

void OutputFile::commit() {
    std::error_code ec;
    if (!fs::is_regular_file(temp_, ec))
        throw IoError(what_ + " " + target_.string() + ": the writer produced no file");
    Finished f{target_, real_, temp_, overwrite_, what_, slot_};
    if (active_batch != nullptr) {
        active_batch->files_.push_back(std::move(f)); // the batch now removes or places it
    } else {
        place(f);
        unregister_temp(slot_);
    }
    committed_ = true;
}

void OutputFile::place(const Finished &f) {
    std::error_code ec;
    if (!f.overwrite) {
        if (::link(f.temp.c_str(), f.real.c_str()) == 0) {
            remove_quietly(f.temp);
            return;
        }
        if (errno == EEXIST)
            throw IoError(f.what + " " + f.target.string() +
                          " already exists; use --overwrite to replace it");
        // File systems without hard links: check, then rename.
        if (fs::exists(f.real, ec))
            throw IoError(f.what + " " + f.target.string() +
                          " already exists; use --overwrite to replace it");
    }
    fs::rename(f.temp, f.real, ec);
    if (ec)
        throw IoError(f.what + " " + f.target.string() +
                      ": cannot move the finished file in place (" + ec.message() + ")");
}

OutputBatch::OutputBatch() : outer_(active_batch) {
    active_batch = this;
}

bool OutputBatch::active() {
    return active_batch != nullptr;
}

OutputBatch::~OutputBatch() {
    active_batch = outer_;
    if (!committed_)
        for (const auto &f : files_) {
            remove_with_sidecars(f.temp);
            unregister_temp(f.slot);
        }
    for (const auto &[folder, slot] : folders_) {
        if (!committed_) {
            std::error_code ec;
            fs::remove(folder, ec); // only when empty: nothing else of the user's goes
        }
        unregister_temp(slot);
    }
}

bool OutputBatch::adopt_folder(const fs::path &folder) {
    if (active_batch == nullptr)
        return false;
    active_batch->folders_.emplace_back(folder, register_temp(folder));
    return true;
}

void OutputBatch::commit(const std::function<bool()> &cancelled) {
    // Held from here to the last file: a signal ending the process now would leave some
    // targets only; SIGKILL still can, in these few system calls.
    struct Committing {
        Committing() { g_committing.store(true); }
        ~Committing() { g_committing.store(false); }
    } committing;
    if (cancelled && cancelled())
        throw Cancelled();
    std::error_code ec;
    for (const auto &f : files_)
        if (!f.overwrite && fs::exists(f.real, ec))
            throw IoError(f.what + " " + f.target.string() +
                          " already exists; use --overwrite to replace it");
    std::size_t placed = 0;
    try {
        for (; placed < files_.size(); ++placed)
            OutputFile::place(files_[placed]);
    } catch (...) {
        for (std::size_t i = 0; i < placed; ++i)
            remove_quietly(files_[i].real);
        throw;
    }
    for (const auto &f : files_)
        unregister_temp(f.slot);
    committed_ = true;
}

void OutputFile::write_text(const fs::path &target, const std::string &text, bool overwrite,
                            const std::string &what) {
    if (is_stream(target)) {
        // A terminal or a pipe (/dev/stdout, /dev/stderr, a named pipe): written as it is.
        std::ofstream f(target, std::ios::binary | std::ios::app);
        f << text;
        f.flush();
        if (!f)
            throw IoError(what + " " + target.string() + ": write failed");
        return;
    }
    OutputFile out(target, overwrite, what);
    {
        std::ofstream f(out.temp_path(), std::ios::binary);
        f << text;
        f.flush();
        if (!f)
            throw IoError(what + " " + target.string() + ": write failed" + full_disk_note(target));
    }
    out.commit();
}

} // namespace globemesh

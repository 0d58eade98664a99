// globemesh/output_file.hpp: safe writing of output files (temporary names, renamed at the end).
//
// An OutputFile reserves a hidden temporary name beside the target (same folder, so the final
// rename is atomic on POSIX file systems). The writer writes to temp_path() and calls commit(),
// which moves the file to the target. If commit() is never reached (an exception, a cancelled
// run), the destructor removes the temporary file and any sidecar files named after it
// (temp + ".aux.xml", "-journal", "-wal", "-shm"), so a failure leaves neither a partial output nor
// a temporary file. An existing target is refused (IoError) unless overwrite is set; without
// overwrite the final step is link()+unlink(), which never replaces a file that appeared meanwhile.
// A process killed by SIGKILL cannot clean up: then only the hidden temporary file remains, never
// a partial target. A target that is a symbolic link is written through it (the link stays);
// one that exists and is not a regular file (a device, a pipe) is refused, except by write_text.
//
// The outputs of one run appear together through an OutputBatch: while one is alive on the
// thread, commit() leaves the finished file under its temporary name, and OutputBatch::commit()
// moves them all at the end. remove_temporaries() is for a signal handler that ends the process.
#pragma once

#include <cstddef>
#include <filesystem>
#include <functional>
#include <string>
#include <utility>
#include <vector>

namespace globemesh {

class OutputFile {
public:
    /// Checks that the target can be written (folder exists, target absent unless overwrite) and
    /// picks a temporary name. `what` names the output in messages (e.g. "UGRID output").
    /// Throws IoError naming the path and what to do.
    OutputFile(std::filesystem::path target, bool overwrite, std::string what = "output");
    ~OutputFile();
    OutputFile(const OutputFile &) = delete;
    OutputFile &operator=(const OutputFile &) = delete;

    /// Where the writer writes; the file does not exist yet when the OutputFile is made.
    const std::filesystem::path &temp_path() const { return temp_; }
    const std::filesystem::path &target() const { return target_; }

    /// Moves the finished temporary file to the target, or hands it to the thread's OutputBatch.
    /// Throws IoError (target appeared without overwrite, rename failed); the temporary file is
    /// then still removed by the destructor.
    void commit();

    /// " (the disk is full)" when the folder of `file` has less than 1 MiB left, else "": for
    /// write errors that do not say so themselves (HDF5's "HDF error", SQLite's missing tables).
    static std::string full_disk_note(const std::filesystem::path &file);

    /// Writes `text` to the target safely in one go (for small reports such as JSON); to a
    /// terminal or pipe (is_stream: /dev/stdout) directly.
    static void write_text(const std::filesystem::path &target, const std::string &text,
                           bool overwrite, const std::string &what = "output");

    /// True when `target` (through symbolic links) is a character device or a named pipe.
    static bool is_stream(const std::filesystem::path &target);

    /// Unlinks every temporary file (and sidecar) of the OutputFiles and OutputBatches alive in
    /// the process, then removes the folders the batches adopted (adopt_folder) when empty.
    /// Async-signal-safe: for a handler that then ends the process. Does nothing while an
    /// OutputBatch moves its files in place (committing()), so that all of them arrive.
    static void remove_temporaries() noexcept;
    /// True while an OutputBatch::commit() moves files to their targets (async-signal-safe).
    static bool committing() noexcept;

private:
    friend class OutputBatch;
    /// Target, temporary name and choices of one finished file, for the final step.
    struct Finished {
        std::filesystem::path target, real, temp;
        bool overwrite;
        std::string what;
        int slot; ///< its entry in the table remove_temporaries() reads, or -1
    };
    static void place(const Finished &f); // the final link or rename; throws IoError

    std::filesystem::path target_, real_, temp_; // real_: target_ through symbolic links
    bool overwrite_;
    std::string what_;
    bool committed_ = false;
    int slot_ = -1;
};

/// The outputs of one run, made to appear together or not at all. While a batch is alive (one
/// per thread), OutputFile::commit() keeps the finished file under its temporary name and hands
/// it to the batch; commit() then moves every file to its target, after checking them all. A
/// batch destroyed before commit() (an error, a cancelled run) removes all the files handed to it,
/// and the folders handed to it that it leaves empty.
class OutputBatch {
public:
    OutputBatch();
    ~OutputBatch();
    OutputBatch(const OutputBatch &) = delete;
    OutputBatch &operator=(const OutputBatch &) = delete;

    /// Throws Cancelled, moving nothing, when `cancelled` (when set) says so once the batch holds
    /// off remove_temporaries(); else moves each file in place. Throws IoError when a target
    /// cannot be written (one appeared without overwrite): the files placed are then removed.
    void commit(const std::function<bool()> &cancelled = {});

    /// True while a batch is alive on this thread (files committed now join it).
    static bool active();

    /// Hands a folder a writer created for its files to this thread's batch, which removes it
    /// (when empty) if the batch ends without commit(), as remove_temporaries() does. False when
    /// no batch is alive: the caller keeps it.
    static bool adopt_folder(const std::filesystem::path &folder);

private:
    friend class OutputFile;
    std::vector<OutputFile::Finished> files_;
    std::vector<std::pair<std::filesystem::path, int>> folders_; ///< created, with their slots
    OutputBatch *outer_ = nullptr;
    bool committed_ = false;
};

} // namespace globemesh

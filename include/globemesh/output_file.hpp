// globemesh/output_file.hpp: safe writing of one output file (temporary name, rename at the end).
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
#pragma once

#include <filesystem>
#include <string>

namespace globemesh {

class OutputFile {
public:
    /// Checks that the target can be written (folder exists, target absent unless overwrite) and
    /// picks a temporary name. `what` names the output in messages (e.g. "UGRID output").
    /// Throws IoError naming the path and what to do.
    OutputFile(std::filesystem::path target, bool overwrite, std::string what = "output");
    ~OutputFile();
    OutputFile(const OutputFile&) = delete;
    OutputFile& operator=(const OutputFile&) = delete;

    /// Where the writer writes; the file does not exist yet when the OutputFile is made.
    const std::filesystem::path& temp_path() const { return temp_; }
    const std::filesystem::path& target() const { return target_; }

    /// Moves the finished temporary file to the target. Throws IoError (target appeared without
    /// overwrite, rename failed); the temporary file is then still removed by the destructor.
    void commit();

    /// " (the disk is full)" when the folder of `file` has less than 1 MiB left, else "": for
    /// write errors that do not say so themselves (HDF5's "HDF error", SQLite's missing tables).
    static std::string full_disk_note(const std::filesystem::path& file);

    /// Writes `text` to the target safely in one go (for small reports such as JSON); to a
    /// terminal or pipe (is_stream: /dev/stdout) directly.
    static void write_text(const std::filesystem::path& target, const std::string& text, bool overwrite,
                           const std::string& what = "output");

    /// True when `target` (through symbolic links) is a character device or a named pipe.
    static bool is_stream(const std::filesystem::path& target);

private:
    std::filesystem::path target_, real_, temp_; // real_: target_ through symbolic links
    bool overwrite_;
    std::string what_;
    bool committed_ = false;
};

} // namespace globemesh

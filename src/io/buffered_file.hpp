// Internal to io/: a file written through a 1 MiB buffer, for the writers that format their own
// bytes (gmsh, ADCIRC/SCHISM, SELAFIN, FESOM2). Failures throw IoError naming the output.
#pragma once

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string>
#include <string_view>
#include <utility>

#include "globemesh/error.hpp"
#include "globemesh/output_file.hpp"

namespace globemesh::io {

class BufferedFile {
public:
    /// Creates `temp` (OutputFile's temporary name, which must not exist yet); `what` and
    /// `target` name the output in messages ("gmsh output", the user's path).
    BufferedFile(const std::filesystem::path &temp, const std::filesystem::path &target,
                 std::string what)
        : file_(std::fopen(temp.c_str(), "wbx")), temp_(temp), target_(target),
          what_(std::move(what)) {
        if (!file_)
            fail("cannot create it");
        buffer_.reserve(capacity + 512);
    }
    ~BufferedFile() {
        if (file_)
            std::fclose(file_);
    }
    BufferedFile(const BufferedFile &) = delete;
    BufferedFile &operator=(const BufferedFile &) = delete;

    /// Appends bytes; the buffer goes to the file when it is full.
    void put(std::string_view bytes) {
        buffer_ += bytes;
        if (buffer_.size() >= capacity)
            flush();
    }
    /// Writes what is left and closes the file.
    void close() {
        flush();
        const bool ok = std::fclose(std::exchange(file_, nullptr)) == 0;
        if (!ok)
            fail("writing failed");
    }

private:
    static constexpr std::size_t capacity = 1 << 20;
    void flush() {
        if (std::fwrite(buffer_.data(), 1, buffer_.size(), file_) != buffer_.size())
            fail("writing failed");
        buffer_.clear();
    }
    [[noreturn]] void fail(const std::string &what) const {
        throw IoError(what_ + " " + target_.string() + ": " + what + " (" + std::strerror(errno) +
                      ")" + OutputFile::full_disk_note(temp_));
    }
    std::FILE *file_;
    std::filesystem::path temp_, target_;
    std::string what_, buffer_;
};

} // namespace globemesh::io

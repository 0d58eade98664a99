// Internal to io/: buffered text output for the text model formats (ADCIRC/SCHISM, FESOM2).
#pragma once

#include <cerrno>
#include <charconv>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string>
#include <string_view>
#include <utility>

#include "globemesh/error.hpp"
#include "globemesh/output_file.hpp"

namespace globemesh::io {

/// Buffered text output to a FILE, numbers formatted with to_chars (shortest exact decimals).
class TextOut {
public:
    TextOut(const std::filesystem::path &temp, const std::filesystem::path &target,
            std::string what)
        : file_(std::fopen(temp.c_str(), "wb")), temp_(temp), target_(target),
          what_(std::move(what)) {
        if (!file_)
            fail("cannot create it");
        buffer_.reserve(capacity + 256);
    }
    ~TextOut() {
        if (file_)
            std::fclose(file_);
    }
    TextOut &text(std::string_view s) {
        buffer_ += s;
        return *this;
    }
    TextOut &integer(std::size_t v) {
        char b[24];
        buffer_.append(b, std::to_chars(b, b + sizeof b, v).ptr);
        return *this;
    }
    TextOut &real(double v) {
        char b[400];
        buffer_.append(b, std::to_chars(b, b + sizeof b, v, std::chars_format::fixed).ptr);
        return *this;
    }
    /// Ends a line, writing the buffer out when it is full.
    void line() {
        buffer_ += '\n';
        if (buffer_.size() >= capacity)
            flush();
    }
    void close() {
        flush();
        const bool ok = std::fclose(file_) == 0;
        file_ = nullptr;
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
    [[noreturn]] void fail(const std::string &what) {
        throw IoError(what_ + " " + target_.string() + ": " + what + " (" + std::strerror(errno) +
                      ")" + OutputFile::full_disk_note(temp_));
    }
    std::FILE *file_;
    std::filesystem::path temp_, target_;
    std::string what_, buffer_;
};

} // namespace globemesh::io

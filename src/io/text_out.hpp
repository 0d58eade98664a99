// Internal to io/: text lines for the text model formats (ADCIRC/SCHISM, FESOM2).
#pragma once

#include <charconv>
#include <filesystem>
#include <string>
#include <string_view>
#include <utility>

#include "buffered_file.hpp"

namespace globemesh::io {

/// Buffered text output, numbers formatted with to_chars (shortest exact decimals).
class TextOut {
public:
    TextOut(const std::filesystem::path &temp, const std::filesystem::path &target,
            std::string what)
        : file_(temp, target, std::move(what)) {}
    TextOut &text(std::string_view s) {
        file_.put(s);
        return *this;
    }
    TextOut &integer(std::size_t v) {
        char b[24];
        file_.put({b, std::to_chars(b, b + sizeof b, v).ptr});
        return *this;
    }
    TextOut &real(double v) {
        char b[400];
        file_.put({b, std::to_chars(b, b + sizeof b, v, std::chars_format::fixed).ptr});
        return *this;
    }
    void line() { file_.put("\n"); }
    void close() { file_.close(); }

private:
    BufferedFile file_;
};

} // namespace globemesh::io

// Internal to io/: the lines of a text mesh format as words, for the ADCIRC and gmsh readers.
#pragma once

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>
#include <vector>

#include "globemesh/error.hpp"

namespace globemesh::io {

/// The file's lines as words, with the line number for messages.
class Lines {
public:
    /// `what` names the format in messages (e.g. "gmsh file"); a line ends at `comment`.
    Lines(const std::filesystem::path &path, std::string what, char comment)
        : path_(path), what_(std::move(what)), comment_(comment), in_(path) {
        if (!in_)
            throw IoError(what_ + " " + path.string() + ": cannot open; give an existing file");
    }
    [[noreturn]] void fail(const std::string &what) const {
        throw DataError(what_ + " " + path_.string() + ": line " + std::to_string(line_) + ": " +
                        what);
    }
    /// The next line's words (before any comment character); false at the end of the file.
    bool next(std::vector<std::string_view> &words) {
        if (!std::getline(in_, text_))
            return false;
        ++line_;
        words.clear();
        const std::string_view s(text_.data(), std::min(text_.find(comment_), text_.size()));
        for (std::size_t i = 0; i < s.size();) {
            while (i < s.size() && std::isspace(static_cast<unsigned char>(s[i])))
                ++i;
            std::size_t j = i;
            while (j < s.size() && !std::isspace(static_cast<unsigned char>(s[j])))
                ++j;
            if (j > i)
                words.push_back(s.substr(i, j - i));
            i = j;
        }
        return true;
    }
    /// The next line's words; fails at the end of the file or when it has fewer than `n`.
    const std::vector<std::string_view> &need(std::size_t n, const char *what) {
        if (!next(words_))
            fail(std::string("the file ends where ") + what + " should be");
        if (words_.size() < n)
            fail(std::string("expected ") + what);
        return words_;
    }
    long long integer(std::string_view w, const char *what) const {
        long long v = 0;
        const auto r = std::from_chars(w.data(), w.data() + w.size(), v);
        if (r.ec != std::errc() || r.ptr != w.data() + w.size())
            fail(std::string(what) + " '" + std::string(w) + "' is not an integer");
        return v;
    }
    double number(std::string_view w, const char *what) const {
        std::string s(w); // from_chars for double is missing from some standard libraries
        std::replace(s.begin(), s.end(), 'D', 'E');
        std::replace(s.begin(), s.end(), 'd', 'e');
        char *end = nullptr;
        const double v = std::strtod(s.c_str(), &end);
        if (end != s.c_str() + s.size() || !std::isfinite(v))
            fail(std::string(what) + " '" + s + "' is not a number");
        return v;
    }
    /// `n` raw bytes from where the last line ended (a binary section's data).
    void bytes(void *out, std::size_t n, const char *what) {
        if (!in_.read(static_cast<char *>(out), static_cast<std::streamsize>(n)))
            fail(std::string("the file ends where ") + what + " should be");
    }
    /// A count of at most `max`.
    std::size_t count(std::string_view w, const char *what, long long max = 1LL << 31) const {
        const long long v = integer(w, what);
        if (v < 0 || v > max)
            fail(std::string(what) + " " + std::to_string(v) + " is out of range");
        return std::size_t(v);
    }

private:
    std::filesystem::path path_;
    std::string what_;
    char comment_;
    std::ifstream in_;
    std::string text_;
    std::vector<std::string_view> words_;
    std::size_t line_ = 0;
};

/// The extension of `path` in lower case, with its dot (".msh"): how the readers are chosen.
inline std::string lower_extension(const std::filesystem::path &path) {
    std::string ext = path.extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    return ext;
}

} // namespace globemesh::io

// globemesh/error.hpp: the exceptions the library throws.
//
// Every message says what went wrong, where (file, layer, option) and, where it helps, what to
// do. A message names options by their MeshOptions field (hmax_km); it keeps them apart from
// the rest of its text (ErrorText), so that a caller with other names for them (the command
// line's --hmax) can say the message in its own words: Error::message(names). what() is the
// message with the field names.
#pragma once

#include <functional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace globemesh {

/// A caller's name for an option, from the option's MeshOptions field name.
using OptionNames = std::function<std::string(std::string_view field)>;

/// The text of an error message, with the options it names kept as their field names.
class ErrorText {
public:
    ErrorText(std::string text) { parts_.push_back({false, std::move(text)}); }
    ErrorText(const char *text) : ErrorText(std::string(text)) {}
    /// The option of MeshOptions field `field` (e.g. "hmax_km"), named as the reader calls it.
    static ErrorText option(std::string field) {
        ErrorText t("");
        t.parts_.back() = {true, std::move(field)};
        return t;
    }
    ErrorText &operator+=(const ErrorText &more) {
        parts_.insert(parts_.end(), more.parts_.begin(), more.parts_.end());
        return *this;
    }
    friend ErrorText operator+(ErrorText a, const ErrorText &b) { return a += b; }
    /// The text, each option named by names(field), or by its field name when names is empty.
    std::string str(const OptionNames &names = {}) const {
        std::string s;
        for (const auto &[is_option, text] : parts_)
            s += is_option && names ? names(text) : text;
        return s;
    }
    /// The field name of the option the text begins with, or "".
    std::string leading_option() const {
        return parts_.front().first ? parts_.front().second : std::string();
    }
    /// The text after its leading option and the space that follows it (for a caller that
    /// names the option itself in front of the message).
    ErrorText after_leading_option() const {
        ErrorText rest = *this;
        if (!rest.parts_.front().first)
            return rest;
        rest.parts_.erase(rest.parts_.begin());
        if (rest.parts_.empty())
            return ErrorText("");
        if (auto &[is_option, text] = rest.parts_.front();
            !is_option && !text.empty() && text[0] == ' ')
            text.erase(0, 1);
        return rest;
    }

private:
    std::vector<std::pair<bool, std::string>> parts_; ///< (is an option's field name, text)
};

/// Shorthand for ErrorText::option in messages: option("hmax_km") + " must be positive".
inline ErrorText option(std::string field) {
    return ErrorText::option(std::move(field));
}

/// Base of every error globemesh throws on purpose.
class Error : public std::runtime_error {
public:
    Error(ErrorText text) : std::runtime_error(text.str()), text_(std::move(text)) {}
    /// The message with each option named by `names` (what() names the fields).
    std::string message(const OptionNames &names) const { return text_.str(names); }
    const ErrorText &text() const { return text_; }

private:
    ErrorText text_;
};

/// The caller asked for something invalid: a bad option value, a missing required option.
class UsageError : public Error {
public:
    using Error::Error;
};

/// The input data cannot give a mesh: no CRS, empty layer, no ocean in the region, too few points.
class DataError : public Error {
public:
    using Error::Error;
};

/// Reading or writing a file failed: missing, unreadable, unwritable, existing output.
class IoError : public Error {
public:
    using Error::Error;
};

/// The user cancelled through the progress callback (Ctrl-C in the CLI).
class Cancelled : public Error {
public:
    Cancelled() : Error("cancelled") {}
};

} // namespace globemesh

// The helpers of cli_common.hpp: CLI11 transforms and error wording, the history line.
#include <algorithm>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <ctime>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include <gdal.h>

#include "cli_common.hpp"
#include "cli_support.hpp"
#include "globemesh/error.hpp"

namespace globemesh::cli {

std::string version_text() {
    return std::string("globemesh ") + GLOBEMESH_VERSION + " (GDAL " +
           GDALVersionInfo("RELEASE_NAME") + ")";
}

/// Shortest text that reads back as the same double.
std::string exact_text(double v) {
    char buffer[32];
    auto [end, ec] = std::to_chars(buffer, buffer + sizeof buffer, v);
    return std::string(buffer, end);
}

/// A CLI11 transform that turns "20km" into "20" (the field's unit), so the bound field, the
/// --help default and --print-config all speak the field's unit.
CLI::Validator unit_transform(double (*parse)(std::string_view), const std::string &name) {
    return CLI::Validator(
        [parse](std::string &value) -> std::string {
            try {
                value = exact_text(parse(value));
                return {};
            } catch (const UsageError &e) {
                return e.what();
            }
        },
        name);
}

/// A CLI11 transform for a count: a whole number, also written as 2e7 (CLI11 alone refuses that
/// with "Could not convert").
CLI::Validator count_transform() {
    return CLI::Validator(
        [](std::string &value) -> std::string {
            char *end = nullptr;
            const double v = std::strtod(value.c_str(), &end);
            if (value.empty() || *end != '\0' || !(v >= 0 && v <= 9.007199254740992e15) ||
                v != std::floor(v))
                return "'" + value + "' is not a whole number, e.g. 20000000 or 2e7";
            value = std::to_string(static_cast<std::uint64_t>(v));
            return {};
        },
        "");
}

/// CLI11 wants the arguments in reverse order.
std::vector<std::string> reversed(std::span<const std::string> args) {
    return std::vector<std::string>(args.rbegin(), args.rend());
}

/// One line: newlines of multi-line messages (CLI11's) become "; ".
std::string one_line(std::string message) {
    while (!message.empty() && (message.back() == '\n' || message.back() == ' '))
        message.pop_back();
    std::string r;
    for (char c : message) {
        if (c == '\n')
            r += "; ";
        else
            r += c;
    }
    return r;
}

/// CLI11's parse errors in the words of the rest of globemesh's messages, for `command` (mesh,
/// info, triangulate; empty at the top level): an option given twice, an option without its
/// value, an unknown option, a stray argument.
std::string usage_text(const CLI::ParseError &e, const std::string &command) {
    const std::string what = one_line(e.what());
    const std::string help =
        command.empty() ? "globemesh --help" : "globemesh " + command + " --help";
    const std::size_t colon = what.find(": ");
    if (dynamic_cast<const CLI::ArgumentMismatch *>(&e) && colon != std::string::npos) {
        // "NAME: At Most N required but received M", "NAME: At least N required but received
        // M", "NAME: N required TYPE missing" (CLI11 2.3's words).
        const std::string name = what.substr(0, colon);
        std::istringstream rest(what.substr(colon + 2));
        std::vector<std::string> w;
        for (std::string x; rest >> x;)
            w.push_back(x);
        // N counts values, not uses: a single value given twice, or --region's 4 given 5; a
        // multiple of N is the option given again as often as not (--region twice: 8 values).
        if (w.size() == 7 && w[0] == "At" && w[1] == "Most" && w[3] == "required" &&
            w[5] == "received") {
            if (w[2] == "1")
                return name + " is given " + w[6] + " times; give it once";
            const bool multiple =
                std::atoi(w[6].c_str()) % std::max(1, std::atoi(w[2].c_str())) == 0;
            return name + " takes " + w[2] + " values, got " + w[6] +
                   (multiple ? "; give it once, with " + w[2] : "");
        }
        if (w.size() == 7 && w[0] == "At" && w[1] == "least" && w[3] == "required" &&
            w[5] == "received")
            return name + " needs " + w[2] + " values, got " + w[6];
        if (w.size() == 4 && w[1] == "required" && w[3] == "missing")
            return name + " needs a value (" + w[2] + ")";
    }
    if (dynamic_cast<const CLI::ExtrasError *>(&e)) {
        // "The following argument(s) was/were not expected: A B": options first.
        std::istringstream words(colon == std::string::npos ? std::string()
                                                            : what.substr(colon + 2));
        std::vector<std::string> options, others;
        for (std::string w; words >> w;)
            (w.size() > 1 && w[0] == '-' ? options : others).push_back(w);
        std::string list;
        for (const auto &w : options.empty() ? others : options)
            list += (list.empty() ? "" : ", ") + w;
        const std::string where = command.empty() ? "" : " for globemesh " + command;
        if (!options.empty())
            return std::string(options.size() > 1 ? "unknown options " : "unknown option ") + list +
                   where + " (" + help + " lists them)";
        return std::string(others.size() > 1 ? "unexpected arguments " : "unexpected argument ") +
               list + where + " (a value goes after its option's name, e.g. --coast land.shp; " +
               help + ")";
    }
    if (dynamic_cast<const CLI::RequiredError *>(&e))
        return what + " (" + help + ")";
    // "Could not convert: NAME = VALUE": a word for a number, or a number past its type's range.
    const std::string convert = "Could not convert: ";
    if (const std::size_t eq = what.find(" = "); dynamic_cast<const CLI::ConversionError *>(&e) &&
                                                 what.rfind(convert, 0) == 0 &&
                                                 eq != std::string::npos) {
        const std::string name = what.substr(convert.size(), eq - convert.size()),
                          value = what.substr(eq + 3);
        const bool number =
            !value.empty() && value.find_first_not_of("-+0123456789") == std::string::npos;
        return name + ": '" + value + "' is " +
               (number ? "out of its range" : "not a value it takes") + " (" + help +
               " gives the kind of value it takes)";
    }
    return what;
}

std::string file_configuration(const std::string &config) {
    std::string out;
    std::size_t start = 0;
    while (start < config.size()) {
        const std::size_t end = std::min(config.find('\n', start), config.size());
        const std::string line = config.substr(start, end - start);
        if (line.rfind("threads=", 0) != 0 && line != "parts=0")
            out += line + (end < config.size() ? "\n" : "");
        start = end + 1;
    }
    return out;
}

/// The command line for the `history` attribute, with the date (UTC).
std::string history_text(const std::string &sub, std::span<const std::string> args) {
    std::time_t now = std::time(nullptr);
    std::tm tm{};
    gmtime_r(&now, &tm);
    char date[32];
    std::strftime(date, sizeof date, "%Y-%m-%dT%H:%M:%SZ", &tm);
    std::string command = "globemesh " + sub;
    for (const auto &a : args) {
        const bool plain = !a.empty() && a.find_first_of(" \t'\"\\$`") == std::string::npos;
        if (plain) {
            command += " " + a;
            continue;
        }
        std::string quoted = "'"; // POSIX shell quoting: ' becomes '\''
        for (char c : a)
            quoted += c == '\'' ? std::string("'\\''") : std::string(1, c);
        command += " " + quoted + "'";
    }
    return std::string(date) + ": " + command;
}

void throw_if_interrupted() {
    if (InterruptGuard::interrupted())
        throw Cancelled();
}

double seconds_since(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

} // namespace globemesh::cli

// Values with units at the command line, converted once into the units of MeshOptions.
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <string>
#include <string_view>

#include "cli_support.hpp"
#include "globemesh/cli.hpp"
#include "globemesh/error.hpp"

namespace globemesh {

namespace {

struct Unit {
    std::string_view name;
    double factor; ///< multiply a value in this unit by factor to get the base unit
};

std::string_view trim(std::string_view s) {
    while (!s.empty() && std::isspace(static_cast<unsigned char>(s.front())))
        s.remove_prefix(1);
    while (!s.empty() && std::isspace(static_cast<unsigned char>(s.back())))
        s.remove_suffix(1);
    return s;
}

/// Parses "<number>[ ]<unit>" where unit is one of `units` (case-sensitive, as SI writes
/// them) or absent (then the first entry, the base unit, applies).
double parse_quantity(std::string_view text, std::initializer_list<Unit> units,
                      std::string_view example) {
    std::string_view s = trim(text);
    double value = 0;
    const char *first = s.data();
    const char *last = s.data() + s.size();
    if (!s.empty() && *first == '+')
        ++first; // from_chars refuses a leading '+'
    auto [end, ec] = std::from_chars(first, last, value);
    if (ec != std::errc() || s.empty()) {
        throw UsageError("'" + std::string(text) + "' is not a number with a unit (e.g. " +
                         std::string(example) + ")");
    }
    if (!std::isfinite(value)) {
        throw UsageError("'" + std::string(text) + "' is not a finite number");
    }
    std::string_view unit = trim(std::string_view(end, static_cast<std::size_t>(last - end)));
    if (unit.empty())
        return value * units.begin()->factor;
    std::string known;
    for (const Unit &u : units) {
        if (unit == u.name)
            return value * u.factor;
        known += (known.empty() ? "" : ", ") + std::string(u.name);
    }
    throw UsageError("unknown unit '" + std::string(unit) + "' in '" + std::string(text) +
                     "' (use " + known + ", e.g. " + std::string(example) + ")");
}

} // namespace

double parse_length_km(std::string_view text) {
    return parse_quantity(text, {{"km", 1.0}, {"m", 1e-3}}, "20km or 5000m");
}

double parse_area_km2(std::string_view text) {
    return parse_quantity(text, {{"km2", 1.0}, {"m2", 1e-6}}, "1000km2 or 1e6m2");
}

double parse_duration_h(std::string_view text) {
    return parse_quantity(text, {{"h", 1.0}, {"min", 1.0 / 60}, {"s", 1.0 / 3600}}, "12.42h");
}

double parse_depth_m(std::string_view text) {
    return parse_quantity(text, {{"m", 1.0}, {"km", 1e3}}, "50m");
}

namespace cli {

std::uint64_t parse_memory_bytes(std::string_view text) {
    const double bytes = parse_quantity(text,
                                        {{"B", 1.0},
                                         {"kB", 1e3},
                                         {"MB", 1e6},
                                         {"GB", 1e9},
                                         {"TB", 1e12},
                                         {"KiB", 1024.0},
                                         {"MiB", 1048576.0},
                                         {"GiB", 1073741824.0},
                                         {"TiB", 1099511627776.0}},
                                        "4GB or 500MB");
    // 2^63: far beyond any machine, and exactly representable.
    if (bytes < 0 || bytes >= 9223372036854775808.0)
        throw UsageError("'" + std::string(text) +
                         "' is not a memory size (e.g. 4GB or 500MB; 0: no limit)");
    return static_cast<std::uint64_t>(std::llround(bytes));
}

} // namespace cli

} // namespace globemesh

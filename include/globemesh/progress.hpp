// globemesh/progress.hpp: progress reporting and cancellation, as GDAL's GDALProgressFunc.
//
// A Progress is called with a fraction in [0, 1] and a short stage name; returning false asks the
// library to stop, which it does by throwing globemesh::Cancelled at the next check. An empty
// Progress reports nothing.
#pragma once

#include <functional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "globemesh/error.hpp"

namespace globemesh {

using Progress = std::function<bool(double fraction, std::string_view stage)>;

/// A Progress that maps [0, 1] of a sub-stage onto [lo, hi] of the parent (GDAL's scaled progress).
inline Progress sub_progress(const Progress &parent, double lo, double hi) {
    if (!parent)
        return {};
    return [parent, lo, hi](double f, std::string_view stage) {
        return parent(lo + (hi - lo) * f, stage);
    };
}

/// Reports f to p (when set) and throws Cancelled when the callback asks to stop.
inline void report(const Progress &p, double f, std::string_view stage) {
    if (p && !p(f, stage))
        throw Cancelled();
}

/// Seconds per named stage, in the order the stages ran.
struct StageTimings {
    std::vector<std::pair<std::string, double>> stages;
    /// Seconds of the stages that read the run's input files (added with add_input; they are
    /// in `stages` too): the rest is the computing.
    double input_seconds = 0;
    void add(const std::string &name, double seconds) { stages.emplace_back(name, seconds); }
    /// Adds `seconds` to the stage `name`, appended when it is new (the writers of one format,
    /// the parts' stages).
    void add_to(const std::string &name, double seconds) {
        for (auto &[stage, s] : stages)
            if (stage == name) {
                s += seconds;
                return;
            }
        add(name, seconds);
    }
    /// A stage that reads input files (the coast, the bathymetry, the points).
    void add_input(const std::string &name, double seconds) {
        add(name, seconds);
        input_seconds += seconds;
    }
    /// Seconds of every stage that is not reading the inputs.
    double compute_seconds() const {
        double total = 0;
        for (const auto &stage : stages)
            total += stage.second;
        return total - input_seconds;
    }
};

} // namespace globemesh

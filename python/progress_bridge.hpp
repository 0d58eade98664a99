// Private to python/: the library's Progress, called with the GIL released, as a Python
// callback(fraction, stage) and a check for KeyboardInterrupt (PyErr_CheckSignals).
#pragma once

#include <chrono>
#include <exception>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>

#include <pybind11/pybind11.h>

#include "gdal_warnings.hpp"
#include "globemesh/progress.hpp"

namespace globemesh::python {

namespace py = pybind11;

/// Lives on the stack of the bound call, which holds the GIL when it makes and destroys it; the
/// Progress it gives captures only a pointer to it, so the library may copy that freely.
class ProgressBridge {
public:
    /// Whether a callback's return is False: Python's, or numpy's (np.False_), not None or 0.
    static bool is_false(const py::object &r) {
        const bool boolean = PyBool_Check(r.ptr()) ||
                             (py::hasattr(r, "dtype") && py::hasattr(r.attr("dtype"), "kind") &&
                              py::str(r.attr("dtype").attr("kind")).cast<std::string>() == "b");
        return boolean && PyObject_IsTrue(r.ptr()) == 0;
    }

    /// `callback`: None, or a callable(fraction, stage) whose False return cancels.
    explicit ProgressBridge(py::object callback) : callback_(std::move(callback)) {}

    Progress progress() {
        return [this](double f, std::string_view stage) { return update(f, stage); };
    }

    /// With the GIL: after the library returned or threw, raises the Python exception that
    /// stopped the run (KeyboardInterrupt, the callback's own), if one did.
    void raise_if_stopped() {
        if (error_) {
            error_->restore();
            error_.reset();
            throw py::error_already_set();
        }
    }

private:
    /// Called by the library, GIL released, from any of its threads. Python is reached at most
    /// every 50 ms (and at the end): taking the GIL on every tick would cost the run.
    bool update(double f, std::string_view stage) {
        std::lock_guard lock(mutex_);
        const auto now = std::chrono::steady_clock::now();
        if (f < 1 && now - last_ < std::chrono::milliseconds(50))
            return !stopped_;
        last_ = now;
        if (stopped_)
            return false;
        py::gil_scoped_acquire gil;
        try {
            if (PyErr_CheckSignals() != 0)
                throw py::error_already_set();
            if (!callback_.is_none() && is_false(callback_(f, std::string(stage))))
                stopped_ = true; // Cancelled reaches the caller as globemesh.Cancelled
        } catch (py::error_already_set &e) {
            error_.emplace(std::move(e));
            stopped_ = true;
        }
        return !stopped_;
    }

    py::object callback_;
    std::mutex mutex_;
    std::chrono::steady_clock::time_point last_{};
    bool stopped_ = false;
    std::optional<py::error_already_set> error_;
};

/// Runs `job` with the GIL released and `bridge`'s progress; then, with the GIL, gives GDAL's
/// warnings to Python and raises what stopped it from Python (before any library error a
/// stopped run threw), or the library's error.
template <class Job> auto run_without_gil(ProgressBridge &bridge, Job &&job) {
    std::exception_ptr failure;
    decltype(job(bridge.progress())) result{};
    GdalWarnings warnings;
    {
        py::gil_scoped_release release;
        try {
            result = job(bridge.progress());
        } catch (...) {
            failure = std::current_exception();
        }
    }
    bridge.raise_if_stopped();
    warnings.warn();
    if (failure)
        std::rethrow_exception(failure);
    return result;
}

} // namespace globemesh::python

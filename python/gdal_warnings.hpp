// Private to python/: GDAL's warnings during a run, as Python warnings (globemesh.GdalWarning)
// instead of GDAL's default handler printing them on stderr.
#pragma once

#include <mutex>
#include <string>
#include <vector>

#include <cpl_error.h>
#include <pybind11/pybind11.h>

namespace globemesh::python {

namespace py = pybind11;

/// The Python class of GDAL's warnings (a UserWarning), set when the module loads.
inline py::object &gdal_warning_class() {
    static py::object cls;
    return cls;
}

/// The Python class of the run's own warnings (the command line's on stderr; a UserWarning).
inline py::object &mesh_warning_class() {
    static py::object cls;
    return cls;
}

/// Each of a run's warnings through warnings.warn, with the GIL (raises if a filter makes it an
/// error).
inline void warn_run(const std::vector<std::string> &warnings) {
    for (const std::string &w : warnings)
        if (PyErr_WarnEx(mesh_warning_class().ptr(), w.c_str(), 1) != 0)
            throw py::error_already_set();
}

/// Collects GDAL's warnings on this thread (where the run calls GDAL) while it lives, GIL
/// released; warn() then gives them to Python, with the GIL. GDAL's errors are not warnings: the
/// library turns them into its exceptions, as the command line does.
class GdalWarnings {
public:
    GdalWarnings() { CPLPushErrorHandlerEx(&GdalWarnings::handler, this); }
    ~GdalWarnings() { CPLPopErrorHandler(); }
    GdalWarnings(const GdalWarnings &) = delete;
    GdalWarnings &operator=(const GdalWarnings &) = delete;

    /// With the GIL: each warning through warnings.warn (raises if a filter makes it an error).
    void warn() {
        std::vector<std::string> messages;
        {
            std::lock_guard lock(mutex_);
            messages.swap(messages_);
        }
        for (const std::string &m : messages)
            if (PyErr_WarnEx(gdal_warning_class().ptr(), ("GDAL: " + m).c_str(), 1) != 0)
                throw py::error_already_set();
    }

private:
    static void CPL_STDCALL handler(CPLErr level, CPLErrorNum, const char *message) {
        auto *self = static_cast<GdalWarnings *>(CPLGetErrorHandlerUserData());
        if (self && level == CE_Warning) {
            std::lock_guard lock(self->mutex_);
            self->messages_.emplace_back(message);
        }
    }
    std::mutex mutex_;
    std::vector<std::string> messages_;
};

} // namespace globemesh::python

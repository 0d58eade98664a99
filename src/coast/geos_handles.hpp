// Internal to the coast module: a GEOS context that keeps GEOS's last error message, and the one
// owner type for the handles made in it (geometries, prepared geometries, STR trees).
#pragma once

#include <memory>
#include <string>

#include <geos_c.h>

#include "geos_interrupt.hpp"
#include "globemesh/error.hpp"

namespace globemesh::coast_detail {

/// A GEOS context whose error handler keeps the last message.
class Geos {
public:
    Geos() : h_(GEOS_init_r()) { GEOSContext_setErrorMessageHandler_r(h_, &Geos::on_error, this); }
    ~Geos() { GEOS_finish_r(h_); }
    Geos(const Geos &) = delete;
    Geos &operator=(const Geos &) = delete;
    GEOSContextHandle_t get() const { return h_; }
    const std::string &message() const { return message_; }

private:
    static void on_error(const char *message, void *self) {
        static_cast<Geos *>(self)->message_ = message ? message : "";
    }
    GEOSContextHandle_t h_;
    std::string message_;
};

/// Destroys a GEOS handle with the destructor GEOS has for its type, in the context it was made in
/// (std::unique_ptr never passes null to its deleter).
struct GeosDeleter {
    GEOSContextHandle_t ctx;
    void operator()(GEOSGeometry *g) const { GEOSGeom_destroy_r(ctx, g); }
    void operator()(const GEOSPreparedGeometry *g) const { GEOSPreparedGeom_destroy_r(ctx, g); }
    void operator()(GEOSSTRtree *t) const { GEOSSTRtree_destroy_r(ctx, t); }
};
/// The owner of a GEOS handle: GeosPtr<T>{handle, GeosDeleter{context}}.
template <class T> using GeosPtr = std::unique_ptr<T, GeosDeleter>;
using GeomPtr = GeosPtr<GEOSGeometry>;
using PreparedPtr = GeosPtr<const GEOSPreparedGeometry>;
using TreePtr = GeosPtr<GEOSSTRtree>;

/// Takes ownership of what a GEOS call returned: throws Cancelled when the run was cancelled (GEOS
/// was interrupted, and g may be null), else DataError naming `what` when g is null.
inline GeomPtr own(Geos &geos, GEOSGeometry *g, const char *what) {
    GeomPtr owned(g, GeosDeleter{geos.get()});
    coast::GeosInterrupt::poll();
    if (!g)
        throw DataError(std::string("coast: GEOS failed to ") + what + ": " + geos.message());
    return owned;
}

/// A copy of g, owned.
inline GeomPtr clone(Geos &geos, const GEOSGeometry *g, const char *what = "copy a polygon") {
    return own(geos, GEOSGeom_clone_r(geos.get(), g), what);
}

} // namespace globemesh::coast_detail

// GEOS's interrupt tied to a run's progress (coast::GeosInterrupt): a GEOS union in progress
// stops when the progress asks to, the failure reads as the cancellation, and GEOS works as
// before once the scope is gone.
#include <gtest/gtest.h>

#include <geos_c.h>

#include <chrono>
#include <memory>
#include <thread>
#include <vector>

#include "geos_interrupt.hpp"

using globemesh::Cancelled;
using globemesh::Progress;
using globemesh::coast::GeosInterrupt;

namespace {

struct Context {
    GEOSContextHandle_t h = GEOS_init_r();
    ~Context() { GEOS_finish_r(h); }
};

/// 60 x 60 overlapping discs: their union takes GEOS many interrupt checks.
GEOSGeometry *discs(const Context &c) {
    std::vector<GEOSGeometry *> parts;
    for (int i = 0; i < 60; ++i) {
        for (int j = 0; j < 60; ++j) {
            GEOSGeometry *point =
                GEOSGeom_createPointFromXY_r(c.h, i * 0.7 + 0.01 * j, j * 0.7 + 0.01 * i);
            parts.push_back(GEOSBuffer_r(c.h, point, 0.5, 8));
            GEOSGeom_destroy_r(c.h, point);
        }
    }
    return GEOSGeom_createCollection_r(c.h, GEOS_MULTIPOLYGON, parts.data(),
                                       static_cast<unsigned>(parts.size()));
}

/// The union of `g`, or null when GEOS failed (was interrupted).
std::unique_ptr<GEOSGeometry, void (*)(GEOSGeometry *)> union_of(const Context &c,
                                                                 const GEOSGeometry *g) {
    static thread_local GEOSContextHandle_t h;
    h = c.h;
    return {GEOSUnaryUnion_r(c.h, g), [](GEOSGeometry *p) {
                if (p)
                    GEOSGeom_destroy_r(h, p);
            }};
}

} // namespace

TEST(GeosInterrupt, a_union_stops_when_the_progress_asks_and_reads_as_cancelled) {
    Context c;
    GEOSGeometry *all = discs(c);
    int asked = 0;
    {
        const GeosInterrupt scope(
            [&](double, std::string_view) { return ++asked < 0; }); // always "stop"
        EXPECT_FALSE(
            scope.progress()(0.5, "cleaning coast")); // a report of the run passes through...
        EXPECT_EQ(asked, 1);
        EXPECT_TRUE(GeosInterrupt::interrupted());
        EXPECT_THROW(GeosInterrupt::poll(), Cancelled);
    }
    {
        // ...and the callback asks again while GEOS works (at most every 50 ms: waited out here).
        asked = 0;
        const GeosInterrupt scope([&](double, std::string_view) { return ++asked < 0; });
        EXPECT_FALSE(GeosInterrupt::interrupted());
        std::this_thread::sleep_for(std::chrono::milliseconds(60));
        EXPECT_EQ(union_of(c, all), nullptr);
        EXPECT_GE(asked, 1);
        EXPECT_TRUE(GeosInterrupt::interrupted());
        EXPECT_THROW(GeosInterrupt::poll(), Cancelled);
        // Every later GEOS call of the run stops too.
        EXPECT_EQ(union_of(c, all), nullptr);
    }
    // Gone: GEOS runs to the end, nothing reads as cancelled.
    EXPECT_FALSE(GeosInterrupt::interrupted());
    EXPECT_NO_THROW(GeosInterrupt::poll());
    const auto whole = union_of(c, all);
    ASSERT_NE(whole, nullptr);
    double area = 0;
    GEOSArea_r(c.h, whole.get(), &area);
    EXPECT_GT(area,
              40 * 40 * 0.7 * 0.7 * 0.9); // the discs overlap into one blob of about 41.8 x 41.8
    GEOSGeom_destroy_r(c.h, all);
}

TEST(GeosInterrupt, a_progress_that_goes_on_or_none_leaves_geos_alone) {
    Context c;
    GEOSGeometry *all = discs(c);
    int asked = 0;
    {
        const GeosInterrupt scope([&](double, std::string_view) { return ++asked > 0; });
        std::this_thread::sleep_for(std::chrono::milliseconds(60));
        EXPECT_NE(union_of(c, all), nullptr);
        EXPECT_FALSE(GeosInterrupt::interrupted());
    }
    {
        const GeosInterrupt none{Progress{}};
        EXPECT_FALSE(none.progress());
        EXPECT_NE(union_of(c, all), nullptr);
        EXPECT_NO_THROW(GeosInterrupt::poll());
    }
    GEOSGeom_destroy_r(c.h, all);
}

// libFuzzer target: the coast pipeline through to a mesh. The input decodes into a small
// GeoJSON FeatureCollection (1-3 features: polygons with holes, multipolygons, or closed and
// open linestrings for the coastline path), written to GDAL's /vsimem/, read by load_coast
// (include/globemesh/coast.hpp) with an optional --region, shaped by shape_boundary and meshed by
// mesh_boundary (include/globemesh/mesher.hpp) at a coarse uniform size (400-2000 km, at most
// 20000 nodes, so one execution stays in milliseconds).
//
// Vertices come from modes: random lon/lat, lon exactly +-180 or a hair beyond it
// (180.00000000000014), latitudes at and near the poles, a copy of the previous vertex, a tiny
// offset from it (1e-12 .. 1e-5 degree), coordinates near 0 down to 1e-300, huge coordinates
// (up to 1e300, outside lon/lat), rings crossing +-180 and rings round a pole, bow ties
// (self-intersecting rings).
//
// Outcome: a mesh that is valid (every face has 3 distinct in-range nodes, is counter-clockwise
// on the sphere by the exact orient predicate, every directed edge appears once, an edge without
// an opposite face is a boundary edge and every boundary edge is an edge of a face, oriented like
// it), or a globemesh::DataError / UsageError. Any other exception, a crash, a hang or a
// sanitizer report is a finding. A finding prints the GeoJSON. At exit the target prints how
// many inputs meshed and how many were refused ("fuzz_coast outcomes: ..."); tools/fuzz fails a
// run where too few meshed, as the property battery does (CoastProperty.hundreds_of_hostile_
// small_coasts_...): a change that refused every input would otherwise pass as clean.
#include <fuzzer/FuzzedDataProvider.h>

#include <cpl_conv.h>
#include <cpl_error.h>
#include <cpl_vsi.h>
#include <gdal.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <set>
#include <string>
#include <string_view>
#include <typeinfo>
#include <utility>
#include <vector>

#include "globemesh/coast.hpp"
#include "globemesh/error.hpp"
#include "globemesh/mesher.hpp"
#include "globemesh/options.hpp"
#include "globemesh/predicates.hpp"
#include "globemesh/progress.hpp"

using namespace globemesh;

namespace {

// Mesher bugs, fixed (MesherProperty tests in tests/unit/property_test.cpp): clockwise faces,
// and refinement that runs away. Set this to true to tolerate such a bug while it is being fixed,
// so that the fuzzer looks further (a hang without progress reports still counts as a finding
// through -timeout).
constexpr bool known_mesher_bugs = false;

std::string g_json; // for failure messages
bool g_print =
    false; // GLOBEMESH_FUZZ_PRINT set: print every decoded input (to replay a finding) and refusal

// Outcomes of the inputs run so far, printed at exit.
std::size_t g_meshed = 0, g_refused = 0;

void refused(const std::exception &e) {
    ++g_refused;
    if (g_print)
        std::fprintf(stderr, "refused: %s\n", e.what());
}

void print_outcomes() {
    std::fprintf(stderr, "fuzz_coast outcomes: %zu meshed, %zu refused\n", g_meshed, g_refused);
}

[[noreturn]] void fail(const std::string &what) {
    std::fprintf(stderr, "fuzz_coast: %s\ninput GeoJSON:\n%s\n", what.c_str(), g_json.c_str());
    std::abort();
}

std::string num(double v) {
    char buf[40];
    std::snprintf(buf, sizeof buf, "%.17g", v);
    return buf;
}

struct Decoder {
    FuzzedDataProvider &in;
    double last_lon = 0, last_lat = 0;

    std::pair<double, double> vertex(int shape, int i, int n, double cx, double cy, double r) {
        double lon, lat;
        const int mode = in.ConsumeIntegralInRange<int>(0, 15);
        switch (mode) {
        case 0:
            lon = in.ConsumeFloatingPointInRange<double>(-180, 180);
            lat = in.ConsumeFloatingPointInRange<double>(-90, 90);
            break;
        case 1:
            lon = in.ConsumeBool() ? 180.0 : -180.0;
            lat = cy + in.ConsumeFloatingPointInRange<double>(-r, r);
            break;
        case 2:
            lon = in.ConsumeBool() ? 180.00000000000014 : -180.00000000000014;
            lat = cy + in.ConsumeFloatingPointInRange<double>(-r, r);
            break;
        case 3:
            lon = cx + in.ConsumeFloatingPointInRange<double>(-r, r);
            lat = in.ConsumeBool() ? 90.0 : -90.0;
            break;
        case 4:
            lon = cx + in.ConsumeFloatingPointInRange<double>(-r, r);
            lat = (in.ConsumeBool() ? 1 : -1) *
                  (90 - std::pow(10.0, in.ConsumeFloatingPointInRange<double>(-12, 0)));
            break;
        case 5:
            lon = last_lon;
            lat = last_lat;
            break;
        case 6: {
            const double e = std::pow(10.0, in.ConsumeFloatingPointInRange<double>(-12, -5));
            lon = last_lon + e * in.ConsumeIntegralInRange<int>(-1, 1);
            lat = last_lat + e * in.ConsumeIntegralInRange<int>(-1, 1);
            break;
        }
        case 7:
            lon = std::ldexp(in.ConsumeFloatingPointInRange<double>(-1, 1),
                             -in.ConsumeIntegralInRange<int>(0, 1000));
            lat = std::ldexp(in.ConsumeFloatingPointInRange<double>(-1, 1),
                             -in.ConsumeIntegralInRange<int>(0, 1000));
            break;
        case 8:
            lon = std::ldexp(in.ConsumeFloatingPointInRange<double>(-1, 1),
                             in.ConsumeIntegralInRange<int>(8, 996));
            lat = cy + in.ConsumeFloatingPointInRange<double>(-r, r);
            break;
        case 9:
            lon = cx + in.ConsumeFloatingPointInRange<double>(-r, r);
            lat = std::ldexp(in.ConsumeFloatingPointInRange<double>(-1, 1),
                             in.ConsumeIntegralInRange<int>(7, 996));
            break;
        default: { // on a (possibly self-intersecting) star polygon about (cx, cy)
            const int turns = shape; // 1: simple, 2+: a star that crosses itself
            const double t = 2 * pi * turns * i / n;
            const double rr = r * (mode % 2 ? 1.0 : 0.5);
            lon = cx + rr * std::cos(t);
            lat = std::clamp(cy + rr * std::sin(t), -90.0, 90.0);
        }
        }
        last_lon = lon;
        last_lat = lat;
        return {lon, lat};
    }

    std::string ring(bool closed) {
        const int n = in.ConsumeIntegralInRange<int>(2, 10);
        const int shape = in.ConsumeIntegralInRange<int>(1, 3);
        const double cx = in.ConsumeFloatingPointInRange<double>(-200, 200);
        const double cy = in.ConsumeFloatingPointInRange<double>(-90, 90);
        const double r = std::pow(10.0, in.ConsumeFloatingPointInRange<double>(-6, 2.3));
        std::string s = "[";
        std::string first;
        for (int i = 0; i < n; ++i) {
            const auto [lon, lat] = vertex(shape, i, n, cx, cy, r);
            const std::string p = "[" + num(lon) + "," + num(lat) + "]";
            if (i == 0)
                first = p;
            s += (i ? "," : "") + p;
        }
        if (closed)
            s += "," + first;
        return s + "]";
    }

    std::string polygon_rings() {
        std::string s = "[" + ring(true);
        for (int h = in.ConsumeIntegralInRange<int>(0, 2); h > 0; --h)
            s += "," + ring(true);
        return s + "]";
    }

    std::string geometry() {
        switch (in.ConsumeIntegralInRange<int>(0, 5)) {
        case 0:
        case 1:
        case 2:
            return "{\"type\":\"Polygon\",\"coordinates\":" + polygon_rings() + "}";
        case 3: {
            std::string s = "{\"type\":\"MultiPolygon\",\"coordinates\":[" + polygon_rings();
            for (int k = in.ConsumeIntegralInRange<int>(0, 2); k > 0; --k)
                s += "," + polygon_rings();
            return s + "]}";
        }
        default:
            return "{\"type\":\"LineString\",\"coordinates\":" + ring(in.ConsumeBool()) + "}";
        }
    }
};

void check_mesh(const Mesh &m) {
    const std::size_t n = m.nodes.size();
    for (const Vec3 &p : m.nodes)
        if (!(std::fabs(norm(p) - 1) < 1e-12))
            fail("a node is not a unit vector");
    std::set<std::pair<NodeIndex, NodeIndex>> directed;
    for (const auto &f : m.faces) {
        for (NodeIndex v : f)
            if (v >= n)
                fail("a face refers to a node out of range");
        if (f[0] == f[1] || f[1] == f[2] || f[0] == f[2])
            fail("a face repeats a node");
        const int o = predicates::orient(m.nodes[f[0]], m.nodes[f[1]], m.nodes[f[2]]);
        if (o == 0 || (o < 0 && !known_mesher_bugs))
            fail("a face is not counter-clockwise on the sphere");
        for (int k = 0; k < 3; ++k)
            if (!directed.insert({f[k], f[(k + 1) % 3]}).second)
                fail("a directed edge appears in two faces");
    }
    std::set<std::pair<NodeIndex, NodeIndex>> boundary;
    for (const BoundaryEdge &e : m.boundary) {
        if (!directed.count({e.a, e.b}))
            fail("a boundary edge is not an edge of a face, oriented like it");
        if (directed.count({e.b, e.a}))
            fail("a boundary edge has faces on both sides");
        boundary.insert({e.a, e.b});
    }
    for (const auto &[a, b] : directed)
        if (!directed.count({b, a}) && !boundary.count({a, b}))
            fail("an edge with one face is not a boundary edge");
    std::vector<char> used(n, 0);
    for (const auto &f : m.faces)
        for (NodeIndex v : f)
            used[v] = 1;
    for (std::size_t i = 0; i < n; ++i)
        if (!used[i])
            fail("a node belongs to no face");
}

} // namespace

extern "C" int LLVMFuzzerInitialize(int *, char ***) {
    CPLSetErrorHandler(CPLQuietErrorHandler);
    g_print = std::getenv("GLOBEMESH_FUZZ_PRINT") != nullptr;
    GDALAllRegister();
    std::atexit(print_outcomes);
    return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t *data, std::size_t size) {
    FuzzedDataProvider in(data, size);
    Decoder dec{in};
    std::string json = "{\"type\":\"FeatureCollection\",\"features\":[";
    const int features = in.ConsumeIntegralInRange<int>(1, 3);
    for (int k = 0; k < features; ++k)
        json += std::string(k ? "," : "") +
                "{\"type\":\"Feature\",\"properties\":{},\"geometry\":" + dec.geometry() + "}";
    json += "]}";
    g_json = json;

    CoastOptions options; // the coast stage's own options, with no memory budget
    options.coast = "/vsimem/fuzz_coast.geojson";
    // A region one input in four; not on an input that has run out (its bytes then read as 0,
    // which would ask for a region of all minimums, W = E, refused before the coast is read).
    if (in.ConsumeIntegralInRange<int>(0, 3) == 3) {
        const double w = in.ConsumeFloatingPointInRange<double>(-180, 180);
        const double e = in.ConsumeFloatingPointInRange<double>(-180, 180);
        const double s = in.ConsumeFloatingPointInRange<double>(-90, 89);
        const double nn = in.ConsumeFloatingPointInRange<double>(s, 90);
        options.region = std::array<double, 4>{w, s, e, nn};
        g_json += "\nregion " + num(w) + "," + num(s) + "," + num(e) + "," + num(nn);
    }
    options.keep_inland_seas = in.ConsumeBool();
    options.min_island_triangles = in.ConsumeIntegralInRange<int>(0, 4);
    const double h = in.ConsumeFloatingPointInRange<double>(400, 2000);
    g_json += "\nh " + num(h) + " keep_inland_seas " + std::to_string(options.keep_inland_seas) +
              " min_island_triangles " + num(options.min_island_triangles);

    if (g_print)
        std::fprintf(stderr, "%s\n", g_json.c_str());
    VSILFILE *f =
        VSIFileFromMemBuffer(options.coast.c_str(), reinterpret_cast<GByte *>(json.data()),
                             static_cast<vsi_l_offset>(json.size()), FALSE);
    if (!f)
        fail("cannot create the /vsimem/ file");
    VSIFCloseL(f);
    try {
        const CoastData coast = load_coast(options);
        const SizeFn size = [h](const Vec3 &) { return h; };
        const Boundary boundary = shape_boundary(coast, size, options, MeshingOptions{}.max_nodes);
        const auto issues = check_boundary(boundary);
        if (!issues.empty())
            fail("shape_boundary returned an invalid boundary: " + issues.front().what);
        if (g_print)
            for (const Ring &r : boundary.rings) {
                std::fprintf(stderr, "ring:");
                for (std::size_t i = 0; i < r.nodes.size(); ++i)
                    std::fprintf(stderr, " {%a, %a, %a}%s", r.nodes[i].x, r.nodes[i].y,
                                 r.nodes[i].z, r.kinds[i] == SegmentKind::open ? "o" : "");
                std::fprintf(stderr, "\n");
            }
        MesherOptions mo;
        mo.max_nodes = 20000;
        mo.keep_inland_seas = options.keep_inland_seas;
        mo.smooth_iterations = 2;
        mo.lattice_km = h;    // as the pipeline
        mo.land = coast.land; // faces centred on land removed, straits closed
                              // (MesherOptions::close_straits)
        // Refinement reports progress every 16384 insertions; with at most 20000 nodes asked
        // for, a 5th report is a runaway (a known mesher bug, see known_mesher_bugs).
        std::size_t reports = 0;
        const Progress guard = [&reports](double, std::string_view stage) {
            return stage != "refine" || ++reports < 5;
        };
        Mesh mesh;
        try {
            mesh = mesh_boundary(boundary, size, mo, nullptr, guard);
        } catch (const Cancelled &) {
            if (!known_mesher_bugs)
                fail("mesh_boundary ran away (over 65000 insertions for <= 20000 nodes)");
            VSIUnlink(options.coast.c_str());
            return 0;
        }
        check_mesh(mesh);
        ++g_meshed;
    } catch (const DataError &e) {
        refused(e);
    } catch (const UsageError &e) {
        refused(e);
    } catch (const std::exception &e) {
        fail(std::string("unexpected exception: ") + typeid(e).name() + ": " + e.what());
    }
    VSIUnlink(options.coast.c_str());
    return 0;
}

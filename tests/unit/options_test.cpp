// MeshOptions' validation as a library user meets it (messages naming the fields), the error
// texts' option names, and the run's metadata formatted from mesh_ocean's typed reports.
#include <gtest/gtest.h>

#include <string>

#include "globemesh/error.hpp"
#include "globemesh/options.hpp"
#include "globemesh/pipeline.hpp"
#include "globemesh/progress.hpp"
#include "support.hpp"

namespace globemesh {
namespace {

std::string usage_message(const MeshOptions &o) {
    return test::thrown_message<UsageError>([&] { validate(o); });
}

TEST(Options, validate_names_the_fields_a_library_user_set) {
    MeshOptions o;
    o.hmax_km = 0;
    EXPECT_EQ(usage_message(o), "hmax_km must be a positive length, e.g. 100km");
    o = MeshOptions{};
    o.hmin_km = 20.5;
    o.hmax_km = 10;
    EXPECT_EQ(usage_message(o), "hmin_km (20.5km) must not be larger than hmax_km (10km)");
    o = MeshOptions{};
    o.min_depth_m = 5;
    EXPECT_EQ(usage_message(o), "min_depth_m needs bathy: it raises the sampled depths");
    // The raster's other options without a raster, ignored before without a word.
    o = MeshOptions{};
    o.bathy_fill_m = 20;
    EXPECT_EQ(usage_message(o),
              "bathy_fill_m needs bathy: it is the depth where the raster has no data");
    o = MeshOptions{};
    o.depth_positive = true;
    EXPECT_EQ(usage_message(o), "depth_positive needs bathy: it says the raster stores depth");
    o = MeshOptions{};
    o.bathy_srs = "EPSG:4326";
    EXPECT_EQ(usage_message(o), "bathy_srs needs bathy: it is the raster's CRS");
    o = MeshOptions{};
    o.bathy_band = 2;
    EXPECT_EQ(usage_message(o), "bathy_band 2 needs bathy: it picks a band of the raster");
    o.bathy = "shelf.tif"; // with the raster, all of them stand
    o.bathy_fill_m = 20;
    o.depth_positive = true;
    o.bathy_srs = "EPSG:4326";
    o.min_depth_m = 5;
    EXPECT_NO_THROW(validate(o));
    o = MeshOptions{};
    o.region = std::array<double, 4>{0, 0, 10, 10};
    o.region_file = "r.gpkg";
    EXPECT_EQ(usage_message(o), "region and region_file cannot be used together");
    EXPECT_NO_THROW(validate(MeshOptions{}));
}

TEST(Options, an_error_names_its_options_as_its_reader_calls_them) {
    const UsageError e(option("hmin_km") + " (2km) must not be larger than " + option("hmax_km") +
                       " (1km)");
    EXPECT_STREQ(e.what(), "hmin_km (2km) must not be larger than hmax_km (1km)");
    auto flags = [](std::string_view field) {
        return field == "hmin_km" ? std::string("--hmin") : std::string("--hmax");
    };
    EXPECT_EQ(e.message(flags), "--hmin (2km) must not be larger than --hmax (1km)");
    EXPECT_EQ(e.text().leading_option(), "hmin_km");
    EXPECT_EQ(e.text().after_leading_option().str(), "(2km) must not be larger than hmax_km (1km)");
    const DataError plain("no ocean in the region");
    EXPECT_EQ(plain.message(flags), "no ocean in the region");
    EXPECT_EQ(plain.text().leading_option(), "");
}

TEST(StageTimings, the_stages_that_read_inputs_are_told_apart_from_the_computing) {
    StageTimings t;
    t.add_input("read_coast", 2);
    t.add("size_field", 0.5);
    t.add_input("read_bathy", 1);
    t.add("refine", 3);
    ASSERT_EQ(t.stages.size(), 4u); // all of them, in order
    EXPECT_EQ(t.stages[2].first, "read_bathy");
    EXPECT_DOUBLE_EQ(t.input_seconds, 3);
    EXPECT_DOUBLE_EQ(t.compute_seconds(), 3.5);
}

TEST(OceanMesh, the_file_metadata_is_formatted_from_the_typed_reports) {
    OceanMesh run;
    run.coast_file = "land.gpkg";
    run.coast_layer = "land";
    run.bathymetry_file = "depth.tif";
    run.depth = DepthReport{3, -12.5, 5.0, 40};
    run.coast.rings = 7;
    run.coast.ocean_area_km2 = 1234567.8;
    run.coast_repairs = {1, 2, 3};
    run.mesher.land_faces_left = 2;
    run.mesher.land_faces_removed = 10;
    run.mesher.land_faces_at = {lonlat_to_vec(10, 20), lonlat_to_vec(-30.5, -40.25)};
    run.straits_closing = true;
    run.mesher.straits_closed = 1;
    run.mesher.straits_closed_places = 1;
    run.mesher.seas_cut_off = {436000, 39000};
    run.mesher.straits_water_km2 = 12.5;
    run.mesher.inlets_closed = 4;
    run.mesher.inlet_area_km2 = 99;
    run.mesher.components = {{1e6, true}, {2.5, false}};
    const auto a = ocean_attributes(run);
    auto value = [&](const std::string &key) {
        for (const auto &[k, v] : a)
            if (k == key)
                return v;
        return std::string("(none)");
    };
    EXPECT_EQ(a.front().first, "coast_file");
    EXPECT_EQ(value("bathymetry_file"), "depth.tif");
    EXPECT_EQ(value("nodes_above_sea_level"), "3");
    EXPECT_EQ(value("min_sampled_depth_m"), "-12.5");
    EXPECT_EQ(value("min_depth_m"), "5");
    EXPECT_EQ(value("nodes_raised_to_min_depth"), "40");
    EXPECT_EQ(value("boundary_rings"), "7");
    EXPECT_EQ(value("coast_repairs"),
              "1 polygons joined at near-touches, 2 rings changed by snap rounding, "
              "3 nodes added to straying arcs");
    EXPECT_EQ(value("faces_on_land"),
              "2 (10 removed, opening 0 holes, joining 0 loops, 0 moved off)");
    EXPECT_EQ(value("faces_on_land_at"), "10.00 20.00, -30.50 -40.25");
    EXPECT_EQ(value("straits_closed"),
              "1 at 1 place (cutting off 2 basins: 436000 km2, 39000 km2; 12.5 km2 of water "
              "closed with them; 0 nodes split)");
    EXPECT_EQ(value("straits_closed_at"), "(none)"); // no place given
    EXPECT_EQ(value("ocean_area_km2"), "1.23457e+06");
    EXPECT_EQ(value("inlets_closed"), "4 (99 km2)");
    EXPECT_EQ(value("ocean_components"), "1e+06 km2 kept; 2.5 km2 dropped");
    EXPECT_EQ(a.back().first, "ocean_components");
    // Without straits closing, and without bathymetry, their attributes are absent.
    run.straits_closing = false;
    run.depth.reset();
    for (const auto &[k, v] : ocean_attributes(run)) {
        EXPECT_NE(k, "straits_closed");
        EXPECT_NE(k, "nodes_above_sea_level");
    }
    // The places: at most `limit`, then ", ...".
    EXPECT_EQ(places_text(run.mesher.land_faces_at, 1), "10.00 20.00, ...");
}

} // namespace
} // namespace globemesh

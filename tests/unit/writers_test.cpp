// The table of output formats and write_outputs (writers.hpp): the rows are what the command line
// relies on (names, extensions, report keys each once), and the outputs of one call appear
// together or not at all, read back by OGR and netCDF-C.
#include <gtest/gtest.h>

#include <gdal.h>
#include <netcdf.h>
#include <ogr_api.h>

#include <cctype>
#include <cmath>
#include <fstream>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include "globemesh/error.hpp"
#include "globemesh/writers.hpp"
#include "io_test_meshes.hpp"
#include "support.hpp"
#include "write_hooks.hpp"

namespace fs = std::filesystem;
using globemesh::test::icosphere;
using globemesh::test::TempDir;

namespace {

std::set<std::string> files_in(const fs::path &dir) {
    std::set<std::string> names;
    for (const auto &e : fs::directory_iterator(dir))
        names.insert(e.path().filename().string());
    return names;
}

bool upper_case(const std::string &s) {
    for (unsigned char c : s)
        if (std::islower(c))
            return false;
    return !s.empty();
}

/// The rows of `names` in the real table, in that order.
std::vector<globemesh::OutputRequest> outputs(const fs::path &dir,
                                              const std::vector<std::string> &files) {
    std::vector<globemesh::OutputRequest> r;
    for (const auto &f : files) {
        const globemesh::Writer *w = globemesh::writer_for_extension(globemesh::writers(), dir / f);
        if (w == nullptr)
            throw std::logic_error("no writer for " + f);
        r.push_back({w, dir / f, {}});
    }
    return r;
}

/// The faces of a GeoPackage's faces layer and the sum of their area_km2, read by OGR.
std::pair<long long, double> gpkg_faces(const fs::path &path) {
    GDALAllRegister();
    GDALDatasetH ds =
        GDALOpenEx(path.c_str(), GDAL_OF_VECTOR | GDAL_OF_READONLY, nullptr, nullptr, nullptr);
    if (ds == nullptr)
        return {-1, 0};
    EXPECT_STREQ(GDALGetDriverShortName(GDALGetDatasetDriver(ds)), "GPKG");
    OGRLayerH faces = GDALDatasetGetLayerByName(ds, "faces");
    double area = 0;
    long long n = 0;
    OGR_L_ResetReading(faces);
    for (OGRFeatureH f; (f = OGR_L_GetNextFeature(faces)) != nullptr; OGR_F_Destroy(f)) {
        area += OGR_F_GetFieldAsDouble(f, OGR_F_GetFieldIndex(f, "area_km2"));
        ++n;
    }
    GDALClose(ds);
    return {n, area};
}

} // namespace

// The command line chooses by name and extension and lists by report key: each must name one row.
TEST(Writers, each_name_extension_and_report_key_names_one_row) {
    std::set<std::string> names, extensions, keys;
    for (const auto &w : globemesh::writers()) {
        SCOPED_TRACE(w.name);
        EXPECT_TRUE(upper_case(w.name));
        EXPECT_TRUE(names.insert(w.name).second);
        EXPECT_TRUE(keys.insert(w.report_key).second);
        EXPECT_FALSE(w.long_name.empty());
        EXPECT_NE(w.extensions.empty(), w.folder_files.empty()); // a file's or a folder's
        for (const auto &e : w.extensions) {
            EXPECT_TRUE(e.size() > 1 && e.find('.') != std::string::npos) << e;
            // A name ending so is this row's, even where a shorter suffix is another's.
            EXPECT_EQ(globemesh::writer_for_extension(globemesh::writers(), "x" + e), &w) << e;
            for (unsigned char c : e)
                EXPECT_FALSE(std::isupper(c)) << e;
            EXPECT_TRUE(extensions.insert(e).second) << e << " is the extension of two formats";
        }
        EXPECT_TRUE(w.write != nullptr);
        EXPECT_GT(w.progress_weight, 0);
        for (const auto &c : w.creation_options) {
            EXPECT_TRUE(upper_case(c.name)) << c.name;
            for (const auto &v : c.values)
                EXPECT_TRUE(upper_case(v)) << v;
        }
    }
    // The first row is the format of a name without extension, as -o wrote before the table.
    EXPECT_EQ(globemesh::writers().front().name, "UGRID");
}

TEST(Writers, names_and_extensions_are_found_in_any_case) {
    const auto &table = globemesh::writers();
    EXPECT_EQ(globemesh::find_writer(table, "gpkg")->name, "GPKG");
    EXPECT_EQ(globemesh::find_writer(table, "Ugrid")->name, "UGRID");
    EXPECT_EQ(globemesh::find_writer(table, "netcdf"), nullptr);
    EXPECT_EQ(globemesh::writer_for_extension(table, "a/b.NC")->name, "UGRID");
    EXPECT_EQ(globemesh::writer_for_extension(table, "x.Gpkg")->name, "GPKG");
    EXPECT_EQ(globemesh::writer_for_extension(table, "x.png")->name, "PNG");
    EXPECT_EQ(globemesh::writer_for_extension(table, "x.gpkg.dat"), nullptr);
    EXPECT_EQ(globemesh::writer_for_extension(table, "noextension"), nullptr);
}

TEST(Writers, the_longest_suffix_a_name_ends_with_chooses) {
    const auto &table = globemesh::writers();
    EXPECT_EQ(globemesh::writer_for_extension(table, "a/North_Sea_NET.nc")->name, "DFLOWFM");
    EXPECT_EQ(globemesh::writer_for_extension(table, "a_net/b.nc")->name, "UGRID");
    EXPECT_EQ(globemesh::writer_for_extension(table, "x.net.nc")->name, "UGRID");
    EXPECT_EQ(globemesh::writer_for_extension(table, "xnet.nc")->name, "UGRID");
    EXPECT_EQ(globemesh::writer_for_extension(table, "run/fort.14")->name, "ADCIRC");
    EXPECT_EQ(globemesh::writer_for_extension(table, "hgrid.ll")->name, "SCHISM");
    EXPECT_EQ(globemesh::writer_for_extension(table, "x_net.nc.bak"), nullptr);
    // A name that is only a suffix is a hidden file without extension, as before.
    EXPECT_EQ(globemesh::writer_for_extension(table, "d/.nc"), nullptr);
}

TEST(Writers, creation_options_are_checked_against_the_row) {
    const globemesh::Writer &ugrid = *globemesh::find_writer(globemesh::writers(), "UGRID");
    globemesh::CreationOptions ok = {{"format", "nc2"}};
    globemesh::check_creation_options(ugrid, ok, "o.nc");
    EXPECT_EQ(ok, (globemesh::CreationOptions{{"FORMAT", "NC2"}}));
    EXPECT_EQ(globemesh::creation_option(ok, "FORMAT"), "NC2");
    EXPECT_EQ(globemesh::creation_option(ok, "OTHER", "x"), "x");
    globemesh::CreationOptions unknown = {{"ZLEVEL", "9"}}, bad = {{"FORMAT", "HDF5"}};
    EXPECT_THROW(globemesh::check_creation_options(ugrid, unknown, "o.nc"), globemesh::UsageError);
    EXPECT_THROW(globemesh::check_creation_options(ugrid, bad, "o.nc"), globemesh::UsageError);
}

// Without a caller's batch, write_outputs makes the files appear together: all three, read back
// by OGR and netCDF-C, with the UGRID creation option applied and the GeoPackage's face areas
// summing to the ellipsoid's.
TEST(Writers, write_outputs_writes_every_output_with_its_creation_options) {
    TempDir dir;
    auto requests = outputs(dir.path(), {"m.nc", "m.gpkg", "m.png"});
    requests[0].creation_options = {{"FORMAT", "NC2"}};
    std::vector<double> fractions;
    globemesh::WriteOptions common;
    common.progress = [&](double f, std::string_view) {
        fractions.push_back(f);
        return true;
    };
    const globemesh::Mesh mesh = icosphere(3);
    globemesh::write_outputs(mesh, requests, common);
    EXPECT_EQ(files_in(dir.path()), (std::set<std::string>{"m.nc", "m.gpkg", "m.png"}));
    int nc = -1, format = -1;
    ASSERT_EQ(nc_open((dir / "m.nc").c_str(), NC_NOWRITE, &nc), NC_NOERR);
    EXPECT_EQ(nc_inq_format(nc, &format), NC_NOERR);
    EXPECT_EQ(format, NC_FORMAT_64BIT_OFFSET);
    nc_close(nc);
    const auto [faces, area_km2] = gpkg_faces(dir / "m.gpkg");
    EXPECT_EQ(faces, static_cast<long long>(mesh.faces.size()));
    const double sphere_km2 = 4 * M_PI * 6371.0088 * 6371.0088; // within the ellipsoid's 0.5 %
    EXPECT_NEAR(area_km2, 510065622.0, 0.005 * sphere_km2);
    // One line from 0 to 1, never back, across the three outputs.
    ASSERT_FALSE(fractions.empty());
    for (std::size_t i = 1; i < fractions.size(); ++i)
        EXPECT_GE(fractions[i], fractions[i - 1]);
    EXPECT_DOUBLE_EQ(fractions.back(), 1.0);
    globemesh::test::expect_mesh_verify(dir / "m.nc");
}

TEST(Writers, a_failure_of_the_last_output_leaves_none_of_them) {
    TempDir dir;
    const auto requests = outputs(dir.path(), {"m.nc", "m.gpkg", "m.png"});
    int partial = 0;
    {
        globemesh::detail::PartialWriteHook hook([&] {
            if (++partial == 3)
                throw globemesh::IoError("the disk is full");
        });
        EXPECT_THROW(globemesh::write_outputs(icosphere(2), requests, {}), globemesh::IoError);
    }
    EXPECT_EQ(partial, 3);
    EXPECT_TRUE(files_in(dir.path()).empty());
    // Cancelled between two outputs: nothing either.
    int asked = 0;
    EXPECT_THROW(globemesh::write_outputs(icosphere(2), requests, {}, [&] { return ++asked == 2; }),
                 globemesh::Cancelled);
    EXPECT_TRUE(files_in(dir.path()).empty());
}

TEST(Writers, a_format_that_needs_depths_refuses_a_mesh_without_them_before_writing) {
    TempDir dir;
    globemesh::Writer deep = *globemesh::find_writer(globemesh::writers(), "UGRID");
    deep.needs = globemesh::needs_depth;
    const globemesh::OutputRequest requests[] = {{&globemesh::writers().front(), dir / "a.nc", {}},
                                                 {&deep, dir / "b.nc", {}}};
    EXPECT_THROW(globemesh::write_outputs(icosphere(1), requests, {}), globemesh::DataError);
    EXPECT_TRUE(files_in(dir.path()).empty());
    globemesh::Mesh with_depth = icosphere(1);
    with_depth.node_fields.push_back(
        {"depth", "depth", "m", "", std::vector<double>(with_depth.nodes.size(), 10.0)});
    globemesh::write_outputs(with_depth, requests, {});
    // With depth, each UGRID file has its QGIS style beside it.
    EXPECT_EQ(files_in(dir.path()), (std::set<std::string>{"a.nc", "a.qml", "b.nc", "b.qml"}));
}

TEST(Writers, a_rewrite_without_depth_removes_the_style_it_wrote_and_keeps_a_users_own) {
    TempDir dir;
    globemesh::Mesh with_depth = icosphere(1);
    with_depth.node_fields.push_back(
        {"depth", "depth", "m", "", std::vector<double>(with_depth.nodes.size(), 10.0)});
    const globemesh::OutputRequest a[] = {{&globemesh::writers().front(), dir / "a.nc", {}}};
    globemesh::write_outputs(with_depth, a, {});
    { std::ofstream(dir / "b.qml") << "<!DOCTYPE qgis>\n<qgis/>\n"; } // the user's own
    const globemesh::OutputRequest b[] = {{&globemesh::writers().front(), dir / "b.nc", {}}};
    globemesh::WriteOptions overwrite;
    overwrite.overwrite = true;
    globemesh::write_outputs(icosphere(1), a, overwrite);
    globemesh::write_outputs(icosphere(1), b, overwrite);
    EXPECT_EQ(files_in(dir.path()), (std::set<std::string>{"a.nc", "b.nc", "b.qml"}));
}

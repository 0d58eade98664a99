// globemesh/bathymetry.hpp: bathymetry from any GDAL raster, as a plain lon/lat grid in memory.
//
// read_bathymetry() opens the raster named by bathy with GDAL, takes band bathy_band, applies
// GDAL's scale/offset, turns the nodata value, NaN and the cells GDAL's mask band marks invalid
// (a per-dataset or per-band mask, an alpha band: GDALGetMaskFlags) into "no data", flips
// depth-positive grids (depth_positive) to elevation positive up, and hands back a Raster:
// values on a regular lon/lat grid of cell centres, in metres, elevation positive up (land > 0,
// sea floor < 0). No GDAL type appears in this interface.
//
// Georeferencing: a raster in WGS 84 lon/lat in effect (PROJ's transformation to EPSG:4326 moves
// no point of it: EPSG:4326, CRS84, the WGS 84 ellipsoid without a datum) with a north-up (or
// south-up) geotransform is read as is, longitudes in 0..360 or -180..180 alike. Any other
// raster (projected, rotated, or geographic on another datum, prime meridian or unit: NAD27,
// ED50, a Paris meridian) is read through an in-memory warped VRT to EPSG:4326 (GDALWarp,
// bilinear, exact transformer -et 0, over the source's whole extent, NaN outside the source
// footprint but in the cells just off it, which hold their neighbours' mean as a plain raster
// holds its edge values past its edge). bathy_srs replaces the
// file's CRS (or gives one). A file without a CRS whose coordinates are CF longitude and latitude
// (GDAL metadata such as lon#standard_name=longitude or lat#units=degrees_north: CUDEM tiles,
// classic global relief NetCDF grids), with a geotransform whose extent can be degrees, is read
// as WGS 84 lon/lat (the progress stage says so, which the CLI shows with --verbose).
// A netCDF variable stored X before Y (z(lon, lat)), which GDAL's netCDF raster driver reads
// with its axes swapped, is read through GDAL's multidimensional view of it (2-D only).
// A grid whose columns span 360 degrees (within a tenth of a cell: coordinates written with few
// digits or as float32) is global, its spacing taken as exactly 360 / columns, and wraps across
// its seam; a node-registered global grid (the last column repeats the first meridian, e.g.
// longitudes 20 .. 380 or -180 .. 180) drops that last column and interpolates across the seam.
//
// Sampling (Raster::sample, elevation_m): bilinear in lon/lat between the four surrounding cell
// centres, exact at the cell centres (error below 1e-9 m there, the values being stored as float)
// and exactly bilinear inside a cell. Where some of the four corners have no data the valid ones
// are averaged with renormalised bilinear weights, unless the nearest corner has no data: then
// the point has no data. Between the outermost cell centres and the raster's edge (half a cell)
// the edge value is held; a global grid whose edge row lies within one cell of a pole holds
// that row up to the pole.
// Outside the raster, or where there is no data, elevation_m gives the fill (-bathy_fill_m) when
// set, NaN otherwise.
//
// Memory: values are stored once, as float (4 bytes a cell; exact for Int16/Int32 below 2^24
// and Float32 rasters, relative rounding 6e-8 otherwise), read straight from GDAL's blocks into
// that array; the full raster is never allocated when it is read decimated. Decimation (GDAL's
// average resampling through RasterIO, which uses the raster's overviews when it has some and
// only the source window a VRT maps otherwise) applies to rasters with more than max_cells
// cells (default 2^28, 1 GiB: a 1-arc-minute global grid fits) and, through RasterLimits, to
// cells finer than the mesh can use. A global grid read whole is averaged by whole blocks of
// columns that divide half its columns (when they fit the memory budget), so the same grid
// stored from 0 or from -180 E gives the same cells. With region (or region_file, the extent of
// its ocean), only the cells that cover the region (and a margin: 1% of its larger side and
// three cells) are read: a regional run reads a small window of a global raster, at the
// resolution the region's mesh needs. read_bathymetry() asks for cells no finer than half
// the smallest edge length (hfloor / 2, see sizefield.hpp, as degrees of a great circle) and
// refuses (DataError naming max_memory_bytes) when the values would take more than half of
// options.max_memory_bytes. GDAL's block cache (GDAL_CACHEMAX, 5% of RAM by default) comes on
// top while reading.
//
// Errors: IoError when the file cannot be opened or read; UsageError for a band that does not
// exist (for a file of several rasters and no band, a NetCDF of several 2-D variables: naming
// them as GDAL's subdatasets, NETCDF:"file.nc":elevation, to give one as bathy) or a bathy_srs
// that is no CRS; DataError for a raster without georeferencing, with no valid cell, or that
// does not cover the region (unless bathy_fill_m gives a value for the uncovered part).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "globemesh/boundary.hpp"
#include "globemesh/options.hpp"
#include "globemesh/progress.hpp"
#include "globemesh/sphere.hpp"

namespace globemesh {

/// West, south, east, north edges of a grid in degrees (east > west; east may exceed 180).
struct LonLatBounds {
    double west = -180, south = -90, east = 180, north = 90;
};

/// Values (NaN = no data) on a regular lon/lat grid of cell centres.
/// Node (i, j) sits at lon0 + i*dlon, lat0 + j*dlat; value index j*nlon + i.
class Raster {
public:
    Raster() = default;
    /// lon0_deg/lat0_deg: centre of cell (0, 0); dlon_deg > 0; dlat_deg non-zero (negative for
    /// north-up rows). values.size() must be nlon*nlat. The grid is global when nlon*dlon is 360
    /// (to 1e-6 of a cell). Throws DataError on inconsistent sizes.
    Raster(double lon0_deg, double lat0_deg, double dlon_deg, double dlat_deg, std::size_t nlon,
           std::size_t nlat, std::vector<float> values);

    std::size_t nlon() const { return nlon_; }
    std::size_t nlat() const { return nlat_; }
    double lon0_deg() const { return lon0_; }
    double lat0_deg() const { return lat0_; }
    double dlon_deg() const { return dlon_; }
    double dlat_deg() const { return dlat_; }
    /// Longitude of column i, degrees (lon0 + i*dlon, not reduced to [-180, 180)).
    double lon_deg(std::size_t i) const { return lon0_ + static_cast<double>(i) * dlon_; }
    /// Latitude of row j, degrees.
    double lat_deg(std::size_t j) const { return lat0_ + static_cast<double>(j) * dlat_; }
    /// Stored value of node (i, j) (NaN = no data).
    float value(std::size_t i, std::size_t j) const { return values_[j * nlon_ + i]; }
    const std::vector<float> &values() const { return values_; }
    /// True when the columns span 360 degrees: column nlon-1 neighbours column 0.
    bool global() const { return global_; }
    /// Edges of the cells (half a cell beyond the outermost centres), degrees.
    LonLatBounds bounds() const;
    /// True when (lon, lat) lies inside bounds(), or less than edge_margin of a cell past them
    /// (longitude taken modulo 360).
    bool contains(double lon_deg, double lat_deg) const;

    /// Bilinear value at (lon, lat) in degrees, any longitude (the edge cells' values up to
    /// edge_margin of a cell past bounds()); NaN outside or without data.
    double sample(double lon_deg, double lat_deg) const;

    /// How far past its edges (cells) a raster is read, at its edge cells' values: a region's
    /// open edge along a parallel is great-circle arcs between nodes on it, which sag past a
    /// raster cut to the region (ETOPO5 cut at 62N, a mesh at 60 km: nodes 0.0002-0.0008 degree
    /// past it, a twentieth of a 10' cell at most).
    static constexpr double edge_margin = 0.25;

    /// Elevation at a point, metres positive up: sample(), or the fill where that is NaN.
    double elevation_m(double lon_deg, double lat_deg) const;
    double elevation_m(const Vec3 &p) const;
    /// Depth at a point, metres positive down (-elevation_m).
    double depth_m(const Vec3 &p) const { return -elevation_m(p); }

    /// Elevation (m, positive up) returned where the raster has no value; nullopt gives NaN.
    void set_fill_elevation_m(std::optional<double> fill) { fill_ = fill; }
    std::optional<double> fill_elevation_m() const { return fill_; }

    /// Number of nodes holding data (not NaN).
    std::size_t valid_count() const;

private:
    double lon0_ = 0, lat0_ = 0, dlon_ = 1, dlat_ = 1;
    std::size_t nlon_ = 0, nlat_ = 0;
    bool global_ = false;
    double v_lo_ = 0, v_hi_ = 0; ///< valid row positions (cell units from row 0)
    /// A non-global raster's column position of lon (cell units from column 0), taken from
    /// edge_margin of a cell west of its west edge round to 360 degrees further.
    double column_of(double lon_deg) const;
    /// column_of(lon), but at a pole (every longitude) the middle column when lon is past the
    /// columns: a raster cut to a box from 155 to 161 E holds 90 N, which a node there names lon 0.
    double column_at(double lon_deg, double lat_deg) const;
    /// Whether column position u (column_of's) lies on a non-global raster's columns, up to
    /// edge_margin of a cell past its east edge.
    bool on_columns(double u) const {
        return u <= static_cast<double>(nlon_) - 0.5 + edge_margin + 1e-9;
    }
    std::vector<float> values_;
    std::optional<double> fill_;
};

/// How coarsely, and within how much memory, read_raster holds a raster.
struct RasterLimits {
    /// Decimate (GDAL average) to at most this many cells; 0: no cap.
    std::size_t max_cells = std::size_t{1} << 28;
    /// Cells finer than this (degrees, each axis apart) are averaged to about this size (never
    /// coarser: the cell count per axis is rounded up); 0: the raster's own resolution.
    double min_cell_deg = 0;
    /// Refuse (DataError naming max_memory_bytes) when the values read would take more bytes; 0: no
    /// cap.
    std::uint64_t max_bytes = 0;
    /// Read only the cells that cover this box (degrees; east > west, east may exceed 180), with
    /// a margin of three cells (of the raster's own size or min_cell_deg, the larger), instead of
    /// the whole raster. A box across the seam of a global raster reads every column of its rows;
    /// a box the raster does not meet reads the whole raster. nullopt: the whole raster.
    std::optional<LonLatBounds> window;
};

/// Reads one band of any GDAL raster as elevation in metres (positive up); see the file comment.
/// path: the raster; band: 1-based; depth_positive: the raster stores depth positive down;
/// max_cells: decimate (GDAL average) rasters larger than this. Throws IoError, UsageError
/// (band out of range, naming bathy_band) or DataError (no georeferencing, all nodata).
Raster read_raster(const std::string &path, int band = 1, bool depth_positive = false,
                   const Progress &progress = {}, std::size_t max_cells = std::size_t{1} << 28);

/// read_raster within `limits`: decimated as they say, and a DataError naming the raster's size,
/// the bytes needed and max_memory_bytes, before anything large is allocated, when it does not fit.
/// srs: the raster's CRS (bathy_srs: any string OGRSpatialReference::SetFromUserInput takes)
/// in place of the file's; empty: the file's, or lon/lat for CF lon/lat axes (file comment).
/// Throws UsageError naming bathy_srs when srs is not a CRS.
Raster read_raster(const std::string &path, int band, bool depth_positive, const Progress &progress,
                   const RasterLimits &limits, const std::string &srs = {});

/// Throws UsageError (one line naming bathy_srs) when srs is neither empty nor a CRS that
/// OGRSpatialReference::SetFromUserInput takes. Opens no file.
void validate_bathy_srs(const std::string &srs);

/// The lon/lat box of the ocean left of `ocean`'s rings: longitudes the shortest arc of the
/// circle that holds every segment (to 1/8 degree, outward), latitudes those of the nodes,
/// reaching a pole that lies in the ocean (then every longitude). nullopt without rings (the
/// whole sphere).
std::optional<LonLatBounds> ocean_extent(const Boundary &ocean);

/// in(north pole) - in(south pole) for the ocean left of the rings: 1 when the ocean holds the
/// north pole but not the south one, -1 the reverse, 0 for neither (or both). Rings through a
/// pole are left out (that pole is on the outline).
int ocean_pole_winding(const Boundary &ocean);

/// What reading the bathymetry takes from the other modules' options: the region the raster
/// must cover (CoastOptions), the finest size the mesh asks for (SizeFieldOptions) and the
/// memory budget (MeshingOptions). Default: the whole globe, the default sizes, no budget.
struct BathymetryContext {
    std::optional<std::array<double, 4>> region; ///< CoastOptions::region (W,S,E,N degrees)
    std::string region_file; ///< CoastOptions::region_file (its ocean is the region; named)
    double hfloor_km = size_floor_km(SizeFieldOptions{}); ///< size_floor_km(SizeFieldOptions)
    std::uint64_t max_memory_bytes = 0; ///< MeshingOptions::max_memory_bytes; 0: no limit
};

/// The BathymetryContext of a whole run's options.
inline BathymetryContext bathymetry_context(const MeshOptions &options) {
    return {options.region, options.region_file, size_floor_km(options), options.max_memory_bytes};
}

/// The limits read_bathymetry applies in `context`: cells no finer than hfloor_km / 2, at most
/// half of max_memory_bytes, and a window widened by 1% of its larger side (the size field's
/// grid reaches a cell beyond the region): region's box, or with region_file the ocean_extent of
/// `ocean` (the coast stage's rings) when given.
RasterLimits bathymetry_limits(const BathymetryContext &context, const Boundary *ocean = nullptr);

/// bathymetry_limits in the context of a whole run's options.
inline RasterLimits bathymetry_limits(const MeshOptions &options, const Boundary *ocean = nullptr) {
    return bathymetry_limits(bathymetry_context(options), ocean);
}

/// Reads options.bathy (band options.bathy_band, options.depth_positive, options.bathy_srs), sets
/// the fill to -options.bathy_fill_m when given, and checks the raster covers the region, within
/// bathymetry_limits(context, ocean). With `ocean` (the rings the coast stage cut for region
/// or region_file) the region is that ocean: the raster must hold every point of its outline
/// (a point a quarter of a cell apart along the great-circle segments) and a pole inside it;
/// land in the region needs no raster. Without: region's box, or the whole globe.
/// Throws as read_raster, and DataError (naming a point not covered, and the whole raster's
/// lon/lat extent) when the raster covers only part of the region and no bathy_fill_m is set;
/// a warped raster covers a point within about a cell of its source's cells (its footprint,
/// through GDAL's transformer), so a rotated or projected raster is refused here, before any
/// meshing, for an ocean inside its lon/lat box but off its cells. Messages name options by field.
Raster read_bathymetry(const BathymetryOptions &options, const BathymetryContext &context,
                       const Progress &progress = {}, const Boundary *ocean = nullptr);

/// read_bathymetry with the bathymetry's part and the context of a whole run's options.
inline Raster read_bathymetry(const MeshOptions &options, const Progress &progress = {},
                              const Boundary *ocean = nullptr) {
    return read_bathymetry(bathymetry_options(options), bathymetry_context(options), progress,
                           ocean);
}

} // namespace globemesh

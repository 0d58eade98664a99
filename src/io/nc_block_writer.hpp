// Internal to io/: NcBlockWriter, which defines a netCDF file's variables and writes their rows a
// block at a time, computed on every core (the UGRID and D-Flow FM writers share it), and the
// WGS 84 WKT those files carry.
#pragma once

#include <algorithm>
#include <array>
#include <filesystem>
#include <optional>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include <netcdf.h>

#include "globemesh/progress.hpp"
#include "globemesh/sphere.hpp"
#include "hdf5_chunks.hpp"
#include "lonlat_batch.hpp"
#include "netcdf_handle.hpp"
#include "ordered_blocks.hpp"

namespace globemesh::io {

inline constexpr const char *wgs84_wkt =
    "GEOGCRS[\"WGS 84\",DATUM[\"World Geodetic System 1984\",ELLIPSOID[\"WGS "
    "84\",6378137,298.257223563,"
    "LENGTHUNIT[\"metre\",1]]],PRIMEM[\"Greenwich\",0,ANGLEUNIT[\"degree\",0.0174532925199433]],"
    "CS[ellipsoidal,2],AXIS[\"geodetic latitude "
    "(Lat)\",north,ORDER[1],ANGLEUNIT[\"degree\",0.0174532925199433]],"
    "AXIS[\"geodetic longitude (Lon)\",east,ORDER[2],ANGLEUNIT[\"degree\",0.0174532925199433]],"
    "ID[\"EPSG\",4326]]";

/// Writes the variables of one file; every call checks its status.
///
/// The variables' data are computed and written a block of block_rows rows (one chunk) at a
/// time (in_blocks), on every core (ordered_blocks.hpp). A netCDF-4 file is defined and closed
/// in netCDF-C first (start_data), then each block's rows are shuffled and deflated on the
/// thread that computed them and stored from this one as whole chunks (hdf5_chunks.hpp); a
/// classic file's rows go through netCDF-C as they are.
class NcBlockWriter {
public:
    /// `what` names the output in messages ("UGRID output"); `stage` is its progress stage.
    NcBlockWriter(NcHandle &nc, const std::filesystem::path &temp,
                  const std::filesystem::path &file, bool compress, const Progress &progress,
                  const char *what = "UGRID output", const char *stage = "write_ugrid")
        : nc_(nc), temp_(temp), file_(file), compress_(compress), progress_(progress), what_(what),
          stage_(stage) {}

    int dim(const char *name, std::size_t len) {
        int d;
        nc_check(nc_def_dim(nc_.id(), name, len, &d), file_,
                 std::string("defining dimension ") + name);
        return d;
    }
    int var(const char *name, nc_type type, std::vector<int> dims) {
        int v;
        nc_check(nc_def_var(nc_.id(), name, type, int(dims.size()), dims.data(), &v), file_,
                 std::string("defining variable ") + name);
        if (dims.empty())
            return v;
        Shape shape{name, 0, 1, 0};
        std::vector<std::size_t> lengths(dims.size());
        for (std::size_t k = 0; k < dims.size(); ++k) {
            nc_check(nc_inq_dimlen(nc_.id(), dims[k], &lengths[k]), file_,
                     std::string("sizing ") + name);
            if (k > 0)
                shape.row_values *= lengths[k];
        }
        shape.rows = lengths[0];
        rows_total_ += shape.rows; // every variable with dimensions is written whole, once
        if (compress_) {
            // Chunks of at most block_rows rows, whole rows each: the blocks in_blocks computes.
            // (netCDF's default chunking makes one chunk of a whole variable.)
            shape.chunk_rows = std::max<std::size_t>(1, std::min(shape.rows, block_rows));
            std::vector<std::size_t> chunk = lengths;
            chunk[0] = shape.chunk_rows;
            nc_check(nc_def_var_chunking(nc_.id(), v, NC_CHUNKED, chunk.data()), file_,
                     std::string("chunking ") + name);
            nc_check(nc_def_var_deflate(nc_.id(), v, 1, 1, 1), file_,
                     std::string("compressing ") + name);
        }
        if (shapes_.size() <= std::size_t(v))
            shapes_.resize(std::size_t(v) + 1);
        shapes_[std::size_t(v)] = shape;
        return v;
    }
    void text(int v, const char *name, const std::string &value) {
        nc_check(nc_put_att_text(nc_.id(), v, name, value.size(), value.c_str()), file_,
                 std::string("writing attribute ") + name);
    }
    void ints(int v, const char *name, std::vector<int> values) {
        nc_check(nc_put_att_int(nc_.id(), v, name, NC_INT, values.size(), values.data()), file_,
                 std::string("writing attribute ") + name);
    }
    void dbl(int v, const char *name, double value) {
        nc_check(nc_put_att_double(nc_.id(), v, name, NC_DOUBLE, 1, &value), file_,
                 std::string("writing attribute ") + name);
    }
    bool has_att(int v, const char *name) const {
        return nc_inq_attid(nc_.id(), v, name, nullptr) == NC_NOERR;
    }

    /// After the definitions and the variables without dimensions: a netCDF-4 file is closed
    /// and reopened for its chunks.
    void start_data() {
        if (!compress_)
            return;
        nc_.close(file_, what_);
        chunks_.emplace(temp_, file_, what_);
    }
    /// After the last block: closes the file (throws IoError).
    void finish() {
        if (chunks_)
            chunks_->close();
        else
            nc_.close(file_, what_);
    }

    /// One block's rows of each variable it holds, as compute gives them (in_blocks).
    class Block {
    public:
        /// Rows `first` .. `first + count - 1` (the block's) of variable v, row_values values of
        /// type T (double or int, as the variable) a row; `data` must live until the block is
        /// stored (it is the caller's Buffers).
        template <class T> void put(int v, const T *data, std::size_t count) {
            static_assert(std::is_same_v<T, double> || std::is_same_v<T, int>);
            if (used_ == pieces_.size())
                pieces_.emplace_back();
            Piece &p = pieces_[used_++];
            p.var = v;
            p.rows = count;
            p.is_double = std::is_same_v<T, double>;
            p.data = data;
            if (encoder_) {
                const Shape &s = writer_->shapes_[std::size_t(v)];
                encoder_->encode(data, count, s.chunk_rows, s.row_values * sizeof(T), sizeof(T),
                                 p.chunk);
            }
        }

    private:
        friend class NcBlockWriter;
        struct Piece {
            int var = -1;
            std::size_t rows = 0;
            bool is_double = false;
            const void *data = nullptr;
            std::vector<unsigned char> chunk; ///< encoded (netCDF-4)
        };
        const NcBlockWriter *writer_ = nullptr;
        ChunkEncoder *encoder_ = nullptr;
        std::vector<Piece>
            pieces_; ///< the first used_ are this block's (the rest: buffers to reuse)
        std::size_t used_ = 0;
    };

    /// Computes and stores the blocks of block_rows rows of n (compute_in_order). compute(first,
    /// count, buffers, block) fills `buffers` (its scratch, a Buffers kept from block to block)
    /// and puts each variable's rows into `block`; it runs on every core, for several blocks at
    /// once in any order, so it must only read shared data. The blocks are stored in order.
    template <class Buffers, class Compute> void in_blocks(std::size_t n, const Compute &compute) {
        struct Slot {
            Buffers buffers{};
            Block block;
        };
        compute_in_order<Slot, std::optional<ChunkEncoder>>(
            (n + block_rows - 1) / block_rows,
            [&](std::size_t k, Slot &slot, std::optional<ChunkEncoder> &encoder) {
                if (compress_ && !encoder)
                    encoder.emplace();
                slot.block.writer_ = this;
                slot.block.encoder_ = encoder ? &*encoder : nullptr;
                slot.block.used_ = 0;
                const std::size_t first = k * block_rows;
                compute(first, std::min(block_rows, n - first), slot.buffers, slot.block);
            },
            [&](std::size_t k, const Slot &slot) { store(k * block_rows, slot.block); });
    }

    /// in_blocks for one variable of N values of type T (double or int, as the variable) a row:
    /// row(i) returns row i as std::array<T, N>.
    template <class T, std::size_t N, class Row>
    void put_rows(int v, std::size_t n, const Row &row) {
        in_blocks<std::vector<T>>(
            n, [&](std::size_t first, std::size_t count, std::vector<T> &rows, Block &block) {
                rows.resize(count * N);
                for (std::size_t i = 0; i < count; ++i) {
                    const std::array<T, N> r = row(first + i);
                    std::copy(r.begin(), r.end(), rows.begin() + std::ptrdiff_t(i * N));
                }
                block.put(v, rows.data(), count);
            });
    }
    /// put_rows for a variable of one value per row: value(i) returns row i's value.
    template <class T, class Value> void put_values(int v, std::size_t n, const Value &value) {
        put_rows<T, 1>(v, n, [&](std::size_t i) { return std::array<T, 1>{value(i)}; });
    }

    /// Writes the lon and lat of n points to variables v_lon and v_lat, point(i) giving point i
    /// (a unit vector), each converted once; with `east`, longitudes in [0, 360) (see
    /// io::east_longitudes).
    template <class Point>
    void put_lonlat(int v_lon, int v_lat, std::size_t n, const Point &point, bool east) {
        put_xy(v_lon, v_lat, n, [&](std::size_t i) {
            LonLat p = vec_to_lonlat(point(i));
            p.lon += east && p.lon < 0 ? 360 : 0;
            return p;
        });
    }
    /// put_lonlat for points derived from the nodes (face centres, edge midpoints), converted
    /// by lonlat_batch: within 2 ulp of vec_to_lonlat's, the same bits on every machine.
    template <class Point>
    void put_derived_lonlat(int v_lon, int v_lat, std::size_t n, const Point &point, bool east) {
        using Columns = std::pair<std::vector<Vec3>, std::array<std::vector<double>, 2>>;
        in_blocks<Columns>(n, [&](std::size_t first, std::size_t count, Columns &b, Block &block) {
            b.first.resize(count);
            b.second[0].resize(count);
            b.second[1].resize(count);
            for (std::size_t i = 0; i < count; ++i)
                b.first[i] = point(first + i);
            lonlat_batch(b.first.data(), count, b.second[0].data(), b.second[1].data());
            if (east)
                for (double &lon : b.second[0])
                    lon += lon < 0 ? 360 : 0;
            block.put(v_lon, b.second[0].data(), count);
            block.put(v_lat, b.second[1].data(), count);
        });
    }
    /// Writes the x (lon) and y (lat) of n points to variables v_x and v_y, xy(i) giving point i's
    /// as a LonLat, each computed once.
    template <class XY> void put_xy(int v_x, int v_y, std::size_t n, const XY &xy) {
        using Columns = std::array<std::vector<double>, 2>;
        in_blocks<Columns>(n, [&](std::size_t first, std::size_t count, Columns &b, Block &block) {
            b[0].resize(count);
            b[1].resize(count);
            for (std::size_t i = 0; i < count; ++i) {
                const LonLat p = xy(first + i);
                b[0][i] = p.lon;
                b[1][i] = p.lat;
            }
            block.put(v_x, b[0].data(), count);
            block.put(v_y, b[1].data(), count);
        });
    }

    static constexpr std::size_t block_rows = 65536; ///< rows a block, as the chunks

private:
    struct Shape {
        std::string name;
        std::size_t rows = 0, row_values = 1, chunk_rows = 0;
    };

    /// Stores a computed block whose rows start at `first`, and reports the progress.
    void store(std::size_t first, const Block &block) {
        for (std::size_t i = 0; i < block.used_; ++i) {
            const Block::Piece &p = block.pieces_[i];
            const Shape &s = shapes_[std::size_t(p.var)];
            if (chunks_) {
                chunks_->write(s.name, first, p.chunk);
            } else {
                const std::size_t start[2] = {first, 0}, count[2] = {p.rows, s.row_values};
                const int status = p.is_double
                                       ? nc_put_vara_double(nc_.id(), p.var, start, count,
                                                            static_cast<const double *>(p.data))
                                       : nc_put_vara_int(nc_.id(), p.var, start, count,
                                                         static_cast<const int *>(p.data));
                nc_check(status, file_, "writing " + s.name);
            }
            rows_done_ += p.rows;
            report(progress_, double(rows_done_) / double(std::max<std::size_t>(rows_total_, 1)),
                   stage_);
        }
    }

    NcHandle &nc_;
    const std::filesystem::path &temp_;
    const std::filesystem::path &file_;
    bool compress_;
    const Progress &progress_;
    const char *what_;
    const char *stage_;
    std::vector<Shape> shapes_;                  ///< by variable id (those with dimensions)
    std::optional<Hdf5ChunkFile> chunks_;        ///< a netCDF-4 file's, from start_data
    std::size_t rows_total_ = 0, rows_done_ = 0; ///< rows of all the variables, and written
};

/// The CF grid mapping of WGS 84 longitude/latitude, on the CRS variable v.
inline void wgs84_grid_mapping(NcBlockWriter &w, int v) {
    w.text(v, "grid_mapping_name", "latitude_longitude");
    w.dbl(v, "longitude_of_prime_meridian", 0.0);
    w.dbl(v, "semi_major_axis", 6378137.0);
    w.dbl(v, "inverse_flattening", 298.257223563);
    w.text(v, "crs_wkt", wgs84_wkt);
}

} // namespace globemesh::io

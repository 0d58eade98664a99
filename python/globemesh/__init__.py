"""globemesh from Python: ocean meshes on the sphere from a coastline and a bathymetry.

    import globemesh
    mesh = globemesh.mesh_ocean(coast="land.gpkg", bathy="etopo.nc", hmax="50km", hmin="10km")
    mesh.node_lon, mesh.node_lat, mesh.faces, mesh.depth   # numpy arrays
    mesh.write("ocean.nc")                                  # as `globemesh mesh -o ocean.nc`
    ds = mesh.to_xarray()                                   # the UGRID file as an xarray Dataset

mesh_ocean() takes the options of `globemesh mesh` (see `globemesh help mesh` and globemesh(1))
as keywords: the long option names with "_" for "-" (coast_layer, min_island_area), with the same
units ("20km", "5000m", a bare number is km), defaults and checks, through the command line's own
parser. Errors are the command line's one-line messages, raised as these globemesh.Error (a
RuntimeError):

    UsageError (a ValueError)    a bad option value: exit status 2 at the command line
    IoError (an OSError)         a file that cannot be read or written
    DataError                    inputs that give no mesh
    Cancelled                    the progress callback returned False
and KeyboardInterrupt for Ctrl-C during a run (or the exception the callback raised). GDAL's
warnings during a run (a raster's odd metadata...) come as Python warnings of the class
globemesh.GdalWarning (a UserWarning), not on stderr; the run's own warnings, which the command
line prints (straits closed, a region's ocean in pieces, nodes above sea level), as
globemesh.MeshWarning (a UserWarning).

A run releases the GIL; progress(fraction, stage) is called at most every 50 ms, and Ctrl-C stops
the run there. A cancelled or failed write() leaves no file.
"""

import os as _os
import tempfile as _tempfile

from . import _globemesh
from ._globemesh import Cancelled, DataError, Error, GdalWarning, IoError, MeshWarning, UsageError

for _e in (Cancelled, DataError, Error, GdalWarning, IoError, MeshWarning, UsageError):
    _e.__module__ = __name__  # globemesh.DataError in tracebacks, as users name them
__version__ = _globemesh.__version__
__all__ = ["mesh_ocean", "triangulate", "Result", "Error", "UsageError", "DataError", "IoError",
           "Cancelled", "GdalWarning", "MeshWarning"]

# keyword -> (is a flag, values it takes), from the command line's own option list.
_KEYWORDS = {name: (flag, count) for name, flag, count in _globemesh.mesh_keywords()}


def _number(value):
    """A number as the command line reads it: 3.0 as 3 (for the options that take a count, such
    as passage_cells or smooth), any other float with all its digits."""
    value = float(value)
    return str(int(value)) if value.is_integer() and abs(value) < 2 ** 53 else repr(value)


def _argument(name, value):
    """The command line argument of keyword `name`: --name=value, --flag, or None (default)."""
    flag, count = _KEYWORDS[name]
    option = "--" + name.replace("_", "-")
    if value is None:
        return None
    if flag:
        if isinstance(value, str):  # "false" is a non-empty string: as the command line reads it
            words = {"true": True, "1": True, "yes": True, "false": False, "0": False, "no": False}
            if value.lower() not in words:
                raise ValueError("%s=%r: give True or False" % (name, value))
            value = words[value.lower()]
        return option if value else option + "=false"
    if isinstance(value, bytes):  # a path as bytes (os.fsencode's)
        value = _os.fsdecode(value)
    if isinstance(value, str) and not value:
        raise ValueError("%s='' is empty: give it a value, or None for its default" % name)
    if count > 1 and not isinstance(value, (str, bytes)):
        value = ",".join(_number(v) if isinstance(v, float) else str(v) for v in value)
    elif isinstance(value, _os.PathLike):
        value = _os.fspath(value)
    elif isinstance(value, float):
        value = _number(value)
    return option + "=" + str(value)


def mesh_ocean(coast=None, bathy=None, *, progress=None, **options):
    """Meshes the ocean between the coastlines of `coast` (any OGR source), graded by the options
    of `globemesh mesh` given as keywords (hmax="50km", region=(-12, 48, 12, 64), ...), with depths
    from `bathy` (any GDAL raster) when given. config="run.toml" reads options, the inputs too, from
    a file as `globemesh mesh --config` does (its outputs are not written: a MeshWarning says so);
    keywords override it. `progress(fraction, stage)` is called during the run, from 0 to 1 at its
    end; returning False cancels it (Cancelled). Returns a Result."""
    unknown = sorted(set(options) - set(_KEYWORDS))
    if unknown:
        raise TypeError("mesh_ocean() got an unexpected keyword argument '%s' (it takes: %s)"
                        % (unknown[0], ", ".join(sorted(_KEYWORDS))))
    options.update(coast=coast, bathy=bathy)
    args = [a for a in (_argument(k, v) for k, v in options.items()) if a is not None]
    return Result(_globemesh.mesh_ocean(args, progress))


def triangulate(lon, lat, *, progress=None):
    """The spherical Delaunay triangulation of the points lon, lat (degrees, 1-D arrays of equal
    length), as `globemesh triangulate` makes it: solid triangles only, coincident points merged.
    Returns a Result (boundary edges tagged open when the points leave part of the sphere empty)."""
    return Result(_globemesh.triangulate(lon, lat, progress))


class Result:
    """A mesh. The arrays are read-only numpy views of the library's own (no copies), or computed
    once by the UGRID writer's own code; each equals the variable of the UGRID file named beside it:

        node_lon, node_lat  (nodes,) degrees              mesh_node_lon, mesh_node_lat
        faces               (faces, 3) int32, 0-based     mesh_face_nodes
        edges               (edges, 2) int32              mesh_edge_nodes
        edge_tags           (edges,) 0 interior 1 coast 2 open   boundary_tag
        boundary_edges      (boundary, 2) int32, mesh on the left   mesh_boundary_nodes
        boundary_tags       (boundary,) 1 coast 2 open
        depth               (nodes,) m, positive down, or None without bathymetry   depth
        target_size         (nodes,) km, the size field, or None   target_size
        quality             (faces,) 1 equilateral, 0 degenerate   quality
        face_area           (faces,) m2, geodesic on WGS84          area
        nodes_xyz           (nodes, 3) unit vectors
        node_fields, face_fields   {name: array} of every field
        attributes          {name: text}: the files' global attributes of the run
        report              the command line's --report JSON as a dict
    """

    def __init__(self, mesh):
        self._mesh = mesh

    def __getattr__(self, name):
        if name == "_mesh":  # not set yet (copy.copy makes a Result without __init__)
            raise AttributeError(name)
        return getattr(self._mesh, name)

    def __repr__(self):
        return "<globemesh.Result: %d nodes, %d faces>" % (len(self.nodes_xyz), len(self.faces))

    @property
    def depth(self):
        return self._mesh.node_fields.get("depth")

    @property
    def target_size(self):
        return self._mesh.node_fields.get("target_size")

    @property
    def attributes(self):
        return dict(self._mesh.attributes)

    @property
    def report(self):
        import json
        return json.loads(self._mesh.report_json)

    def write(self, path, format=None, *, overwrite=False, output_srs=None, progress=None,
              **creation_options):
        """Writes the mesh as `globemesh mesh -o PATH [-f FORMAT] [--co KEY=VALUE]...` would: the
        format from the extension or named (UGRID, GPKG, PNG, GMSH, ADCIRC, ...; see globemesh(1),
        OUTPUT FORMATS), creation options as keywords (MSH_VERSION="2.2"). `path` may be a list
        of paths, written together. An existing file is an IoError unless overwrite=True. On an
        error or a cancel no file is left."""
        paths = [path] if isinstance(path, (str, bytes, _os.PathLike)) else list(path)
        paths = [_os.fsdecode(p) for p in paths]
        if not paths:
            raise ValueError("write() was given no path: give a file, or a list of files")
        creation = ["%s=%s" % (k, v) for k, v in creation_options.items()]
        self._mesh.write(paths, format or "", creation, overwrite, output_srs or "", progress)

    def to_xarray(self):
        """The UGRID file as an xarray Dataset: the variables and attributes of the file write()
        makes (it is written by the same writer to a temporary file and read back whole), so that
        xugrid and uxarray read it as they read the file. Needs xarray (Debian: python3-xarray)."""
        try:
            import xarray
        except ImportError as e:
            raise ImportError("Result.to_xarray() needs xarray (Debian: apt install "
                              "python3-xarray; or pip install xarray)") from e
        with _tempfile.TemporaryDirectory(prefix="globemesh-") as folder:
            path = _os.path.join(folder, "mesh.nc")
            self.write(path)
            with xarray.open_dataset(path, mask_and_scale=False) as ds:
                return ds.load()

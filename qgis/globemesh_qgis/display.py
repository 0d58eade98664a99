"""The display copy of a mesh for QGIS. QGIS (MDAL) draws a triangle straight between its corners
in lon/lat, so a face across the antimeridian (corners at 179 and -179) is smeared across the
whole map. The model file keeps its true topology; the plugin loads this copy instead, where such
a face uses copies of its western corners moved by +360 degrees (it then reaches past 180, drawn
where it is). A face round a pole cannot be drawn as a triangle in lon/lat at all and is left
out of the copy. Only the nodes, faces and the node and face variables are kept (QGIS shows no
data on the edges of a 2D mesh). The copy is read from the UGRID file and written with GDAL's
multidimensional API (osgeo.gdal, which QGIS always has), so it needs nothing else."""

import os
import shutil

import numpy
from osgeo import gdal


def seam_faces(lon, faces):
    """Per face: True where it spans more than 180 degrees of longitude."""
    corners = lon[faces]
    return corners.max(axis=1) - corners.min(axis=1) > 180


def unwrap(lon, faces):
    """The display topology: (copied, faces, kept), where copied are the nodes copied at lon + 360
    (appended after the nodes in that order), faces the new face table of the kept faces."""
    corners = lon[faces]
    crossing = seam_faces(lon, faces)
    moved = numpy.where(corners < 0, corners + 360, corners)
    fixed = crossing & (moved.max(axis=1) - moved.min(axis=1) <= 180)
    kept = ~crossing | fixed
    west = fixed[:, None] & (corners < 0)
    copied = numpy.unique(faces[west])
    new = faces.copy()
    new[west] = len(lon) + numpy.searchsorted(copied, faces[west])
    return copied, new[kept].astype(numpy.int32), kept


def may_cross(result):
    """False when no face of the globemesh Result can cross the antimeridian (a quick look at its
    nodes, which treats a node on the antimeridian as a crossing since the file may give it -180)."""
    x, y = result.nodes_xyz[:, 0], result.nodes_xyz[:, 1]
    lon = numpy.degrees(numpy.arctan2(y, x))
    return bool(seam_faces(lon, numpy.asarray(result.faces)).any() or (numpy.abs(lon) > 180 - 1e-9).any())


def display_path(nc):
    """NAME_display.nc beside NAME.nc."""
    root, ext = os.path.splitext(nc)
    return root + "_display" + ext


def remove_display_copy(nc):
    """Removes the display copy of nc (and its style) an earlier run left, which no longer matches nc."""
    root = os.path.splitext(display_path(nc))[0]
    for path in (root + ".nc", root + ".qml"):
        if os.path.exists(path):
            os.remove(path)


def _read(nc):
    """{name: (values, {attribute: value}, dimension names)} of the variables of the UGRID file,
    and its global attributes, read with GDAL."""
    file = gdal.OpenEx(nc, gdal.OF_MULTIDIM_RASTER)
    if file is None:
        raise OSError("%s: GDAL cannot read it: %s" % (nc, gdal.GetLastErrorMsg()))
    root = file.GetRootGroup()
    variables = {}
    for name in root.GetMDArrayNames(["SHOW_ALL=YES"]):  # with crs and mesh, variables without data
        array = root.OpenMDArray(name)
        attributes = {a.GetName(): a.Read() for a in array.GetAttributes()}
        if array.GetUnit():  # GDAL gives units, and takes them, apart from the other attributes
            attributes["units"] = array.GetUnit()
        dims = [d.GetName() for d in array.GetDimensions()]
        variables[name] = (array.ReadAsArray() if dims else None, attributes, dims)
    return variables, {a.GetName(): a.Read() for a in root.GetAttributes()}


_TYPES = {numpy.dtype("float64"): gdal.GDT_Float64, numpy.dtype("int32"): gdal.GDT_Int32}


def _attribute(owner, name, value):
    """Writes attribute `name` (text, a number or a list of numbers) on a GDAL group or array."""
    if isinstance(value, str):
        owner.CreateAttribute(name, [], gdal.ExtendedDataType.CreateString()).Write(value)
        return
    values = numpy.atleast_1d(numpy.asarray(value))
    kind = gdal.GDT_Int32 if values.dtype.kind in "iu" else gdal.GDT_Float64
    shape = [] if numpy.ndim(value) == 0 else [len(values)]
    owner.CreateAttribute(name, shape, gdal.ExtendedDataType.Create(kind)).Write(values.tolist()
                                                                                 if shape else values[0].item())


def _variable(group, dims, name, values, attributes):
    """Writes a variable (a scalar when values is None) with its attributes."""
    kind = _TYPES.get(values.dtype, gdal.GDT_Float64) if values is not None else gdal.GDT_Int32
    array = group.CreateMDArray(name, dims if values is not None else [], gdal.ExtendedDataType.Create(kind))
    for key, value in attributes.items():
        if key == "units":
            array.SetUnit(value)
        elif key != "_FillValue":
            _attribute(array, key, value)
    if values is not None:
        array.Write(numpy.ascontiguousarray(values))


def _write(path, variables, globals_, copied, new_faces, kept):
    """The display copy: crs, mesh, node coordinates, faces and the node and face variables."""
    out = gdal.GetDriverByName("netCDF").CreateMultiDimensional(path, [], ["FORMAT=NC4"])
    if out is None:
        raise OSError("%s: GDAL cannot write it: %s" % (path, gdal.GetLastErrorMsg()))
    group = out.GetRootGroup()
    for key, value in dict(globals_, title="display copy for QGIS (faces across the antimeridian unwrapped); "
                                           "not a model file").items():
        _attribute(group, key, value)
    lon = variables["mesh_node_lon"][0]
    node = group.CreateDimension("nMesh_node", None, None, len(lon) + len(copied))
    face = group.CreateDimension("nMesh_face", None, None, len(new_faces))
    three = group.CreateDimension("Three", None, None, 3)
    _variable(group, [], "crs", None, variables["crs"][1])
    mesh = {k: v for k, v in variables["mesh"][1].items() if k in ("cf_role", "long_name", "topology_dimension")}
    _variable(group, [], "mesh", None, dict(mesh, node_coordinates="mesh_node_lon mesh_node_lat",
                                            face_node_connectivity="mesh_face_nodes", face_dimension="nMesh_face"))
    for name, shift in (("mesh_node_lon", 360), ("mesh_node_lat", 0)):
        values, attributes, _ = variables[name]  # grid_mapping, which GDAL reads as the CRS, given again
        _variable(group, [node], name, numpy.concatenate([values, values[copied] + shift]),
                  dict(attributes, grid_mapping="crs"))
    _variable(group, [face, three], "mesh_face_nodes", new_faces, variables["mesh_face_nodes"][1])
    for name, (values, attributes, _) in variables.items():
        where = attributes.get("location")
        if attributes.get("mesh") != "mesh" or where not in ("node", "face"):
            continue
        attributes = {k: v for k, v in attributes.items() if k != "coordinates"}
        if where == "node":
            attributes["coordinates"] = "mesh_node_lon mesh_node_lat"
        shown = numpy.concatenate([values, values[copied]]) if where == "node" else values[kept]
        _variable(group, [node if where == "node" else face], name, shown, attributes)
    out = None  # closes the file


def write_display_copy(result, nc):
    """Writes the display copy of the globemesh Result (written to nc) beside it, with a copy of
    its QGIS style; returns (path, faces moved, faces left out), or None when no face crosses the
    antimeridian (the file itself draws right; a copy from an earlier run is removed)."""
    path = display_path(nc)
    if not may_cross(result):
        remove_display_copy(nc)
        return None
    variables, globals_ = _read(nc)
    lon, faces = variables["mesh_node_lon"][0], variables["mesh_face_nodes"][0].astype(numpy.int64)
    if not seam_faces(lon, faces).any():
        remove_display_copy(nc)
        return None
    copied, new_faces, kept = unwrap(lon, faces)
    temporary = path + ".part"  # a failed copy leaves no half-written file
    try:
        _write(temporary, variables, globals_, copied, new_faces, kept)
        os.replace(temporary, path)
    finally:
        if os.path.exists(temporary):
            os.remove(temporary)
    style = os.path.splitext(nc)[0] + ".qml"  # the same dataset groups, in the same order
    if os.path.exists(style):
        shutil.copyfile(style, os.path.splitext(path)[0] + ".qml")
    elif os.path.exists(os.path.splitext(path)[0] + ".qml"):
        os.remove(os.path.splitext(path)[0] + ".qml")
    return path, int(seam_faces(lon, faces).sum() - (~kept).sum()), int((~kept).sum())

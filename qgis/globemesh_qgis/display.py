"""The display copy of a mesh for QGIS. QGIS (MDAL) draws a triangle straight between its corners
in lon/lat, so a face across the antimeridian (corners at 179 and -179) is smeared across the
whole map. The model file keeps its true topology; the plugin loads this copy instead, where such
a face uses copies of its western corners moved by +360 degrees (it then reaches past 180, drawn
where it is). A face round a pole cannot be drawn as a triangle in lon/lat at all and is left
out of the copy. Only the nodes, faces and the node and face variables are kept (QGIS shows no
data on the edges of a 2D mesh)."""

import os
import shutil

import numpy


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


def write_display_copy(result, nc):
    """Writes the display copy of the globemesh Result (written to nc) beside it, with a copy of
    its QGIS style; returns (path, faces moved, faces left out), or None when no face crosses the
    antimeridian (the file itself draws right). Needs xarray."""
    if not may_cross(result):
        return None
    import xarray
    ds = result.to_xarray()
    lon, faces = ds["mesh_node_lon"].values, ds["mesh_face_nodes"].values.astype(numpy.int64)
    if not seam_faces(lon, faces).any():
        return None
    path = display_path(nc)
    copied, new_faces, kept = unwrap(lon, faces)
    node, face = "nMesh_node", "nMesh_face"
    out = xarray.Dataset(attrs=dict(ds.attrs, title="display copy for QGIS (faces across the antimeridian "
                                                    "unwrapped); not a model file"))
    out["crs"] = ds["crs"]
    mesh = {k: v for k, v in ds["mesh"].attrs.items() if k in ("cf_role", "long_name", "topology_dimension")}
    out["mesh"] = xarray.DataArray(0, attrs=dict(mesh, node_coordinates="mesh_node_lon mesh_node_lat",
                                                 face_node_connectivity="mesh_face_nodes",
                                                 face_dimension=face))
    for name in ("mesh_node_lon", "mesh_node_lat"):
        values = ds[name].values
        extra = values[copied] + (360 if name == "mesh_node_lon" else 0)
        out[name] = xarray.DataArray(numpy.concatenate([values, extra]), dims=(node,), attrs=ds[name].attrs)
    out["mesh_face_nodes"] = xarray.DataArray(new_faces, dims=(face, "Three"), attrs=ds["mesh_face_nodes"].attrs)
    for name, var in ds.data_vars.items():
        where = var.attrs.get("location")
        if var.attrs.get("mesh") != "mesh" or where not in ("node", "face"):
            continue
        values = var.values
        values = numpy.concatenate([values, values[copied]]) if where == "node" else values[kept]
        attrs = {k: v for k, v in var.attrs.items() if k != "coordinates"}
        attrs["coordinates"] = "mesh_node_lon mesh_node_lat" if where == "node" else None
        out[name] = xarray.DataArray(values, dims=(node if where == "node" else face,),
                                     attrs={k: v for k, v in attrs.items() if v is not None})
    out.to_netcdf(path)
    style = os.path.splitext(nc)[0] + ".qml"  # the same dataset groups, in the same order
    if os.path.exists(style):
        shutil.copyfile(style, os.path.splitext(path)[0] + ".qml")
    return path, int(seam_faces(lon, faces).sum() - (~kept).sum()), int((~kept).sum())

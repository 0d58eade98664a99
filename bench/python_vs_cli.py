#!/usr/bin/python3
"""The Python module against the command line on any inputs: runs `globemesh mesh ARGS -o F.nc`
and globemesh.mesh_ocean() with the same options, compares every array with the file's variable
(netCDF4) and prints both wall times. Usage (PYTHONPATH at build/release/python):
    bench/python_vs_cli.py GLOBEMESH_EXE key=value...   (e.g. coast=land.gpkg hmax=50km)
A flag is key=true; a list (region) is key=W,S,E,N."""

import os
import subprocess
import sys
import tempfile
import time

import netCDF4
import numpy as np

import globemesh

exe, pairs = sys.argv[1], [a.split("=", 1) for a in sys.argv[2:]]
options = {k: (True if v == "true" else v) for k, v in pairs}
args = []
for k, v in options.items():
    args += ["--" + k.replace("_", "-")] + ([] if v is True else [v])
with tempfile.TemporaryDirectory() as folder:
    path = os.path.join(folder, "cli.nc")
    t0 = time.monotonic()
    subprocess.run([exe, "mesh", "-q", *args, "-o", path], check=True, stdout=subprocess.DEVNULL)
    t_cli = time.monotonic() - t0
    options = {k: (tuple(v.split(",")) if k == "region" else v) for k, v in options.items()}
    t0 = time.monotonic()
    mesh = globemesh.mesh_ocean(**options)
    pairs = [("node_lon", "mesh_node_lon"), ("node_lat", "mesh_node_lat"), ("faces", "mesh_face_nodes"),
             ("edges", "mesh_edge_nodes"), ("edge_tags", "boundary_tag"), ("quality", "quality"),
             ("face_area", "area")] + [(n, n) for n in mesh.node_fields]
    arrays = {ours: getattr(mesh, ours) if ours not in mesh.node_fields else mesh.node_fields[ours]
              for ours, _ in pairs}
    t_py = time.monotonic() - t0
    with netCDF4.Dataset(path) as nc:
        same = all(np.array_equal(arrays[o], nc[t][:]) for o, t in pairs)
print("%d nodes, %d faces: %s; command line %.2f s (with writing the file), Python %.2f s (with "
      "the derived arrays)" % (len(mesh.node_lon), len(mesh.faces),
                               "every array equal" if same else "ARRAYS DIFFER", t_cli, t_py))
sys.exit(0 if same else 1)

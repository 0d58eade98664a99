#!/usr/bin/python3
"""One line of the figures the coast sections of RESULTS-coast.md compare, for a mesh written with
--report: nodes, q min, q > 0.8 and size fit (the report's), the shortest edge and the edges
shorter than h/10 and h/32 (h per edge: the mean target_size of its two nodes; lengths: arcs of
mesh_edge_nodes), faces left on land, straits closed (basins cut off) and inlets closed (the
report's attributes).
   bench/coast_figures.py MESH.nc REPORT.json NAME"""
import json, re, sys
import netCDF4, numpy as np

nc, rep, name = sys.argv[1:4]
d = json.load(open(rep))
m, a = d['mesh'], d['attributes']
ds = netCDF4.Dataset(nc)
ds.set_auto_mask(False)
lon, lat = np.radians(ds['mesh_node_lon'][:]), np.radians(ds['mesh_node_lat'][:])
p = np.stack([np.cos(lat) * np.cos(lon), np.cos(lat) * np.sin(lon), np.sin(lat)], 1)
e = ds['mesh_edge_nodes'][:].astype(np.int64) - ds['mesh_edge_nodes'].start_index
u, w = p[e[:, 0]], p[e[:, 1]]
km = 6371.0 * np.arctan2(np.linalg.norm(np.cross(u, w), axis=1), (u * w).sum(1))
size = ds['target_size']
h = 0.5 * (size[:][e[:, 0]] + size[:][e[:, 1]]) / (1000.0 if size.units.strip() == 'm' else 1.0)


def count(key):  # the leading count of a report attribute ("78 (cutting off ...)")
    found = re.match(r'\s*(\d+)', str(a.get(key, '0')))
    return int(found.group(1)) if found else 0


basins = re.search(r'cutting off (\d+) basins', str(a.get('straits_closed', '')))
print(f"{name:14s} n={m['nodes']:>9} qmin={m['quality']['min']:.3f} "
      f"q>0.8={100 * m['quality']['above_0_8']:.3f} fit={100 * m['size_ratio']['in_0_7_1_4']:.2f} "
      f"minedge={1000 * km.min():7.0f}m <h/10={int((km < h / 10).sum()):5d} "
      f"<h/32={int((km < h / 32).sum()):3d} land={count('faces_on_land')} "
      f"straits={count('straits_closed')}({basins.group(1) if basins else 0}) "
      f"inlets={count('inlets_closed')} landat=[{a.get('faces_on_land_at', '')}]")

#!/usr/bin/python3
"""Where parts lose to one part: edges and faces near the lunes' borders (issue 41).

    bench/border_edges.py ONE_PART.nc PARTS.nc N

Counts, within 1 degree of the N parts' borders (the half-meridians at L + 360 k / N degrees, L
the PARTS.nc's parts_border_lon attribute, or -90 + 0.0123456789 in files written before it),
the edges shorter than a quarter and a tenth
of their target size (the mean of their ends' target_size) and the faces below q 0.8, in both
files; then the 1-degree cells (rounded longitude, floored latitude of the edge's midpoint) where
PARTS.nc has the most short edges more than ONE_PART.nc (the border's doing, not a strait's).
Reads the files with netCDF4 (not with globemesh).
"""
import sys

import netCDF4
import numpy as np


def unit(lon_deg, lat_deg):
    lon, lat = np.radians(lon_deg), np.radians(lat_deg)
    return np.stack([np.cos(lat) * np.cos(lon), np.cos(lat) * np.sin(lon), np.sin(lat)], 1)


def border_distance(points, parts, first):
    """Degrees of arc from each point to the nearest border half-plane."""
    out = np.full(len(points), 180.0)
    for k in range(parts):
        lon = np.radians(first + 360.0 * k / parts)
        normal = np.array([-np.sin(lon), np.cos(lon), 0.0])
        toward = np.array([np.cos(lon), np.sin(lon), 0.0])
        d = np.degrees(np.arcsin(np.clip(np.abs(points @ normal), 0, 1)))
        d[points @ toward < 0] = 180.0  # the other half of the great circle is no border
        out = np.minimum(out, d)
    return out


def figures(path, parts, first):
    d = netCDF4.Dataset(path)
    nodes = unit(np.asarray(d['mesh_node_lon'][:]), np.asarray(d['mesh_node_lat'][:]))
    ends = np.asarray(d['mesh_edge_nodes'][:])
    target = np.asarray(d['target_size'][:])
    a, b = nodes[ends[:, 0]], nodes[ends[:, 1]]
    km = 6371.0 * np.arctan2(np.linalg.norm(np.cross(a, b), axis=1), (a * b).sum(1))
    ratio = km / (0.5 * (target[ends[:, 0]] + target[ends[:, 1]]))
    mid = a + b
    mid /= np.linalg.norm(mid, axis=1)[:, None]
    near_edge = border_distance(mid, parts, first) < 1
    faces = unit(np.asarray(d['mesh_face_lon'][:]), np.asarray(d['mesh_face_lat'][:]))
    near_face = border_distance(faces, parts, first) < 1
    q = np.asarray(d['quality'][:])
    short = near_edge & (ratio < 0.25)
    print(f'{path}: within 1 degree of the {parts} borders: edges < h/4 {short.sum()}, '
          f'< h/10 {(near_edge & (ratio < 0.1)).sum()}, faces q < 0.8 '
          f'{(near_face & (q < 0.8)).sum()}')
    return short, mid


def cells(short, mid):
    """Short edges per 1-degree cell (rounded longitude, floored latitude)."""
    lon = np.degrees(np.arctan2(mid[short, 1], mid[short, 0]))
    lat = np.degrees(np.arcsin(mid[short, 2]))
    count = {}
    for x, y in zip(np.round(lon).astype(int), np.floor(lat).astype(int)):
        count[(x, y)] = count.get((x, y), 0) + 1
    return count


def main():
    one, many, parts = sys.argv[1], sys.argv[2], int(sys.argv[3])
    with netCDF4.Dataset(many) as d:
        first = float(getattr(d, 'parts_border_lon', -90 + 0.0123456789))
    print(f'borders at {first} + 360 k / {parts} degrees')
    base = cells(*figures(one, parts, first))
    more = cells(*figures(many, parts, first))
    excess = sorted(((n - base.get(c, 0), c) for c, n in more.items()), reverse=True)[:8]
    print('  cells (lon lat: parts / one part) with the most short edges more:',
          ', '.join(f'{x} {y}: {more[(x, y)]} / {base.get((x, y), 0)}'
                    for d, (x, y) in excess if d > 0))


if __name__ == '__main__':
    main()

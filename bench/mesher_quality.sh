#!/usr/bin/env bash
# Issue 4's quality and fidelity figures on the 1:50m land: the global ocean at a uniform 100 km
# and at the Gulf Stream field (bench/mesher_fields), each judged by mesh-verify (validity,
# face centroids on land, boundary to coast, size fit) and by the script below: q above 0.8, q
# below 0.6 away from coast corners sharper than 60 degrees, and boundary nodes' distance to the
# source coast against h/4 at each node (distances to the source densified every 1 km).
# Usage: bench/mesher_quality.sh [BUILD_DIR] [mesh-verify]   (default build/release)
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-$root/build/release}
verify=${2:-$root/../shared/tools/mesh-verify}
coast=$root/fixtures/coast/ne_50m_land.gpkg
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
for field in uniform:100 gulf-stream; do
    rm -f "$tmp/m.nc"
    "$build/bench/mesher_fields" "$coast" land "$field" "$tmp/m.nc"
    /usr/bin/python3 "$verify" "$tmp/m.nc" --size-var target_size --coast "$coast" --coast-layer land \
        --json "$tmp/v.json" --quiet >/dev/null || true
    /usr/bin/python3 - "$tmp/m.nc" "$tmp/v.json" "$coast" <<'PY'
import json, sys
import numpy as np, netCDF4
from osgeo import ogr
from scipy.spatial import cKDTree
nc, vj, coast = sys.argv[1:4]
v = json.load(open(vj))
ds = netCDF4.Dataset(nc)
lon, lat = (np.radians(np.asarray(ds[n][:], float)) for n in ("mesh_node_lon", "mesh_node_lat"))
X = np.stack([np.cos(lat) * np.cos(lon), np.cos(lat) * np.sin(lon), np.sin(lat)], 1)
fv = ds["mesh_face_nodes"]
F = np.asarray(fv[:]).astype(np.int64) - getattr(fv, "start_index", 0)
h = np.asarray(ds["target_size"][:], float)
q = np.asarray(ds["quality"][:], float)
E = np.sort(np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]]), 1)
u, cnt = np.unique(E, axis=0, return_counts=True)
onb = np.zeros(len(X), bool); onb[u[cnt == 1].ravel()] = True
# Ocean angle at every node; sharp corners: boundary nodes below 60 degrees.
angle = np.zeros(len(X))
for i in range(3):
    p, a, b = X[F[:, i]], X[F[:, (i + 1) % 3]], X[F[:, (i + 2) % 3]]
    s, t = a - p, b - p
    np.add.at(angle, F[:, i], np.arctan2(np.linalg.norm(np.cross(s, t), axis=1), (s * t).sum(1)))
sharp = onb & (angle < np.radians(60))
at_sharp = sharp[F].any(1)
# Source coast densified every 1 km, as unit vectors.
pts = []
src = ogr.Open(coast)
for feat in src.GetLayerByName("land"):
    g = feat.GetGeometryRef()
    polys = [g] if g.GetGeometryName() == "POLYGON" else [g.GetGeometryRef(k) for k in range(g.GetGeometryCount())]
    for poly in polys:
        for r in range(poly.GetGeometryCount()):
            P = np.radians(np.array(poly.GetGeometryRef(r).GetPoints())[:, :2])
            V = np.stack([np.cos(P[:, 1]) * np.cos(P[:, 0]), np.cos(P[:, 1]) * np.sin(P[:, 0]), np.sin(P[:, 1])], 1)
            for a, b in zip(V[:-1], V[1:]):
                n = max(1, int(np.ceil(np.linalg.norm(b - a) * 6371.0)))
                t = np.linspace(0, 1, n, endpoint=False)[:, None]
                w = a * (1 - t) + b * t
                pts.append(w / np.linalg.norm(w, axis=1)[:, None])
d, _ = cKDTree(np.concatenate(pts)).query(X[onb])
ratio = d * 6371.0 / h[onb]
c = v["coast"]
print(f"  mesh-verify: valid {v['valid']}, faces {len(F)}, face centroids on land {c['face_centroids_on_land']}, "
      f"boundary->coast p95 {c['boundary_to_coast']['p95_km']:.1f} km, size fit {100 * v['size_field']['fraction_in_range']:.1f}%")
print(f"  quality: mean {q.mean():.4f}, above 0.8 {100 * (q > 0.8).mean():.2f}% (target 99), "
      f"min {q.min():.3f}, min away from sharp corners {q[~at_sharp].min():.3f} (target 0.6), "
      f"below 0.6 away from them {(q[~at_sharp] < 0.6).sum()}, faces at {sharp.sum()} sharp corners {at_sharp.sum()}")
print(f"  boundary node to source coast / h: p95 {np.quantile(ratio, 0.95):.3f} (target 0.25), max {ratio.max():.3f}")
PY
done

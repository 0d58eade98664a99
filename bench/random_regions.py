#!/usr/bin/python3
"""Random regional meshes over real coasts and bathymetry, judged one by one.

Draws seeded random boxes (--region W,S,E,N): centres on the coast, anywhere, across 180, at the
poles, over inland lakes and on land; widths 0.2-40 degrees, aspect 0.3-3; --hmax chosen from the
box's ocean area for 2e3-3e5 nodes; sometimes --hmin with --bathy, --coast-size, --wavelength,
--slope. Runs each (one at a time, with a timeout), checks the .nc with mesh-verify, compares the
mesh's area with the box's ocean area computed from the same coast with shapely, and classifies:
ok, refusal (an error a user can act on), crash, hang, invalid, internal, area (mesh area far
from the box's ocean area), odd-refusal ("no ocean" for a box with ocean).

Usage: bench/random_regions.py --seed 1 --count 150 --exe build/dev/src/globemesh --out DIR
Writes DIR/results.jsonl (one line a box) and prints a summary table by class. Needs the
GSHHG (/tmp/gshhg) and DCW (/tmp/dcw) land layers and ../shared/data (GM_SHARED).
Run with /usr/bin/python3 (Debian GDAL, shapely 1.8).
"""
import argparse
import json
import math
import os
import random
import subprocess
import sys
import time

import numpy as np
import shapely.affinity
import shapely.ops
import shapely.validation
import shapely.wkb
from osgeo import ogr

ogr.UseExceptions()
R_KM = 6371.0088
SHARED = os.environ.get("GM_SHARED", "/work/shared")
ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
COASTS = {
    "gshhg_l": "/tmp/gshhg/l.gpkg",
    "gshhg_i": "/tmp/gshhg/i.gpkg",
    "gshhg_h": "/tmp/gshhg/h.gpkg",
    "gshhg_f": "/tmp/gshhg/f.gpkg",
    "ne10m": f"{SHARED}/data/ne_10m_land.gpkg",
    "dcw": "/tmp/dcw/dcw.gpkg",
}
ETOPO = f"{SHARED}/data/etopo5_global_10min.nc"
NWSHELF = f"{ROOT}/fixtures/bathy/etopo5_nwshelf_5min.tif"
CUDEM = f"{SHARED}/data/cudem_sabine_equal.nc"
LAKES = {"caspian": (50.5, 42.0), "great_lakes": (-84.0, 45.0), "victoria": (33.0, -1.0)}
INLAND = {"sahara": (15.0, 23.0), "siberia": (100.0, 62.0), "mongolia": (103.0, 46.0),
          "amazon": (-60.0, -8.0)}


def ring_area(xy):
    """Area (km2) inside a ring whose edges are straight in lon/lat degrees."""
    lon = np.radians(xy[:, 0])
    lat = np.radians(xy[:, 1])
    dl = lon[1:] - lon[:-1]
    p1, p2 = lat[:-1], lat[1:]
    dp = p2 - p1
    small = np.abs(dp) < 1e-12
    safe = np.where(small, 1.0, dp)
    term = np.where(small, np.sin(p1) * dl, dl * (np.cos(p1) - np.cos(p2)) / safe)
    return abs(term.sum()) * R_KM * R_KM


def geom_area(g):
    total = 0.0
    for p in getattr(g, "geoms", [g]):
        if p.geom_type == "Polygon":
            total += ring_area(np.asarray(p.exterior.coords))
            total -= sum(ring_area(np.asarray(r.coords)) for r in p.interiors)
        elif hasattr(p, "geoms"):
            total += geom_area(p)
    return total


def lon_spans(w, e):
    return [(w, e)] if w < e else [(w, 180.0), (-180.0, e)]


def box_area(w, s, e, n):
    width = (e - w) if w < e else (e - w + 360.0)
    return math.radians(width) * (math.sin(math.radians(n)) - math.sin(math.radians(s))) * R_KM**2


def land_area(path, w, s, e, n):
    """Area (km2) of the coast's land inside the box, data at any 360-shift of longitude."""
    ds = ogr.Open(path)
    layer = ds.GetLayer("land")
    pieces = []
    for a, b in lon_spans(w, e):
        for k in (-1, 0, 1):
            layer.SetSpatialFilterRect(a + 360 * k, s, b + 360 * k, n)
            for f in layer:
                g = f.GetGeometryRef()
                if g is None:
                    continue
                sg = shapely.wkb.loads(bytes(g.ExportToWkb()))
                if not sg.is_valid:
                    sg = shapely.validation.make_valid(sg)
                c = shapely.ops.clip_by_rect(sg, a + 360 * k, s, b + 360 * k, n)
                if not c.is_empty:
                    pieces.append(shapely.affinity.translate(c, -360 * k, 0))
    layer.SetSpatialFilter(None)
    if not pieces:
        return 0.0
    u = shapely.ops.unary_union([p for p in pieces if p.area > 0] or pieces)
    return geom_area(u)


class Drawer:
    def __init__(self, rng):
        self.rng = rng
        ds = ogr.Open(COASTS["gshhg_l"])
        pts = []
        for f in ds.GetLayer("land"):
            g = shapely.wkb.loads(bytes(f.GetGeometryRef().ExportToWkb()))
            for p in getattr(g, "geoms", [g]):
                pts.append(np.asarray(p.exterior.coords)[:, :2])
        self.coast_pts = np.concatenate(pts)

    def centre(self, kind):
        r = self.rng
        if kind == "coast":
            lon, lat = self.coast_pts[r.randrange(len(self.coast_pts))]
            return ((lon + 180) % 360 - 180, lat)
        if kind == "anywhere":
            return (r.uniform(-180, 180), math.degrees(math.asin(r.uniform(-1, 1))))
        if kind == "antimeridian":
            return (r.choice([-1, 1]) * r.uniform(175, 180), math.degrees(math.asin(r.uniform(-0.9, 0.9))))
        if kind == "lake":
            name = r.choice(sorted(LAKES))
            lon, lat = LAKES[name]
            return (lon + r.uniform(-1, 1), lat + r.uniform(-1, 1))
        if kind == "inland":
            lon, lat = INLAND[r.choice(sorted(INLAND))]
            return (lon + r.uniform(-3, 3), lat + r.uniform(-3, 3))
        raise ValueError(kind)

    def box(self):
        r = self.rng
        kind = r.choices(["coast", "anywhere", "antimeridian", "pole", "lake", "inland", "cudem"],
                         [50, 12, 10, 10, 9, 5, 4])[0]
        width = math.exp(r.uniform(math.log(0.2), math.log(40)))
        aspect = math.exp(r.uniform(math.log(0.3), math.log(3)))
        height = min(width / aspect, 60.0)
        if kind == "cudem":
            w, s = -94.0 + r.uniform(0, 0.1), 29.7 + r.uniform(0, 0.1)
            return kind, (round(w, 4), round(s, 4), round(w + r.uniform(0.05, 0.1), 4),
                          round(s + r.uniform(0.05, 0.1), 4))
        if kind == "pole":
            north = r.random() < 0.5
            if r.random() < 0.4:  # every longitude: the pole inside
                w, e = -180.0, 180.0
            else:
                lon = r.uniform(-180, 180)
                w, e = lon - width / 2, lon + width / 2
            if north:
                s, n = 90 - height, 90.0
            else:
                s, n = -90.0, -90 + height
            return kind, self.wrap(w, s, e, n)
        lon, lat = self.centre(kind)
        w, e = lon - width / 2, lon + width / 2
        s, n = max(lat - height / 2, -90.0), min(lat + height / 2, 90.0)
        return kind, self.wrap(w, s, e, n)

    @staticmethod
    def wrap(w, s, e, n):
        if e - w >= 360:
            return (-180.0, round(s, 4), 180.0, round(n, 4))
        w = (w + 180) % 360 - 180
        e = (e + 180) % 360 - 180
        return (round(w, 4), round(s, 4), round(e, 4), round(n, 4))

    def coast(self, width):
        r = self.rng
        names = ["gshhg_l", "gshhg_i", "gshhg_h", "ne10m", "dcw"]
        if width < 3:
            names.append("gshhg_f")
        return r.choice(names)


def options(rng, kind, box, coast, ocean_km2):
    """Size options for 2e3-3e5 nodes over the box's ocean."""
    target = math.exp(rng.uniform(math.log(2e3), math.log(3e4) if rng.random() < 0.85 else math.log(3e5)))
    area = max(ocean_km2, 0.05 * box_area(*box))
    h = math.sqrt(area / (0.866 * target))
    opts = ["--hmax", f"{h:.4g}km"]
    bathy = None
    w, s, e, n = box
    if kind == "cudem":
        bathy = CUDEM
    elif rng.random() < 0.5:
        inshelf = w < e and -12 < w and e < 13 and 46 < s and n < 62
        bathy = NWSHELF if inshelf and rng.random() < 0.5 else ETOPO
    extra = rng.random()
    if bathy:
        opts += ["--bathy", bathy]
        if extra < 0.3:
            opts += ["--hmin", f"{h / rng.uniform(3, 10):.4g}km", "--wavelength", str(rng.randint(20, 60))]
        elif extra < 0.5:
            opts += ["--hmin", f"{h / rng.uniform(3, 10):.4g}km", "--slope", str(rng.randint(5, 20))]
    if rng.random() < 0.3:
        opts += ["--coast-size", f"{h / rng.uniform(2, 6):.4g}km"]
    if kind == "lake" and rng.random() < 0.5:
        opts += ["--keep-inland-seas"]
    return opts


def run_one(args, i, kind, box, coast, opts, ocean_km2, land_km2):
    out = os.path.join(args.out, f"b{i:03d}.nc")
    rep = os.path.join(args.out, f"b{i:03d}.json")
    for p in (out, rep):
        if os.path.exists(p):
            os.remove(p)
    region = ",".join(f"{v:g}" for v in box)
    cmd = [args.exe, "mesh", "-q", "--overwrite", "--coast", COASTS[coast], "--coast-layer", "land",
           f"--region={region}", *opts, "-o", out, "--report", rep]
    t0 = time.time()
    rec = {"i": i, "kind": kind, "box": box, "coast": coast, "opts": opts,
           "ocean_km2": round(ocean_km2, 1), "land_km2": round(land_km2, 1),
           "cmd": " ".join(cmd)}
    try:
        p = subprocess.run(cmd, capture_output=True, text=True, timeout=args.timeout)
        rec["rc"] = p.returncode
        rec["err"] = (p.stderr.strip().splitlines() or [""])[0][:300]
    except subprocess.TimeoutExpired:
        rec["rc"] = "timeout"
        rec["err"] = ""
    rec["time"] = round(time.time() - t0, 2)
    if rec["rc"] == 0:
        if os.path.exists(rep):
            m = json.load(open(rep))["mesh"]
            rec["nodes"] = m["nodes"]
            rec["qmin"] = round(m["quality"]["min"], 3)
            rec["mesh_km2"] = round(m["area_km2"], 1)
            rec["components"] = json.load(open(rep))["attributes"].get("ocean_components", "")
        if os.path.exists(out):
            vj = out + ".verify.json"
            v = subprocess.run([args.verify, "--quiet", "--json", vj, out], capture_output=True,
                               text=True, timeout=600)
            try:
                vd = json.load(open(vj))
                rec["valid"] = vd.get("valid")
                rec["verify_fail"] = str(vd.get("failures"))[:300]
            except Exception:
                rec["valid"] = None
                rec["verify_fail"] = (v.stdout + v.stderr)[-300:]
        else:
            rec["valid"] = None
    rec["class"] = classify(rec)
    if rec["class"] == "ok" and not args.keep:
        for p in (out, rep, out + ".verify.json"):
            if os.path.exists(p):
                os.remove(p)
    return rec


def classify(rec):
    rc = rec["rc"]
    err = rec.get("err", "")
    if rc == "timeout":
        return "hang"
    if rc < 0 or rc >= 128:
        return "crash"
    if rc != 0:
        if "internal" in err or "invariant" in err or not err.startswith("globemesh:"):
            return "internal"
        if "ocean" in err and rec["ocean_km2"] > 0.02 * box_area(*rec["box"]):
            return "odd-refusal"
        return "refusal"
    if rec.get("valid") is not True:
        return "invalid"
    ocean, mesh = rec["ocean_km2"], rec.get("mesh_km2", 0)
    if ocean > 0 and not (0.85 <= mesh / ocean <= 1.15):
        return "area-dropped" if "dropped" in rec.get("components", "") else "area"
    return "ok"


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--count", type=int, default=150)
    ap.add_argument("--start", type=int, default=0, help="skip the first START boxes (same draws)")
    ap.add_argument("--exe", default=os.path.join(ROOT, "build/dev/src/globemesh"))
    ap.add_argument("--verify", default=f"{SHARED}/tools/mesh-verify")
    ap.add_argument("--out", default="/tmp/random_regions")
    ap.add_argument("--timeout", type=float, default=120)
    ap.add_argument("--keep", action="store_true", help="keep the outputs of boxes that pass")
    ap.add_argument("--only", default="", help="comma-separated box numbers to run")
    ap.add_argument("--summary", action="store_true", help="only summarize DIR/results.jsonl")
    args = ap.parse_args()
    if args.summary:
        summarize(os.path.join(args.out, "results.jsonl"))
        return
    os.makedirs(args.out, exist_ok=True)
    rng = random.Random(args.seed)
    drawer = Drawer(rng)
    only = {int(x) for x in args.only.split(",") if x}
    log = open(os.path.join(args.out, "results.jsonl"), "a")
    for i in range(args.count):
        kind, box = drawer.box()
        width = (box[2] - box[0]) % 360 or 360
        coast = drawer.coast(width)
        land = land_area(COASTS[coast], *box) if (i >= args.start and (not only or i in only)) else 0.0
        ocean = max(box_area(*box) - land, 0.0)
        opts = options(rng, kind, box, coast, ocean)
        if i < args.start or (only and i not in only):
            continue
        rec = run_one(args, i, kind, box, coast, opts, ocean, land)
        log.write(json.dumps(rec) + "\n")
        log.flush()
        print(f"{i:3d} {rec['class']:11s} {kind:12s} {coast:8s} {rec['time']:6.1f}s "
              f"n={rec.get('nodes', '-')} q={rec.get('qmin', '-')} "
              f"area {rec.get('mesh_km2', '-')}/{rec['ocean_km2']} {rec['err'][:100]}", flush=True)
    summarize(os.path.join(args.out, "results.jsonl"))


def summarize(path):
    """Counts by class of the boxes in results.jsonl (a box run twice: its last run)."""
    last = {}
    for line in open(path):
        r = json.loads(line)
        last[r["i"]] = r
    counts = {}
    for r in last.values():
        counts[r["class"]] = counts.get(r["class"], 0) + 1
    print(f"{len(last)} boxes")
    print("class         count")
    for k in sorted(counts):
        print(f"{k:13s} {counts[k]}")


if __name__ == "__main__":
    main()

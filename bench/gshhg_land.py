#!/usr/bin/python3
"""Assembles GSHHG land polygons from GMT's binned shorelines (Debian gmt-gshhg-*).

`gmt coast -Rd -D<res> -W -M` dumps the shoreline cut into pieces at the edges of GMT's bins.
Pieces of one level whose ends meet are joined end to start; a chain whose ends lie on -180 and
180 continues across the antimeridian (longitudes unwrapped past 180, which globemesh wraps
back); Antarctica, the one chain that goes all the way round, is closed through the South Pole.
Only level 1, the land/ocean shoreline, is kept: lakes (level 2) are land to an ocean mesh.
Writes a GeoPackage with one polygon per island or continent (layer 'land', EPSG:4326).
Usage: bench/gshhg_land.py {c,l,i,h,f} OUT.gpkg   (needs Debian's gmt and gmt-gshhg-*)
"""
import argparse, re, subprocess, sys, tempfile
from osgeo import ogr, osr

def pieces(res):
    with tempfile.TemporaryDirectory() as tmp:  # GMT leaves its gmt.history in the working folder
        out = subprocess.run(["gmt", "coast", "-Rd", "-D" + res, "-W", "-M"], check=True,
                             capture_output=True, text=True, cwd=tmp).stdout
    cur, lev = None, None
    for line in out.splitlines():
        if line.startswith(">"):
            if cur: yield lev, bin_, cur
            m = re.match(r">\s*Shore Bin # (\d+), Level (\d+)", line)
            bin_, lev = int(m.group(1)), int(m.group(2)); cur = []
        else:
            x, y = line.split()[:2]
            cur.append((float(x), float(y)))
    if cur: yield lev, bin_, cur

def key(p):
    x = round(p[0], 7)
    if x == -180.0: x = 180.0     # the seam's two sides are one meridian
    return (x, round(p[1], 7))

def assemble(res, level):
    closed, open_ = [], []
    bins = []
    for lev, b, pts in pieces(res):
        if lev != level: continue
        if key(pts[0]) == key(pts[-1]) and len(pts) > 3:
            closed.append(pts)
        else:
            open_.append(pts); bins.append(b)
    by_start = {}
    for i, p in enumerate(open_):
        by_start.setdefault(key(p[0]), []).append(i)
    used = [False] * len(open_)
    for i in range(len(open_)):
        if used[i]: continue
        used[i] = True
        chain, last_bin = list(open_[i]), bins[i]
        while key(chain[-1]) != key(chain[0]):
            # A shore that touches its bin's edge at a vertex leaves and re-enters the same bin
            # there: the continuation is the piece of a neighbouring bin that starts there.
            nxt = [j for j in by_start.get(key(chain[-1]), []) if not used[j] and bins[j] != last_bin]
            if not nxt:
                sys.exit(f"gshhg_land: a piece ends unmatched at {chain[-1]}")
            used[nxt[0]] = True
            last_bin = bins[nxt[0]]
            chain.extend(open_[nxt[0]][1:])
        closed.append(chain)
    return closed

def unwrap(ring):
    """Makes longitudes continuous (a ring crossing 180 goes past it); a ring that goes once round
    the globe (Antarctica) is closed through the South Pole."""
    out = [ring[0]]
    for x, y in ring[1:]:
        px = out[-1][0]
        while x - px > 180: x -= 360
        while x - px < -180: x += 360
        out.append((x, y))
    span = out[-1][0] - out[0][0]
    if abs(span) > 1:                      # went round the pole
        x0, y0 = out[0]; x1, y1 = out[-1]
        out = out[:-1] + [(x1, y1), (x1, -90.0), (x0, -90.0), (x0, y0)]
    shift = 0
    lo = min(p[0] for p in out)
    if lo < -180 - 1e-9: shift = 360
    return [(x + shift, y) for x, y in out]

def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("resolution", choices=list("clihf"))
    ap.add_argument("output")
    a = ap.parse_args()
    rings = assemble(a.resolution, 1)
    drv = ogr.GetDriverByName("GPKG")
    ds = drv.CreateDataSource(a.output)
    srs = osr.SpatialReference(); srs.ImportFromEPSG(4326)
    lyr = ds.CreateLayer("land", srs, ogr.wkbPolygon)
    lyr.StartTransaction()
    for r in rings:
        ring = ogr.Geometry(ogr.wkbLinearRing)
        for x, y in unwrap(r):
            ring.AddPoint_2D(x, y)
        ring.CloseRings()
        poly = ogr.Geometry(ogr.wkbPolygon); poly.AddGeometry(ring)
        f = ogr.Feature(lyr.GetLayerDefn()); f.SetGeometry(poly); lyr.CreateFeature(f)
    lyr.CommitTransaction()
    print(f"gshhg_land: {len(rings)} polygons, {sum(len(r) for r in rings)} vertices -> {a.output}")

main()

#!/usr/bin/python3
"""Writes the Digital Chart of the World's countries (Debian gmt-dcw) as land polygons.

`gmt coast -E=<continent> -M` dumps each country as rings ("> Name Segment k"), longitudes in
0..360 or past 180 where a country crosses the antimeridian. A real source unlike GSHHG or
Natural Earth: the land is many polygons that share their borders (countries side by side,
exclaves, enclaves as separate rings), which globemesh must union. Each ring is an outer ring
(the dump marks no holes); a ring wholly east of 180 is moved to -180..0, one across 180 stays
unwrapped (which globemesh wraps back); Antarctica, a ring all the way round, is closed through
the South Pole. Writes a GeoPackage, layer 'land' (EPSG:4326), one multipolygon per country.
Usage: bench/dcw_land.py OUT.gpkg   (needs Debian's gmt and gmt-dcw)
"""
import argparse, subprocess, tempfile
from osgeo import ogr, osr

CONTINENTS = ["AF", "AN", "AS", "EU", "NA", "OC", "SA"]


def rings(continent):
    with tempfile.TemporaryDirectory() as tmp:  # GMT leaves its gmt.history in the working folder
        out = subprocess.run(["gmt", "coast", "-E=" + continent, "-M"], check=True,
                             capture_output=True, text=True, cwd=tmp).stdout
    name, cur = None, []
    for line in out.splitlines():
        if line.startswith(">"):
            if cur:
                yield name, cur
            name, cur = line[1:].rsplit("Segment", 1)[0].strip(), []
        else:
            x, y = line.split()[:2]
            cur.append((float(x), float(y)))
    if cur:
        yield name, cur


def placed(ring):
    xs = [p[0] for p in ring]
    if max(xs) - min(xs) > 350:  # all the way round: through the South Pole
        jump = max(range(len(ring) - 1), key=lambda i: abs(ring[i + 1][0] - ring[i][0]))
        pts = ring[jump + 1:-1] + ring[:jump + 1]  # from one side of the seam round to the other
        return pts + [(pts[-1][0], -90.0), (pts[0][0], -90.0), pts[0]]
    if min(xs) >= 180:
        return [(x - 360, y) for x, y in ring]
    return ring


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out")
    out = ap.parse_args().out
    countries = {}
    for c in CONTINENTS:
        for name, ring in rings(c):
            if len(ring) >= 4:
                countries.setdefault(name, []).append(placed(ring))
    drv = ogr.GetDriverByName("GPKG")
    ds = drv.CreateDataSource(out)
    srs = osr.SpatialReference()
    srs.ImportFromEPSG(4326)
    layer = ds.CreateLayer("land", srs, ogr.wkbMultiPolygon)
    layer.CreateField(ogr.FieldDefn("name", ogr.OFTString))
    layer.StartTransaction()
    for name, rs in sorted(countries.items()):
        multi = ogr.Geometry(ogr.wkbMultiPolygon)
        for r in rs:
            ring = ogr.Geometry(ogr.wkbLinearRing)
            for x, y in r:
                ring.AddPoint_2D(x, y)
            ring.CloseRings()
            poly = ogr.Geometry(ogr.wkbPolygon)
            poly.AddGeometry(ring)
            multi.AddGeometry(poly)
        f = ogr.Feature(layer.GetLayerDefn())
        f.SetField("name", name)
        f.SetGeometry(multi)
        layer.CreateFeature(f)
    layer.CommitTransaction()
    print(f"dcw_land: {len(countries)} countries, {sum(len(r) for r in countries.values())} rings,"
          f" {sum(len(x) for r in countries.values() for x in r)} points -> {out}")


if __name__ == "__main__":
    main()

#!/usr/bin/python3
"""Synthetic stress case for the coast stage's union (issue 41): a land polygon with N lakes
that overlaps a second polygon (so the two are dissolved together), and N islands apart from
it, as a GeoPackage layer 'land' (EPSG:4326). GEOS 3.11's union places every free hole by a
scan of every shell of the same union: holes x shells, quadratic when both are many (OSM land
polygons spent > 20 min there). Usage: bench/coast_holes.py N OUT.gpkg"""
import sys
from osgeo import ogr, osr


def square(x0, y0, d, clockwise=False):
    ring = ogr.Geometry(ogr.wkbLinearRing)
    pts = [(x0, y0), (x0 + d, y0), (x0 + d, y0 + d), (x0, y0 + d), (x0, y0)]
    for x, y in (reversed(pts) if clockwise else pts):
        ring.AddPoint_2D(x, y)
    return ring


def main(n, path):
    srs = osr.SpatialReference()
    srs.ImportFromEPSG(4326)
    ds = ogr.GetDriverByName("GPKG").CreateDataSource(path)
    layer = ds.CreateLayer("land", srs, ogr.wkbPolygon)
    def add(poly):
        f = ogr.Feature(layer.GetLayerDefn())
        f.SetGeometry(poly)
        layer.CreateFeature(f)
    k = int(n ** 0.5) + 1
    big = ogr.Geometry(ogr.wkbPolygon)  # 10 x 10 degrees, n lakes of 0.3 k-th of a cell
    big.AddGeometry(square(0.0, 0.0, 10.0))
    for c in range(n):
        i, j = divmod(c, k)
        big.AddGeometry(square(0.1 + i * 9.8 / k, 0.1 + j * 9.8 / k, 3.0 / k, clockwise=True))
    add(big)
    other = ogr.Geometry(ogr.wkbPolygon)  # overlaps the big one's corner
    other.AddGeometry(square(9.0, -1.0, 2.0))
    add(other)
    for c in range(n):  # islands of 0.05 degree, 0.1 degree apart, east of it
        island = ogr.Geometry(ogr.wkbPolygon)
        island.AddGeometry(square(20.0 + (c % 200) * 0.1, (c // 200) * 0.1, 0.05))
        add(island)
    layer.SyncToDisk()


if __name__ == "__main__":
    main(int(sys.argv[1]), sys.argv[2])

#!/usr/bin/python3
"""Compares the face areas of UGRID files made by two builds (tools/same-outputs records, or two
files): every other variable must be identical; prints the largest absolute and relative
difference of `area` and its relative difference on the total.
   bench/area_diff.py DIR_A DIR_B   (the *.nc of DIR_A against those of DIR_B)
   bench/area_diff.py A.nc B.nc"""
import pathlib, sys
import netCDF4, numpy as np

a, b = map(pathlib.Path, sys.argv[1:3])
pairs = [(f, b / f.name) for f in sorted(a.glob("*.nc"))] if a.is_dir() else [(a, b)]
bad = 0
for fa, fb in pairs:
    da, db = netCDF4.Dataset(fa), netCDF4.Dataset(fb)
    for v in sorted(set(da.variables) | set(db.variables)):
        if v == "area":
            continue
        x, y = da[v][...], db[v][...]
        if not np.array_equal(np.ma.filled(x, -1), np.ma.filled(y, -1)):
            print(f"{fa.name}: variable {v} differs"); bad += 1
    x, y = np.asarray(da["area"][...], float), np.asarray(db["area"][...], float)
    d = np.abs(x - y)
    print(f"{fa.name}: {x.size} faces, area {x.min():.4g}-{x.max():.4g} m2; max abs diff {d.max():.3g} m2, "
          f"max rel {(d / x).max():.3g}, faces over 1e-9 rel {(d > 1e-9 * x).sum()}; "
          f"total rel diff {abs(x.sum() - y.sum()) / x.sum():.3g}")
sys.exit(1 if bad else 0)

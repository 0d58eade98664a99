#!/usr/bin/python3
"""Compares two GeoPackages written by globemesh, table by table, in SQLite (not through GDAL).

Every row of every table, geometry blobs byte for byte, the spatial indexes' rows and packed
nodes, gpkg_contents (extents), gpkg_ogr_contents (counts) and the schema (sqlite_master), except
the write times (gpkg_contents.last_change, layer_styles.update_time) and mesh_info's "source"
row (the program's version). Exit 0 when equal; prints the first differences otherwise.
  bench/gpkg-compare.py A.gpkg B.gpkg
"""
import sqlite3
import sys

SKIP = {"gpkg_contents": {"last_change"}, "layer_styles": {"update_time"}}


def tables(db):
    return sorted(r[0] for r in db.execute(
        "SELECT name FROM sqlite_master WHERE type = 'table' AND sql NOT LIKE 'CREATE VIRTUAL%'"))


def rows(db, table):
    columns = [r[1] for r in db.execute(f'PRAGMA table_info("{table}")')
               if r[1] not in SKIP.get(table, set())]
    names = ", ".join(f'"{c}"' for c in columns)
    # Sorted: the metadata tables' rows in any order (a feature's row starts with its fid).
    rs = sorted(db.execute(f'SELECT {names} FROM "{table}"').fetchall(), key=repr)
    if table == "mesh_info":
        rs = [r for r in rs if r[columns.index("key")] != "source"]
    return columns, rs


def main(a_path, b_path):
    a, b = sqlite3.connect(a_path), sqlite3.connect(b_path)
    bad = 0
    schema = "SELECT type, name, tbl_name, sql FROM sqlite_master ORDER BY type, name"
    if a.execute(schema).fetchall() != b.execute(schema).fetchall():
        print("schema differs (sqlite_master)")
        bad += 1
    ta, tb = tables(a), tables(b)
    if ta != tb:
        print("tables differ:", sorted(set(ta) ^ set(tb)))
        bad += 1
    for t in sorted(set(ta) & set(tb)):
        (ca, ra), (cb, rb) = rows(a, t), rows(b, t)
        if ca != cb or len(ra) != len(rb):
            print(f"{t}: columns or row count differ ({len(ra)} / {len(rb)} rows)")
            bad += 1
            continue
        diff = [i for i, (x, y) in enumerate(zip(ra, rb)) if x != y]
        for i in diff[:3]:
            print(f"{t}: row {i + 1} differs:\n  {ra[i]!r:.300}\n  {rb[i]!r:.300}")
        if diff:
            print(f"{t}: {len(diff)} of {len(ra)} rows differ")
            bad += 1
        else:
            print(f"{t}: {len(ra)} rows equal")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main(*sys.argv[1:3]))

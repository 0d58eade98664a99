"""The style NAME.qml the command line writes beside NAME.nc, read by Debian's QGIS: opening the .nc
as a mesh layer (as a user does by hand) loads it, and the layer then draws the dataset group of
the variable depth (QGIS names a group by its long_name, read here with netCDF4) with a colour ramp
from 0 to the deepest node. A mesh without depth gets no style; an existing NAME.qml is refused
without --overwrite, leaving no .nc. Exit 77 (ctest: skipped) when QGIS's Python cannot be imported
(a failure under CI=true)."""

import os
import subprocess
import sys
import tempfile

SOURCE = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
FIXTURES = os.path.join(SOURCE, "fixtures")
EXE = os.environ["GLOBEMESH_EXE"]

os.environ["QT_QPA_PLATFORM"] = "offscreen"
try:
    from qgis.core import QgsApplication, QgsMeshDatasetIndex, QgsMeshLayer
except ImportError as e:
    if os.environ.get("CI") == "true":
        sys.exit("QGIS's Python cannot be imported (%s), and CI=true requires it" % e)
    print("SKIPPED: QGIS's Python (Debian: python3-qgis) cannot be imported: %s" % e)
    sys.exit(77)
import netCDF4  # noqa: E402
import numpy  # noqa: E402


def mesh(out, *args, sizes=("--hmax", "500km", "--hmin", "150km")):
    return subprocess.run([EXE, "mesh", "-q", "--coast", os.path.join(FIXTURES, "coast", "ne_110m_land.gpkg"),
                           "--coast-layer", "land", "-o", out] + list(sizes) + list(args),
                          capture_output=True, text=True)


app = QgsApplication([], False)
app.initQgis()
with tempfile.TemporaryDirectory(prefix="globemesh-qml-") as folder:
    etopo = os.path.join(FIXTURES, "bathy", "etopo5_global_10min.nc")
    nwshelf = os.path.join(FIXTURES, "bathy", "etopo5_nwshelf_5min.tif")
    for name, args, sizes in (("global", ["--bathy", etopo], ("--hmax", "500km", "--hmin", "150km")),
                              ("shelf", ["--bathy", nwshelf, "--region", "-12,48,10,62"], ("--hmax", "60km"))):
        nc = os.path.join(folder, name + ".nc")
        run = mesh(nc, *args, sizes=sizes)
        assert run.returncode == 0, run.stderr
        assert os.path.exists(os.path.join(folder, name + ".qml")), os.listdir(folder)
        assert "\nwrote             %s, %s\n" % (nc, os.path.join(folder, name + ".qml")) in run.stdout, run.stdout
        with netCDF4.Dataset(nc) as file:
            long_name, deepest = file["depth"].long_name, numpy.nanmax(file["depth"][:])
            groups = sum(1 for v in file.variables.values() if getattr(v, "location", "") in ("node", "face"))
        layer = QgsMeshLayer(nc, name, "mdal")
        assert layer.isValid() and layer.datasetGroupCount() == groups, (layer.isValid(), layer.datasetGroupCount())
        settings = layer.rendererSettings()
        group = settings.activeScalarDatasetGroup()
        shown = layer.datasetGroupMetadata(QgsMeshDatasetIndex(group)).name()
        assert shown == long_name, (name, shown, long_name)
        assert layer.datasetGroupMetadata(QgsMeshDatasetIndex(0)).name() != long_name  # QGIS's own choice
        scalar = settings.scalarSettings(group)
        assert scalar.classificationMinimum() == 0, scalar.classificationMinimum()
        assert abs(scalar.classificationMaximum() - deepest) < 1e-3 * deepest, (scalar.classificationMaximum(), deepest)
        items = scalar.colorRampShader().colorRampItemList()
        assert len(items) > 2 and items[0].color.lightness() > items[-1].color.lightness()  # deep is dark
        del layer

    # convert writes the style with the depths it reads, and says so.
    converted = os.path.join(folder, "converted.nc")
    run = subprocess.run([EXE, "convert", "-q", os.path.join(folder, "shelf.nc"), converted], capture_output=True,
                         text=True)
    written = "\nwritten           %s, %s\n" % (converted, converted[:-3] + ".qml")
    assert run.returncode == 0 and written in run.stdout, run
    for name in ("converted.nc", "converted.qml"):
        os.remove(os.path.join(folder, name))

    # No bathymetry, no depth: no style.
    run = mesh(os.path.join(folder, "bare.nc"))
    assert run.returncode == 0 and "\nwrote             %s\n" % os.path.join(folder, "bare.nc") in run.stdout, run
    assert sorted(f for f in os.listdir(folder) if f.startswith("bare")) == ["bare.nc"], os.listdir(folder)

    # A NAME.qml already there: refused without --overwrite (one line, exit 1, no .nc), replaced with it.
    nc, qml = os.path.join(folder, "mine.nc"), os.path.join(folder, "mine.qml")
    with open(qml, "w") as f:
        f.write("<qgis/>")
    run = mesh(nc, "--bathy", etopo)
    assert run.returncode == 1 and run.stderr.count("\n") == 1 and "mine.qml" in run.stderr, run.stderr
    assert not os.path.exists(nc) and open(qml).read() == "<qgis/>"
    assert sorted(os.listdir(folder)) == sorted(["bare.nc", "global.nc", "global.qml", "mine.qml", "shelf.nc",
                                                 "shelf.qml"]), os.listdir(folder)
    assert mesh(nc, "--bathy", etopo, "--overwrite").returncode == 0
    assert "mesh-renderer-settings" in open(qml).read()
print("OK")
app.exitQgis()

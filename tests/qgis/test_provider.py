"""The QGIS Processing provider (qgis/globemesh_qgis), headless in Debian's QGIS: the provider
loads with its two algorithms; "Mesh ocean" runs on a coastline layer and a bathymetry layer
opened in a QGIS project, its UGRID file opens in QGIS as a mesh with faces, the checker
../shared/tools/mesh-verify accepts it, and the outputs it asks to load are the mesh (drawn by
depth) and the GeoPackage's layers. Exit 77 (ctest: skipped) when QGIS's Python cannot be
imported or mesh-verify is absent (a failure under CI=true, as tests/support.hpp)."""

import os
import subprocess
import sys
import tempfile

SOURCE = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
FIXTURES = os.path.join(SOURCE, "fixtures")
SHARED = os.environ.get("GLOBEMESH_SHARED_DIR", os.path.join(SOURCE, "..", "shared"))
CHECKER = os.environ.get("GLOBEMESH_MESH_VERIFY", os.path.join(SHARED, "tools", "mesh-verify"))


def skip(why):
    if os.environ.get("CI") == "true":
        sys.exit("%s, and CI=true requires it" % why)
    print("SKIPPED: " + why)
    sys.exit(77)


os.environ["QT_QPA_PLATFORM"] = "offscreen"
try:
    from qgis.core import (QgsApplication, QgsMeshDatasetIndex, QgsMeshLayer, QgsProcessingContext,
                           QgsProcessingFeedback, QgsProject, QgsRasterLayer, QgsVectorLayer)
except ImportError as e:
    skip("QGIS's Python (Debian: python3-qgis) cannot be imported: %s" % e)
if not os.path.exists(CHECKER):
    skip("mesh-verify (%s) is missing" % CHECKER)

app = QgsApplication([], False)
app.initQgis()
sys.path.insert(0, os.path.join(SOURCE, "qgis"))
sys.path.append("/usr/share/qgis/python/plugins")  # Debian's processing
import processing  # noqa: E402
from processing.core.Processing import Processing  # noqa: E402

from globemesh_qgis.provider import GlobemeshProvider  # noqa: E402

Processing.initialize()
provider = GlobemeshProvider()
assert QgsApplication.processingRegistry().addProvider(provider)
assert provider.id() == "globemesh"
names = sorted(a.id() for a in provider.algorithms())
assert names == ["globemesh:meshocean", "globemesh:triangulate"], names

project = QgsProject.instance()
coast = QgsVectorLayer(os.path.join(FIXTURES, "coast", "ne_110m_land.gpkg") + "|layername=land", "land", "ogr")
bathy = QgsRasterLayer(os.path.join(FIXTURES, "bathy", "etopo5_global_10min.nc"), "etopo5")
assert coast.isValid() and bathy.isValid()
project.addMapLayers([coast, bathy])

with tempfile.TemporaryDirectory(prefix="globemesh-qgis-") as folder:
    nc, gpkg = os.path.join(folder, "ocean.nc"), os.path.join(folder, "ocean.gpkg")
    context = QgsProcessingContext()
    context.setProject(project)
    feedback = QgsProcessingFeedback()
    steps = []
    feedback.progressChanged.connect(steps.append)
    result = processing.run("globemesh:meshocean", {"COAST": coast.id(), "BATHY": bathy.id(), "HMAX": 500,
                                                    "HMIN": 150, "OUTPUT": nc, "OUTPUT_GPKG": gpkg},
                            context=context, feedback=feedback)
    assert result == {"OUTPUT": nc, "OUTPUT_GPKG": gpkg}, result
    assert steps and max(steps) > 50, steps  # the run moved the progress bar

    mesh = QgsMeshLayer(nc, "ocean", "mdal")
    assert mesh.isValid() and mesh.meshFaceCount() > 0, (mesh.isValid(), mesh.meshFaceCount())
    status = subprocess.run([CHECKER, nc, "--quiet", "--size-var", "target_size"]).returncode
    assert status == 0, "mesh-verify rejects %s" % nc

    # What it loads when done: the mesh, drawn by depth once Processing post-processes it, and the
    # GeoPackage's faces and boundary.
    loads = context.layersToLoadOnCompletion()
    assert sorted(loads) == sorted([nc, gpkg + "|layername=faces", gpkg + "|layername=boundary"]), sorted(loads)
    def active(layer):
        group = layer.rendererSettings().activeScalarDatasetGroup()
        return layer.datasetGroupMetadata(QgsMeshDatasetIndex(group)).name()

    import netCDF4  # QGIS's reader names a group by its variable's long_name
    with netCDF4.Dataset(nc) as file:
        depth = file["depth"].long_name
    assert active(mesh) != depth  # what QGIS draws by itself
    loads[nc].postProcessor().postProcessLayer(mesh, context, feedback)
    assert active(mesh) == depth, active(mesh)
    for path in loads:
        if path != nc:
            layer = QgsVectorLayer(path, "x", "ogr")
            assert layer.isValid() and layer.featureCount() > 0, path
print("OK: %d faces" % mesh.meshFaceCount())
del mesh, layer, loads, context, feedback  # QGIS's objects go before QGIS does
project.clear()
app.exitQgis()

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
os.environ["GDAL_PAM_ENABLED"] = "NO"  # no .aux.xml beside the fixtures
sys.modules["xarray"] = None  # the plugin's display copy needs no xarray (an import of it fails)
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
    assert {k: v for k, v in result.items() if v} == {"OUTPUT": nc, "OUTPUT_GPKG": gpkg}, result
    # The bar goes up to 100% at the end, the writes after the run (it went back to 0 for them,
    # and the run alone stopped at 97%).
    assert steps and steps == sorted(steps) and steps[-1] == 100, steps

    mesh = QgsMeshLayer(nc, "ocean", "mdal")
    assert mesh.isValid() and mesh.meshFaceCount() > 0, (mesh.isValid(), mesh.meshFaceCount())
    status = subprocess.run([CHECKER, nc, "--quiet", "--size-var", "target_size"]).returncode
    assert status == 0, "mesh-verify rejects %s" % nc

    # What it loads when done: the mesh (this global one through its display copy, as faces cross
    # the antimeridian), drawn by depth, and the GeoPackage's faces and boundary.
    display = os.path.join(folder, "ocean_display.nc")
    loads = context.layersToLoadOnCompletion()
    assert sorted(loads) == sorted([display, gpkg + "|layername=faces", gpkg + "|layername=boundary"]), sorted(loads)
    def active(layer):
        group = layer.rendererSettings().activeScalarDatasetGroup()
        return layer.datasetGroupMetadata(QgsMeshDatasetIndex(group)).name()

    import netCDF4  # QGIS's reader names a group by its variable's long_name
    import numpy
    with netCDF4.Dataset(nc) as file:
        depth = file["depth"].long_name
        lon, faces, depths = file["mesh_node_lon"][:], file["mesh_face_nodes"][:], file["depth"][:]
    assert (numpy.ptp(lon[faces], axis=1) > 180).sum() > 50  # the model file keeps its true topology
    with netCDF4.Dataset(display) as file:  # the copy: the same nodes first, then western copies + 360
        shown_lon, shown_faces, shown_depths = file["mesh_node_lon"][:], file["mesh_face_nodes"][:], file["depth"][:]
    n = len(lon)
    assert (shown_lon[:n] == lon).all() and (shown_depths[:n] == depths).all()
    assert (shown_lon[n:] > 180).all() and (shown_lon[n:] <= 360).all()
    assert (numpy.ptp(shown_lon[shown_faces], axis=1) <= 180).all()
    assert len(faces) - 2 <= len(shown_faces) < len(faces)  # the face round the North Pole left out
    # QGIS draws every loaded file without a face wider than 180 degrees (qgis-check --strict).
    qgis_check = os.path.join(SHARED, "tools", "qgis-check")
    if os.path.exists(qgis_check):
        check = subprocess.run([qgis_check, "--strict", display, gpkg], capture_output=True, text=True)
        assert check.returncode == 0, check.stdout + check.stderr
    shown = QgsMeshLayer(display, "ocean (display)", "mdal")
    assert active(shown) == depth, active(shown)  # by the style ocean_display.qml beside it
    assert active(mesh) == depth, active(mesh)  # by the style ocean.qml beside ocean.nc
    os.remove(os.path.join(folder, "ocean.qml"))
    mesh = QgsMeshLayer(nc, "ocean", "mdal")
    assert active(mesh) != depth  # what QGIS draws by itself
    loads[display].postProcessor().postProcessLayer(mesh, context, feedback)
    assert active(mesh) == depth, active(mesh)
    # The GeoPackage's layers: faces graduated by quality, boundary coast and open in two colours,
    # also when QGIS did not load the faces' style stored in the GeoPackage.
    from qgis.core import QgsCategorizedSymbolRenderer, QgsGraduatedSymbolRenderer
    bare = QgsVectorLayer.LayerOptions()
    bare.loadDefaultStyle = False
    for path in loads:
        if path != display:
            for options in (QgsVectorLayer.LayerOptions(), bare):
                layer = QgsVectorLayer(path, "x", "ogr", options)
                assert layer.isValid() and layer.featureCount() > 0, path
                loads[path].postProcessor().postProcessLayer(layer, context, feedback)
                renderer = layer.renderer()
                if path.endswith("faces"):
                    assert isinstance(renderer, QgsGraduatedSymbolRenderer), renderer
                    assert renderer.classAttribute() == "quality" and len(renderer.ranges()) == 5
                else:
                    assert isinstance(renderer, QgsCategorizedSymbolRenderer), renderer
                    assert renderer.classAttribute() == "tag"
                    colours = {c.value(): c.symbol().color().name() for c in renderer.categories()}
                    assert sorted(colours) == ["coast", "open"] and len(set(colours.values())) == 2, colours
                    tags = {f["tag"] for f in layer.getFeatures()}
                    assert tags <= set(colours), tags  # every feature drawn by a category
    # A regional run into the same file: the display copy of the global one (and its style) goes.
    del shown
    processing.run("globemesh:meshocean", {"COAST": coast.id(), "REGION": "-20,20,30,60 [EPSG:4326]", "HMAX": 500,
                                           "OUTPUT": nc})
    assert sorted(f for f in os.listdir(folder) if f.startswith("ocean_display")) == [], os.listdir(folder)
print("OK: %d faces" % mesh.meshFaceCount())
del mesh, layer, loads, context, feedback  # QGIS's objects go before QGIS does


class Told(QgsProcessingFeedback):
    """A feedback that keeps what the algorithm tells the log."""
    def __init__(self):
        super().__init__()
        self.told = []

    def pushInfo(self, info):  # noqa: N802 (QGIS's name)
        self.told.append(info)


class stderr_to:
    """Sends the process's standard error (file descriptor 2, where C libraries print) to a file."""
    def __init__(self, path):
        self.path = path

    def __enter__(self):
        sys.stderr.flush()
        self.saved = os.dup(2)
        with open(self.path, "w") as file:
            os.dup2(file.fileno(), 2)

    def __exit__(self, *exc):
        sys.stderr.flush()
        os.dup2(self.saved, 2)
        os.close(self.saved)


def nodes_in(nc, west, south, east, north):
    """How many nodes of the UGRID file lie in the box (read with netCDF4, not QGIS)."""
    import netCDF4
    with netCDF4.Dataset(nc) as file:
        lon, lat = file["mesh_node_lon"][:], file["mesh_node_lat"][:]
    return int(((lon >= west) & (lon <= east) & (lat >= south) & (lat <= north)).sum()), len(lon)


# A shapefile without its .prj, its CRS set on the layer in QGIS: the provider passed the file, and
# globemesh refused it ("declares no coordinate reference system; give it with --coast-srs"),
# which Processing offers no way to give. A file that declares the layer's CRS is passed as it is.
from globemesh_qgis.algorithms import _declares  # noqa: E402
from qgis.core import QgsCoordinateReferenceSystem  # noqa: E402
assert _declares(os.path.join(FIXTURES, "coast", "ne_110m_land.gpkg"), "land", QgsCoordinateReferenceSystem("EPSG:4326"))
with tempfile.TemporaryDirectory(prefix="globemesh-qgis-") as folder:
    import shutil
    for ext in ("shp", "shx", "dbf"):
        shutil.copy(os.path.join(FIXTURES, "coast", "ne_110m_land_shp", "ne_110m_land." + ext), folder)
    bare = QgsVectorLayer(os.path.join(folder, "ne_110m_land.shp"), "bare", "ogr")
    bare.setCrs(QgsCoordinateReferenceSystem("EPSG:4326"))
    QgsProject.instance().addMapLayer(bare)
    assert not _declares(bare.source(), None, bare.crs())
    nc = os.path.join(folder, "bare.nc")
    processing.run("globemesh:meshocean", {"COAST": bare.id(), "HMAX": 800, "OUTPUT": nc})
    assert nodes_in(nc, -180, -90, 180, 90)[0] > 0
    QgsProject.instance().removeMapLayer(bare.id())

# An extent across 180, written west above east in lon/lat, or in a CRS whose x runs across it
# (EPSG:3832, the Pacific's Mercator): QGIS swapped the first and took the second's whole band
# of longitudes, and the run meshed about the whole world's band (5012 nodes at -68..170).
with tempfile.TemporaryDirectory(prefix="globemesh-qgis-") as folder:
    for extent in ("170,-170,-50,-30 [EPSG:4326]", "2226390,4452780,-6446276,-3503549 [EPSG:3832]"):
        nc = os.path.join(folder, "pacific.nc")
        processing.run("globemesh:meshocean", {"COAST": coast.id(), "REGION": extent, "HMAX": 200, "OUTPUT": nc})
        import netCDF4
        with netCDF4.Dataset(nc) as file:
            lon = file["mesh_node_lon"][:] % 360
        assert lon.min() >= 169.99 and lon.max() <= 190.01, (extent, lon.min(), lon.max())

# A region (as Processing writes an extent: xmin,xmax,ymin,ymax [crs]) and the selected features only:
# with Great Britain left out of the selection, the sea covers England.
from qgis.core import QgsGeometry, QgsPointXY, QgsProcessingFeatureSourceDefinition, QgsProcessingUtils  # noqa: E402
with tempfile.TemporaryDirectory(prefix="globemesh-qgis-") as folder:
    england = (-2.5, 52, -1, 53.2)  # the Midlands
    for selected in (False, True):
        if selected:
            inland = QgsGeometry.fromPointXY(QgsPointXY(-1.5, 52.8))
            coast.selectByIds([f.id() for f in coast.getFeatures() if not f.geometry().intersects(inland)])
            assert 0 < coast.selectedFeatureCount() < coast.featureCount()
        nc = os.path.join(folder, "region%d.nc" % selected)
        source = QgsProcessingFeatureSourceDefinition(coast.id(), True) if selected else coast.id()
        processing.run("globemesh:meshocean", {"COAST": source, "REGION": "-20,20,30,60 [EPSG:4326]",
                                               "HMAX": 50, "OUTPUT": nc})
        # The whole mesh in the region, up to its parallels: nodes on 60N, and a node the
        # refinement puts on an edge between two of them 0.002 degree poleward at most at 50 km
        # (its north edge had been one great circle, rising to 61.5N midway).
        inside, total = nodes_in(nc, -20.001, 29.999, 20.001, 60.003)
        assert inside == total > 0, (inside, total)
        assert (nodes_in(nc, *england)[0] > 0) == selected, nodes_in(nc, *england)
        assert subprocess.run([CHECKER, nc, "--quiet"]).returncode == 0, "mesh-verify rejects %s" % nc
        assert not os.path.exists(nc.replace(".nc", "_display.nc"))  # no face crosses the antimeridian

    # The region as a polygon layer (its selected feature: the North Sea, not the Java Sea), a
    # size-regions layer whose edge length field is not size_km (15 km in a box off the Netherlands),
    # the world's passages, a channel term, and every model format: QGIS loads the two its reader opens.
    from qgis.core import QgsFeature, QgsProcessingException, QgsRectangle

    def polygons(name, boxes, field=None):
        layer = QgsVectorLayer("Polygon?crs=EPSG:4326" + ("&field=%s:double" % field if field else ""), name, "memory")
        features = []
        for box in boxes:
            feature = QgsFeature(layer.fields())
            feature.setGeometry(QgsGeometry.fromRect(QgsRectangle(*box[:4])))
            feature.setAttributes(list(box[4:]))
            features.append(feature)
        assert layer.dataProvider().addFeatures(features)
        return layer
    regions = polygons("regions", [(-12, 46, 13, 62), (100, -10, 120, 10)])
    sizes = polygons("sizes", [(2, 53, 5, 56, 15.0)], "h")
    project.addMapLayers([regions, sizes])
    regions.selectByIds([1])
    out = {"OUTPUT": os.path.join(folder, "north_sea.nc"), "OUTPUT_MSH": os.path.join(folder, "north_sea.msh"),
           "OUTPUT_ADCIRC": os.path.join(folder, "fort.14"), "OUTPUT_SCHISM": os.path.join(folder, "hgrid.gr3"),
           "OUTPUT_SELAFIN": os.path.join(folder, "north_sea.slf"),
           "OUTPUT_DFLOWFM": os.path.join(folder, "north_sea.nc"), "OUTPUT_FESOM2": os.path.join(folder, "fesom")}
    context = QgsProcessingContext()
    context.setProject(project)
    # QGIS's mesh reader is not asked to open the formats it has no driver for: it printed "ERROR:
    # Status 3: Unable to load mesh" on stderr for each (MDAL's own message, past GDAL's handler).
    with stderr_to(os.path.join(folder, "stderr.txt")):
        result = processing.run("globemesh:meshocean",
                                dict(out, COAST=coast.id(), BATHY=bathy.id(), HMAX=100, HMIN=10,
                                     REGION_LAYER=QgsProcessingFeatureSourceDefinition(regions.id(), True),
                                     SIZE_REGIONS=sizes.id(), SIZE_FIELD="h", DEFAULT_PASSAGES=True, FEATURE_SIZE=2,
                                     PASSAGE_CELLS=3), context=context)
    with open(os.path.join(folder, "stderr.txt")) as printed:
        assert "Unable to load mesh" not in printed.read()
    net = os.path.join(folder, "north_sea_net.nc")  # D-Flow FM's name ending, which picks its format
    assert {k: v for k, v in result.items() if v} == dict(out, OUTPUT_DFLOWFM=net), result
    nc = out["OUTPUT"]
    inside, total = nodes_in(nc, -12.001, 45.999, 13.001, 62.5)
    assert inside == total > 0, (inside, total)
    assert subprocess.run([CHECKER, nc, "--quiet"]).returncode == 0, "mesh-verify rejects %s" % nc
    import netCDF4
    import numpy
    with netCDF4.Dataset(nc) as file:
        configuration = file.globemesh_configuration
        lon, lat, faces = (numpy.asarray(file[v][:]) for v in ("mesh_node_lon", "mesh_node_lat", "mesh_face_nodes"))
    assert 'passages="default"' in configuration  # the world's list, found (else the run fails)
    assert "feature-size=2" in configuration and 'size-regions="' in configuration, configuration
    assert "passage-cells=3" in configuration, configuration  # a count, not "3.0" (refused)
    # The size region: edges of about 15 km inside (km along the meridian and the parallel), over 40 km
    # off Ireland (100 km at most, shorter near the coast).
    def edge_km(where):
        a, b = faces[where][:, 0], faces[where][:, 1]
        dx = (lon[a] - lon[b]) * numpy.cos(numpy.radians(lat[a]))
        return numpy.median(numpy.hypot(dx, lat[a] - lat[b])) * 111.2
    corner_lon, corner_lat = lon[faces[:, 0]], lat[faces[:, 0]]
    boxed = (corner_lon > 2.5) & (corner_lon < 4.5) & (corner_lat > 53.5) & (corner_lat < 55.5)
    atlantic = (corner_lon < -8) & (corner_lat < 58) & (corner_lat > 47)
    assert edge_km(boxed) < 20 and edge_km(atlantic) > 40, (edge_km(boxed), edge_km(atlantic))
    loads = context.layersToLoadOnCompletion()
    assert sorted(loads) == sorted([nc, out["OUTPUT_SELAFIN"], net]), sorted(loads)
    for path in (out["OUTPUT_SELAFIN"], net):
        model = QgsMeshLayer(path, "model", "mdal")
        loads[path].postProcessor().postProcessLayer(model, context, QgsProcessingFeedback())
        assert model.meshFaceCount() == len(faces) and model.crs().authid() == "EPSG:4326", path
    with open(out["OUTPUT_ADCIRC"]) as grid:
        grid.readline()
        assert [int(n) for n in grid.readline().split()[:2]] == [len(faces), len(lon)]
    assert sorted(os.listdir(out["OUTPUT_FESOM2"])) == ["aux3d.out", "elem2d.out", "nod2d.out"]
    assert os.path.getsize(out["OUTPUT_MSH"]) > 0 and os.path.getsize(out["OUTPUT_SCHISM"]) > 0
    del model, loads, context
    for both, why in (({"REGION": "-20,20,30,60 [EPSG:4326]", "REGION_LAYER": regions.id()}, "not both"),
                      ({"PASSAGES": os.path.join(FIXTURES, "passages", "passages.geojson"), "DEFAULT_PASSAGES": True},
                       "not both")):
        try:
            processing.run("globemesh:meshocean", dict(both, COAST=coast.id(), HMAX=500,
                                                       OUTPUT=os.path.join(folder, "both.nc")))
            raise AssertionError("ran with %s" % both)
        except QgsProcessingException as e:
            assert why in str(e), e

    # A path with several polygon layers and no layer named: the first, as QGIS reads it.
    from osgeo import gdal
    two = os.path.join(folder, "two_layers.gpkg")
    for name in ("land", "land_again"):
        gdal.VectorTranslate(two, os.path.join(FIXTURES, "coast", "ne_110m_land.gpkg"), layers=["land"],
                             layerName=name, accessMode="update" if os.path.exists(two) else None)
    nc = os.path.join(folder, "two_layers.nc")
    result = processing.run("globemesh:meshocean", {"COAST": two, "HMAX": 500, "OUTPUT": nc})
    assert {k: v for k, v in result.items() if v} == {"OUTPUT": nc}, result

    # The mesh output named .gpkg or .msh (the format follows the name): a GeoPackage loads as its
    # layers, a gmsh file, which QGIS's mesh reader does not open, is not loaded and the log says
    # so (both were loaded as a mesh layer, invalid).
    for name, expected in (("as.gpkg", ["as.gpkg|layername=boundary", "as.gpkg|layername=faces"]), ("as.msh", [])):
        context, log = QgsProcessingContext(), Told()
        context.setProject(project)
        processing.run("globemesh:meshocean", {"COAST": coast.id(), "HMAX": 800, "OUTPUT": os.path.join(folder, name)},
                       context=context, feedback=log)
        loads = context.layersToLoadOnCompletion()
        assert sorted(os.path.basename(p) for p in loads) == expected, sorted(loads)
        for path in loads:
            layer = QgsVectorLayer(path, "x", "ogr")
            assert loads[path].layerTypeHint == QgsProcessingUtils.LayerHint.Vector and layer.featureCount() > 0
        assert any("does not open this format, so it is not loaded" in t for t in log.told) == (not expected), log.told
    del layer, loads, context, log

    # Cancelled (as the progress bar's Cancel button does): nothing written.
    cancelled = QgsProcessingFeedback()
    cancelled.cancel()
    nc = os.path.join(folder, "cancelled.nc")
    assert processing.run("globemesh:meshocean", {"COAST": coast.id(), "HMAX": 500, "OUTPUT": nc},
                          feedback=cancelled) == {}
    assert not os.path.exists(nc), os.listdir(folder)

    # Triangulate points: 2000 points spread over the whole sphere make 2*2000-4 triangles (Euler).
    points = QgsVectorLayer("file://%s?type=csv&xField=lon&yField=lat&crs=EPSG:4326"
                            % os.path.join(FIXTURES, "points", "stations.csv"), "stations", "delimitedtext")
    assert points.isValid() and points.featureCount() == 2000
    nc = os.path.join(folder, "stations.nc")
    processing.run("globemesh:triangulate", {"POINTS": points, "OUTPUT": nc})
    mesh = QgsMeshLayer(nc, "stations", "mdal")
    assert mesh.meshFaceCount() == 3996 and mesh.meshVertexCount() == 2000, mesh.meshFaceCount()
    assert subprocess.run([CHECKER, nc, "--quiet"]).returncode == 0, "mesh-verify rejects %s" % nc
    del mesh, points
project.clear()
app.exitQgis()

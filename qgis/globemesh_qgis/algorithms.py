"""The algorithms of the provider "globemesh". They run globemesh in-process through its Python
module (import globemesh): a run reports its progress to the progress bar and stops when the
user cancels, and the mesh is written by the command line's own writers (Result.write)."""

import os

from qgis.core import (QgsCoordinateReferenceSystem, QgsFeatureRequest, QgsMeshDatasetIndex, QgsMeshLayer,
                       QgsProcessing, QgsProcessingAlgorithm, QgsProcessingContext, QgsProcessingException,
                       QgsProcessingLayerPostProcessorInterface, QgsProcessingParameterExtent,
                       QgsProcessingParameterFeatureSource, QgsProcessingParameterFileDestination,
                       QgsProcessingParameterNumber, QgsProcessingParameterRasterLayer, QgsProcessingUtils)

from . import display, styles

WGS84 = QgsCoordinateReferenceSystem("EPSG:4326")
GPKG_LAYERS = ("faces", "boundary")  # the GeoPackage's layers loaded into the project


def _globemesh():
    """The Python module globemesh, or a one-line error saying how to get it."""
    try:
        import globemesh
    except ImportError as e:
        raise QgsProcessingException("globemesh's Python module cannot be imported (%s): install globemesh with "
                                     "-DGLOBEMESH_PYTHON=ON, or add its folder to PYTHONPATH" % e)
    return globemesh


def _progress(feedback):
    """A globemesh progress callback that moves QGIS's progress bar and cancels on the user's word."""
    def progress(fraction, stage):
        feedback.setProgress(100.0 * fraction)
        return not feedback.isCanceled()
    return progress


def _long_name(path, variable):
    """The long_name of a NetCDF variable (which QGIS's reader names a dataset group by), or None."""
    from osgeo import gdal
    try:  # GDAL raises or returns None on a failure, as gdal.UseExceptions() was called or not
        file = gdal.OpenEx(path, gdal.OF_MULTIDIM_RASTER)
        array = file.GetRootGroup().OpenMDArray(variable) if file else None
        attribute = array.GetAttribute("long_name") if array else None
        return attribute.ReadAsString() if attribute else None
    except RuntimeError:
        return None


def _first_layer(path):
    """The name of the first layer of an OGR source: the layer QGIS reads from a path that names
    none (globemesh asks for one when there are several)."""
    from osgeo import ogr
    try:
        source = ogr.Open(path)
        return source.GetLayer(0).GetName() if source and source.GetLayerCount() else None
    except RuntimeError:
        return None


def show_depth(layer):
    """Makes the mesh layer draw its dataset group of the variable depth (QGIS draws the first
    group, face area, otherwise). True when it has one."""
    names = {"depth", _long_name(layer.source(), "depth")}
    for group in layer.datasetGroupsIndexes():
        if layer.datasetGroupMetadata(QgsMeshDatasetIndex(group)).name() in names:
            settings = layer.rendererSettings()
            settings.setActiveScalarDatasetGroup(group)
            layer.setRendererSettings(settings)
            return True
    return False


class _Style(QgsProcessingLayerPostProcessorInterface):
    """Styles a loaded layer: the mesh by depth, a GeoPackage layer by styles.STYLES[name]."""
    def __init__(self, gpkg_layer=None):
        super().__init__()
        self.gpkg_layer = gpkg_layer

    def postProcessLayer(self, layer, context, feedback):  # noqa: N802 (QGIS's name)
        if isinstance(layer, QgsMeshLayer):
            show_depth(layer)
        elif self.gpkg_layer in styles.STYLES:
            styles.STYLES[self.gpkg_layer](layer)


# The processing context deletes its post-processors with itself, but holds no Python reference:
# each run's are kept alive here until QGIS has deleted them.
_POST_PROCESSORS = []


def _post_processor(gpkg_layer=None):
    from qgis.PyQt import sip
    _POST_PROCESSORS[:] = [p for p in _POST_PROCESSORS if not sip.isdeleted(p)]
    _POST_PROCESSORS.append(_Style(gpkg_layer))
    return _POST_PROCESSORS[-1]


class _Algorithm(QgsProcessingAlgorithm):
    OUTPUT = "OUTPUT"
    OUTPUT_GPKG = "OUTPUT_GPKG"

    def createInstance(self):  # noqa: N802 (QGIS's name)
        return type(self)()

    def group(self):
        return ""

    def groupId(self):  # noqa: N802
        return ""

    def _add_outputs(self):
        self.addParameter(QgsProcessingParameterFileDestination(self.OUTPUT, "UGRID mesh", "UGRID NetCDF (*.nc)"))
        self.addParameter(QgsProcessingParameterFileDestination(self.OUTPUT_GPKG, "GeoPackage (faces, nodes, boundary)",
                                                                "GeoPackage (*.gpkg)", optional=True,
                                                                createByDefault=False))

    def _write(self, mesh, parameters, context, feedback):
        """Writes the mesh to the outputs chosen, loads them into the project when done, returns them."""
        nc = self.parameterAsFileOutput(parameters, self.OUTPUT, context)
        gpkg = self.parameterAsFileOutput(parameters, self.OUTPUT_GPKG, context)
        paths = [nc] + ([gpkg] if gpkg else [])
        mesh.write(paths, overwrite=True, progress=_progress(feedback))
        name = os.path.splitext(os.path.basename(nc))[0]
        shown = self._display_copy(mesh, nc, feedback)
        details = QgsProcessingContext.LayerDetails(name if shown == nc else name + " (display)", context.project(),
                                                    self.OUTPUT, QgsProcessingUtils.LayerHint.Mesh)
        details.setPostProcessor(_post_processor())
        context.addLayerToLoadOnCompletion(shown, details)
        for layer in GPKG_LAYERS if gpkg else ():
            details = QgsProcessingContext.LayerDetails("%s %s" % (name, layer), context.project(), self.OUTPUT_GPKG,
                                                        QgsProcessingUtils.LayerHint.Vector)
            details.setPostProcessor(_post_processor(layer))
            context.addLayerToLoadOnCompletion("%s|layername=%s" % (gpkg, layer), details)
        return {self.OUTPUT: nc, self.OUTPUT_GPKG: gpkg or None}

    @staticmethod
    def _display_copy(mesh, nc, feedback):
        """The UGRID file to load: nc, or its display copy when faces cross the antimeridian
        (display.py); without xarray, nc with a warning."""
        try:
            copy = display.write_display_copy(mesh, nc)
        except ImportError as e:
            feedback.pushWarning("%s: faces across the antimeridian are drawn smeared across the map (%s: "
                                 "install python3-xarray for a display copy); the GeoPackage's faces draw right"
                                 % (nc, e))
            return nc
        if copy is None:
            return nc
        feedback.pushInfo("%s: display copy of %s for QGIS: %d faces across the antimeridian unwrapped, %d round "
                          "a pole left out (a model reads %s)" % (copy[0], nc, copy[1], copy[2], nc))
        return copy[0]

    def _run(self, run, parameters, context, feedback):
        """The outputs of the mesh that run(globemesh, progress) makes, with globemesh's errors as
        Processing's; a cancelled run writes nothing."""
        globemesh = _globemesh()
        try:
            mesh = run(globemesh, _progress(feedback))
            return self._write(mesh, parameters, context, feedback)
        except globemesh.Cancelled:
            feedback.pushInfo("cancelled: nothing written")
            return {}
        except globemesh.Error as e:
            raise QgsProcessingException(str(e))


class MeshOcean(_Algorithm):
    COAST = "COAST"
    BATHY = "BATHY"
    REGION = "REGION"
    HMAX = "HMAX"
    HMIN = "HMIN"

    def name(self):
        return "meshocean"

    def displayName(self):  # noqa: N802 (QGIS's name)
        return "Mesh ocean"

    def shortHelpString(self):  # noqa: N802
        return ("Meshes the ocean between the coastlines of a polygon layer (its selected features when "
                "'selected features only' is checked) on the sphere, as `globemesh mesh` does: edges of at "
                "most hmax km, graded down to hmin km, with the depths of the bathymetry raster when given. "
                "The region, when given, is turned into longitudes and latitudes (EPSG:4326). "
                "The UGRID mesh is loaded showing depth; when faces cross the antimeridian, through a display "
                "copy NAME_display.nc that QGIS draws without smearing them (the UGRID file is the model's).")

    def initAlgorithm(self, config=None):  # noqa: N802
        self.addParameter(QgsProcessingParameterFeatureSource(self.COAST, "Coastline (land polygons)",
                                                              [QgsProcessing.TypeVectorPolygon]))
        self.addParameter(QgsProcessingParameterRasterLayer(self.BATHY, "Bathymetry", optional=True))
        self.addParameter(QgsProcessingParameterExtent(self.REGION, "Region (whole globe when empty)", optional=True))
        self.addParameter(QgsProcessingParameterNumber(self.HMAX, "Largest edge length (km)",
                                                       QgsProcessingParameterNumber.Double, 50.0, minValue=0.0))
        self.addParameter(QgsProcessingParameterNumber(self.HMIN, "Smallest edge length (km; 0: max(hmax/1000, 10 m))",
                                                       QgsProcessingParameterNumber.Double, 0.0, minValue=0.0))
        self._add_outputs()

    def _options(self, parameters, context, feedback):
        """The keywords of globemesh.mesh_ocean() given by the parameters."""
        coast, layer = self.parameterAsCompatibleSourceLayerPathAndLayerName(
            parameters, self.COAST, context, ["gpkg", "shp"], "gpkg", feedback)
        options = {"coast": coast, "coast_layer": layer or _first_layer(coast),
                   "hmax": "%rkm" % self.parameterAsDouble(parameters, self.HMAX, context),
                   "hmin": "%rkm" % self.parameterAsDouble(parameters, self.HMIN, context)}
        bathy = self.parameterAsRasterLayer(parameters, self.BATHY, context)
        if bathy is not None:
            if bathy.providerType() != "gdal":  # globemesh reads the raster with GDAL, by its source
                raise QgsProcessingException("bathymetry layer %s: not a GDAL raster (provider %s); save it as a "
                                             "GeoTIFF first" % (bathy.name(), bathy.providerType()))
            options["bathy"] = bathy.source()
        if parameters.get(self.REGION):
            r = self.parameterAsExtent(parameters, self.REGION, context, WGS84)
            options["region"] = (r.xMinimum(), r.yMinimum(), r.xMaximum(), r.yMaximum())
        return options

    def processAlgorithm(self, parameters, context, feedback):  # noqa: N802
        options = self._options(parameters, context, feedback)
        feedback.pushInfo("globemesh.mesh_ocean(%s)" % ", ".join("%s=%r" % kv for kv in options.items()))
        return self._run(lambda globemesh, progress: globemesh.mesh_ocean(progress=progress, **options),
                         parameters, context, feedback)


class TriangulatePoints(_Algorithm):
    POINTS = "POINTS"

    def name(self):
        return "triangulate"

    def displayName(self):  # noqa: N802 (QGIS's name)
        return "Triangulate points"

    def shortHelpString(self):  # noqa: N802
        return ("The spherical Delaunay triangulation of a point layer (its selected features when "
                "'selected features only' is checked), as `globemesh triangulate` makes it: coincident "
                "points merged, boundary edges tagged open where the points leave part of the sphere empty.")

    def initAlgorithm(self, config=None):  # noqa: N802
        self.addParameter(QgsProcessingParameterFeatureSource(self.POINTS, "Points",
                                                              [QgsProcessing.TypeVectorPoint]))
        self._add_outputs()

    def _lon_lat(self, parameters, context):
        """The longitudes and latitudes (EPSG:4326) of every vertex of the point layer."""
        source = self.parameterAsSource(parameters, self.POINTS, context)
        if source is None:
            raise QgsProcessingException(self.invalidSourceError(parameters, self.POINTS))
        request = QgsFeatureRequest().setDestinationCrs(WGS84, context.transformContext())
        request.setNoAttributes()
        lon, lat = [], []
        for feature in source.getFeatures(request):
            for point in feature.geometry().vertices():
                lon.append(point.x())
                lat.append(point.y())
        return lon, lat

    def processAlgorithm(self, parameters, context, feedback):  # noqa: N802
        import numpy
        lon, lat = (numpy.asarray(v, dtype=float) for v in self._lon_lat(parameters, context))
        feedback.pushInfo("globemesh.triangulate(%d points)" % len(lon))
        return self._run(lambda globemesh, progress: globemesh.triangulate(lon, lat, progress=progress),
                         parameters, context, feedback)

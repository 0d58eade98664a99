"""The algorithms of the provider "globemesh". They run globemesh in-process through its Python
module (import globemesh): a run reports its progress to the progress bar and stops when the
user cancels, and the mesh is written by the command line's own writers (Result.write)."""

import os
import re
import warnings

from qgis.core import (QgsCoordinateReferenceSystem, QgsCoordinateTransform, QgsExpression, QgsFeatureRequest,
                       QgsMeshDatasetIndex, QgsMeshLayer, QgsPointXY, QgsProcessing, QgsProcessingAlgorithm,
                       QgsProcessingContext,
                       QgsProcessingException, QgsProcessingLayerPostProcessorInterface, QgsProcessingParameterBoolean,
                       QgsProcessingParameterCrs, QgsProcessingParameterDefinition, QgsProcessingParameterExtent,
                       QgsProcessingParameterFeatureSource, QgsProcessingParameterField,
                       QgsProcessingParameterFileDestination, QgsProcessingParameterFolderDestination,
                       QgsProcessingParameterNumber, QgsProcessingParameterRasterLayer, QgsProcessingUtils)

from . import display, styles

WGS84 = QgsCoordinateReferenceSystem("EPSG:4326")
GPKG_LAYERS = ("faces", "boundary")  # the GeoPackage's layers loaded into the project
# The model formats, each an optional output: (parameter, description, file filter, the name's
# ending that picks the format at the command line). QGIS loads those its reader (MDAL) opens.
MODEL_OUTPUTS = (("OUTPUT_MSH", "gmsh mesh (MSH 4.1)", "gmsh MSH (*.msh)", ".msh"),
                 ("OUTPUT_ADCIRC", "ADCIRC grid (fort.14)", "ADCIRC grid (*.14)", ".14"),
                 ("OUTPUT_SCHISM", "SCHISM grid (hgrid.gr3)", "SCHISM grid (*.gr3)", ".gr3"),
                 ("OUTPUT_SELAFIN", "TELEMAC SELAFIN (.slf, and its boundary file .cli)", "SELAFIN (*.slf)", ".slf"),
                 ("OUTPUT_DFLOWFM", "D-Flow FM network file (_net.nc)", "D-Flow FM network (*_net.nc)", "_net.nc"))
OUTPUT_FESOM2 = "OUTPUT_FESOM2"  # a folder (nod2d.out, elem2d.out, aux3d.out)
OUTPUT_SRS = "OUTPUT_SRS"


def _globemesh():
    """The Python module globemesh, or a one-line error saying how to get it."""
    try:
        import globemesh
    except ImportError as e:
        raise QgsProcessingException("globemesh's Python module cannot be imported (%s): install globemesh with "
                                     "-DGLOBEMESH_PYTHON=ON, or add its folder to PYTHONPATH" % e)
    return globemesh


# The run's share of the progress bar, the writes having the rest: the command line's for a UGRID
# output (its writer's progress_weight 1.5 to the run's 1, src/io/writers.cpp).
RUN_SHARE = 0.4


def _progress(feedback, lo=0.0, hi=1.0):
    """A globemesh progress callback that moves QGIS's progress bar over [lo, hi] of it and cancels
    on the user's word."""
    def progress(fraction, stage):
        feedback.setProgress(100.0 * (lo + (hi - lo) * fraction))
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


def with_ending(path, ending):
    """path, made to end with `ending` (what picks its format): NAME.nc -> NAME_net.nc, NAME -> NAME.14."""
    if path.lower().endswith(ending):
        return path
    root, ext = os.path.splitext(path)
    return (root if ext and ending.endswith(ext.lower()) else path) + ending


def output_format(path):
    """What globemesh writes to `path`, by the name's ending as the command line picks the format
    (src/io/writers.cpp; _net.nc is D-Flow FM's): "UGRID", "GPKG" or "model" (any other)."""
    lower = path.lower()
    if lower.endswith((".nc", ".nc4")) and not lower.endswith("_net.nc"):
        return "UGRID"
    return "GPKG" if lower.endswith(".gpkg") else "model"


def _mesh_endings():
    """The name endings of the files QGIS's mesh reader (MDAL) has a driver for ("*.slf" in its
    file filters: .slf and .nc, not .msh, .14, .gr3)."""
    from qgis.core import QgsProviderRegistry
    return tuple(p[1:].lower() for p in re.findall(r"\*\.[\w.]+", QgsProviderRegistry.instance().fileMeshFilters()))


def loads_in_qgis(path):
    """Whether QGIS's mesh reader (MDAL) opens the file, without GDAL's messages about the formats
    it tries. A file no MDAL driver claims by its ending is not tried: MDAL prints "Unable to load
    mesh" on stderr for it, past GDAL's error handler."""
    if not path.lower().endswith(_mesh_endings()):
        return False
    from osgeo import gdal
    gdal.PushErrorHandler("CPLQuietErrorHandler")
    try:
        return QgsMeshLayer(path, "probe", "mdal").isValid()
    finally:
        gdal.PopErrorHandler()


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
    """Styles a loaded layer: the mesh by depth (in its CRS when given: a model file's), a
    GeoPackage layer by styles.STYLES[name]."""
    def __init__(self, gpkg_layer=None, crs=None):
        super().__init__()
        self.gpkg_layer = gpkg_layer
        self.crs = crs

    def postProcessLayer(self, layer, context, feedback):  # noqa: N802 (QGIS's name)
        if isinstance(layer, QgsMeshLayer):
            if self.crs is not None and self.crs.isValid():
                layer.setCrs(self.crs)
            show_depth(layer)
        elif self.gpkg_layer in styles.STYLES:
            styles.STYLES[self.gpkg_layer](layer)


# The processing context deletes its post-processors with itself, but holds no Python reference:
# each run's are kept alive here until QGIS has deleted them.
_POST_PROCESSORS = []


def _post_processor(gpkg_layer=None, crs=None):
    from qgis.PyQt import sip
    _POST_PROCESSORS[:] = [p for p in _POST_PROCESSORS if not sip.isdeleted(p)]
    _POST_PROCESSORS.append(_Style(gpkg_layer, crs))
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
        for name, description, filter, _ in MODEL_OUTPUTS:
            self.addParameter(QgsProcessingParameterFileDestination(name, description, filter, optional=True,
                                                                    createByDefault=False))
        self.addParameter(QgsProcessingParameterFolderDestination(OUTPUT_FESOM2, "FESOM2 mesh folder", optional=True,
                                                                  createByDefault=False))
        srs = QgsProcessingParameterCrs(OUTPUT_SRS, "CRS of the model formats' coordinates (lon/lat when empty)",
                                        optional=True)
        srs.setFlags(srs.flags() | QgsProcessingParameterDefinition.FlagAdvanced)
        self.addParameter(srs)

    def _outputs(self, parameters, context):
        """{parameter: path} of the outputs asked for (the model formats' names made to end as their
        format asks), in the order written."""
        outputs = {self.OUTPUT: self.parameterAsFileOutput(parameters, self.OUTPUT, context)}
        for name, ending in [(self.OUTPUT_GPKG, ".gpkg")] + [(m[0], m[3]) for m in MODEL_OUTPUTS]:
            path = self.parameterAsFileOutput(parameters, name, context)
            if path:
                outputs[name] = with_ending(path, ending)
        folder = self.parameterAsFileOutput(parameters, OUTPUT_FESOM2, context)
        if folder:
            outputs[OUTPUT_FESOM2] = folder
        return outputs

    def _write(self, mesh, parameters, context, feedback):
        """Writes the mesh to the outputs chosen, loads them into the project when done, returns them."""
        outputs = self._outputs(parameters, context)
        srs = self.parameterAsCrs(parameters, OUTPUT_SRS, context) if parameters.get(OUTPUT_SRS) else None
        mesh.write(list(outputs.values()), "FESOM2" if OUTPUT_FESOM2 in outputs else None, overwrite=True,
                   output_srs=srs.authid() or srs.toWkt() if srs and srs.isValid() else None,
                   progress=_progress(feedback, RUN_SHARE, 1.0))
        nc = outputs[self.OUTPUT]
        name = os.path.splitext(os.path.basename(nc))[0]
        format = output_format(nc)
        if format == "UGRID":
            shown = self._display_copy(mesh, nc, feedback)
            self._load(shown, name if shown == nc else name + " (display)", self.OUTPUT, context, _post_processor())
        elif format == "GPKG":  # the UGRID output named .gpkg: a GeoPackage, loaded as one
            self._load_gpkg(nc, name, self.OUTPUT, context)
        else:
            self._load_model(nc, self.OUTPUT, srs, context, feedback)
        if self.OUTPUT_GPKG in outputs:
            self._load_gpkg(outputs[self.OUTPUT_GPKG], name, self.OUTPUT_GPKG, context)
        self._load_models(outputs, srs, context, feedback)
        results = {p: outputs.get(p) for p in [self.OUTPUT, self.OUTPUT_GPKG] + [m[0] for m in MODEL_OUTPUTS]}
        results[OUTPUT_FESOM2] = outputs.get(OUTPUT_FESOM2)
        return results

    @staticmethod
    def _load(path, name, output, context, post_processor, hint=QgsProcessingUtils.LayerHint.Mesh):
        details = QgsProcessingContext.LayerDetails(name, context.project(), output, hint)
        details.setPostProcessor(post_processor)
        context.addLayerToLoadOnCompletion(path, details)

    def _load_gpkg(self, path, name, output, context):
        """Loads the GeoPackage's layers GPKG_LAYERS, each styled."""
        for layer in GPKG_LAYERS:
            self._load("%s|layername=%s" % (path, layer), "%s %s" % (name, layer), output, context,
                       _post_processor(layer), QgsProcessingUtils.LayerHint.Vector)

    def _load_model(self, path, output, srs, context, feedback):
        """Loads a model file if QGIS reads it (in its CRS: the one asked, else lon/lat); says so if not."""
        if loads_in_qgis(path):
            self._load(path, os.path.basename(path), output, context, _post_processor(crs=srs or WGS84))
        else:
            feedback.pushInfo("%s: written; QGIS's mesh reader does not open this format, so it is not loaded"
                              % path)

    def _load_models(self, outputs, srs, context, feedback):
        """Loads the model files asked for that QGIS reads."""
        for name, _, _, _ in MODEL_OUTPUTS:
            if outputs.get(name) is not None:
                self._load_model(outputs[name], name, srs, context, feedback)

    @staticmethod
    def _display_copy(mesh, nc, feedback):
        """The UGRID file to load: nc, or its display copy when faces cross the antimeridian
        (display.py); nc with a warning when the copy cannot be written."""
        try:
            copy = display.write_display_copy(mesh, nc)
        except (OSError, RuntimeError) as e:
            feedback.pushWarning("%s: faces across the antimeridian are drawn smeared across the map (no display "
                                 "copy: %s); the GeoPackage's faces draw right" % (nc, e))
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
            with warnings.catch_warnings(record=True) as caught:  # the run's, as the log's warnings
                warnings.simplefilter("always")
                mesh = run(globemesh, _progress(feedback, 0.0, RUN_SHARE))
            for w in caught:
                feedback.pushWarning(str(w.message))
            return self._write(mesh, parameters, context, feedback)
        except globemesh.Cancelled:
            feedback.pushInfo("cancelled: nothing written")
            return {}
        except globemesh.Error as e:
            raise QgsProcessingException(str(e))


def _declares(path, layer, crs):
    """Whether the file's layer declares `crs` (a QgsCoordinateReferenceSystem), as OGR reads it."""
    from osgeo import ogr
    data = ogr.Open(path)
    found = data and (data.GetLayerByName(layer) if layer else data.GetLayer(0))
    srs = found.GetSpatialRef() if found else None
    return srs is not None and QgsCoordinateReferenceSystem.fromWkt(srs.ExportToWkt()) == crs


# The size and coast options beside hmax and hmin: (parameter, keyword, description, default
# (globemesh's), unit, advanced). A value other than the default is passed on.
NUMBER_OPTIONS = (("FEATURE_SIZE", "feature_size", "Elements across every channel (3 as OceanMesh2D; 0: off)", 0, "",
                   False),
                  ("WAVELENGTH", "wavelength", "Points per tidal wavelength, from the bathymetry (0: off)", 0, "",
                   False),
                  ("SLOPE", "slope", "Points per topographic length scale, from the bathymetry (0: off)", 0, "", False),
                  ("GRADE", "grade", "Gradation: largest growth of the edge length (km/km)", 0.15, "", False),
                  ("COAST_SIZE", "coast_size", "Edge length at the coast (km; 0: off)", 0, "km", True),
                  ("COAST_RATE", "coast_rate", "Growth of the edge length away from the coast (km/km)", 0.1, "", True),
                  ("MIN_ISLAND_AREA", "min_island_area", "Drop islands and lakes smaller than (km2)", 0, "km2", True),
                  ("PASSAGE_CELLS", "passage_cells", "Edges across each passage", 2, "", True))


class MeshOcean(_Algorithm):
    COAST = "COAST"
    BATHY = "BATHY"
    REGION = "REGION"
    REGION_LAYER = "REGION_LAYER"
    HMAX = "HMAX"
    HMIN = "HMIN"
    SIZE_REGIONS = "SIZE_REGIONS"
    SIZE_FIELD = "SIZE_FIELD"
    PASSAGES = "PASSAGES"
    DEFAULT_PASSAGES = "DEFAULT_PASSAGES"
    KEEP_INLAND_SEAS = "KEEP_INLAND_SEAS"

    def name(self):
        return "meshocean"

    def displayName(self):  # noqa: N802 (QGIS's name)
        return "Mesh ocean"

    def shortHelpString(self):  # noqa: N802
        return ("Meshes the ocean between the coastlines of a polygon layer (its selected features when "
                "'selected features only' is checked) on the sphere, as `globemesh mesh` does: edges of at "
                "most hmax km, graded down to hmin km, with the depths of the bathymetry raster when given. "
                "The region is an extent (turned into longitudes and latitudes, EPSG:4326) or a polygon layer "
                "(--region-file), not both. Size regions are polygons whose field (size_km by default) gives the "
                "edge length in km inside (--size-regions). Passages are lines across straits kept open: a line "
                "layer, or the world's critical passages (--passages default). Each layer's selection is "
                "honoured. The other numbers are those of `globemesh help mesh`; 0 switches a term off. "
                "The UGRID mesh is loaded showing depth; when faces cross the antimeridian, through a display "
                "copy NAME_display.nc that QGIS draws without smearing them (the UGRID file is the model's). "
                "The model formats asked for are written with it; QGIS loads those it reads (SELAFIN, D-Flow FM).")

    def initAlgorithm(self, config=None):  # noqa: N802
        self.addParameter(QgsProcessingParameterFeatureSource(self.COAST, "Coastline (land polygons)",
                                                              [QgsProcessing.TypeVectorPolygon]))
        self.addParameter(QgsProcessingParameterRasterLayer(self.BATHY, "Bathymetry", optional=True))
        self.addParameter(QgsProcessingParameterExtent(self.REGION, "Region (whole globe when empty)", optional=True))
        self.addParameter(QgsProcessingParameterFeatureSource(self.REGION_LAYER, "Region as polygons (instead of the "
                                                              "extent)", [QgsProcessing.TypeVectorPolygon],
                                                              optional=True))
        self.addParameter(QgsProcessingParameterNumber(self.HMAX, "Largest edge length (km)",
                                                       QgsProcessingParameterNumber.Double, 50.0, minValue=0.0))
        self.addParameter(QgsProcessingParameterNumber(self.HMIN, "Smallest edge length (km; 0: max(hmax/1000, 10 m))",
                                                       QgsProcessingParameterNumber.Double, 0.0, minValue=0.0))
        self.addParameter(QgsProcessingParameterFeatureSource(self.SIZE_REGIONS, "Size regions (polygons)",
                                                              [QgsProcessing.TypeVectorPolygon], optional=True))
        self.addParameter(QgsProcessingParameterField(self.SIZE_FIELD, "Size regions' edge length field (km)",
                                                      "size_km", self.SIZE_REGIONS,
                                                      QgsProcessingParameterField.Numeric, optional=True))
        self.addParameter(QgsProcessingParameterBoolean(self.DEFAULT_PASSAGES, "Keep the world's critical passages "
                                                        "open (Gibraltar, Bosphorus...)", False))
        self.addParameter(QgsProcessingParameterFeatureSource(self.PASSAGES, "Passages (lines across straits, instead "
                                                              "of the world's)", [QgsProcessing.TypeVectorLine],
                                                              optional=True))
        for name, _, description, default, _, advanced in NUMBER_OPTIONS:
            self._add(QgsProcessingParameterNumber(name, description, QgsProcessingParameterNumber.Double, default,
                                                   minValue=0.0), advanced)
        self._add(QgsProcessingParameterBoolean(self.KEEP_INLAND_SEAS, "Keep water bodies not connected to the "
                                                "ocean", False), True)
        self._add_outputs()

    def _add(self, parameter, advanced):
        if advanced:
            parameter.setFlags(parameter.flags() | QgsProcessingParameterDefinition.FlagAdvanced)
        self.addParameter(parameter)

    def _layer_file(self, parameters, name, context, feedback):
        """(path, layer name) of a vector layer parameter as globemesh reads it: its file, or a
        temporary GeoPackage of its selected features (or of a layer OGR cannot read); None when empty."""
        if not parameters.get(name):
            return None, None
        path, layer = self.parameterAsCompatibleSourceLayerPathAndLayerName(parameters, name, context, ["gpkg", "shp"],
                                                                            "gpkg", feedback)
        shown = self.parameterAsVectorLayer(parameters, name, context)
        if shown is not None and shown.crs().isValid() and not _declares(path, layer, shown.crs()):
            # The CRS set on the layer in QGIS, which its file lacks or names otherwise: a copy
            # of the features carries it (globemesh reads the file's, or refuses a file without).
            path, layer = self.parameterAsCompatibleSourceLayerPathAndLayerName(parameters, name, context, [],
                                                                                "gpkg", feedback)
        return path, layer or _first_layer(path)

    def _size_regions(self, parameters, context, feedback):
        """The size regions' (path, layer), their field copied as size_km when it is another."""
        field = self.parameterAsString(parameters, self.SIZE_FIELD, context) or "size_km"
        if not parameters.get(self.SIZE_REGIONS) or field == "size_km":
            return self._layer_file(parameters, self.SIZE_REGIONS, context, feedback)
        import processing
        copied = processing.run("native:fieldcalculator", {
            "INPUT": parameters[self.SIZE_REGIONS], "FIELD_NAME": "size_km", "FIELD_TYPE": 0, "FIELD_LENGTH": 0,
            "FIELD_PRECISION": 0, "FORMULA": "to_real(%s)" % QgsExpression.quotedColumnRef(field),
            "OUTPUT": QgsProcessingUtils.generateTempFilename("size_regions.gpkg")}, context=context,
            feedback=feedback, is_child_algorithm=True)
        return copied["OUTPUT"], _first_layer(copied["OUTPUT"])

    def _region(self, parameters, context, feedback, options):
        """The region: an extent in lon/lat, or a polygon layer."""
        if parameters.get(self.REGION) and parameters.get(self.REGION_LAYER):
            raise QgsProcessingException("give the region as an extent or as a polygon layer, not both")
        if parameters.get(self.REGION):
            options["region"] = self._lonlat_region(parameters, context)
        options["region_file"], options["region_layer"] = self._layer_file(parameters, self.REGION_LAYER, context,
                                                                           feedback)

    def _lonlat_region(self, parameters, context):
        """The extent as globemesh's region W,S,E,N in degrees, W > E across 180. An extent written
        xmin,xmax,ymin,ymax [EPSG:4326] with xmin above xmax crosses 180 (QGIS swaps the two);
        one in another CRS is its outline's shortest span of longitudes in lon/lat (QGIS's own
        transform took the whole band for an extent across 180), unless it holds a pole."""
        raw, crs = parameters.get(self.REGION), self.parameterAsExtentCrs(parameters, self.REGION, context)
        number = r"\s*([-+0-9.eE]+)\s*"
        m = re.match(",".join([number] * 4), raw) if isinstance(raw, str) else None
        if m and (not crs.isValid() or crs.isGeographic()):
            x0, x1, y0, y1 = map(float, m.groups())
            if x0 > x1:
                return (x0, min(y0, y1), x1, max(y0, y1))
        whole = self.parameterAsExtent(parameters, self.REGION, context, WGS84)
        whole = (whole.xMinimum(), whole.yMinimum(), whole.xMaximum(), whole.yMaximum())
        if not crs.isValid() or crs.isGeographic():
            return whole
        r = self.parameterAsExtent(parameters, self.REGION, context)
        to_lonlat = QgsCoordinateTransform(crs, WGS84, context.transformContext())
        steps = [k / 16 for k in range(17)]
        outline = [(r.xMinimum() + f * r.width(), r.yMinimum() + g * r.height())
                   for f in steps for g in (0, 1)] + [(r.xMinimum() + f * r.width(), r.yMinimum() + g * r.height())
                                                      for g in steps for f in (0, 1)]
        points = [to_lonlat.transform(QgsPointXY(x, y)) for x, y in outline]
        lons = sorted(p.x() for p in points)
        gaps = [(lons[k + 1] - lons[k], k) for k in range(len(lons) - 1)] + [(lons[0] + 360 - lons[-1], -1)]
        gap, k = max(gaps)
        if k == -1 or gap < 60:  # no span across 180, or the outline all round a pole
            return whole
        return (lons[k + 1], min(p.y() for p in points), lons[k], max(p.y() for p in points))

    def _passages(self, parameters, context, feedback, options):
        if self.parameterAsBool(parameters, self.DEFAULT_PASSAGES, context):
            if parameters.get(self.PASSAGES):
                raise QgsProcessingException("keep the world's critical passages or a passages layer, not both")
            options["passages"] = "default"
        else:
            options["passages"], options["passages_layer"] = self._layer_file(parameters, self.PASSAGES, context,
                                                                               feedback)

    def _bathy(self, parameters, context):
        bathy = self.parameterAsRasterLayer(parameters, self.BATHY, context)
        if bathy is not None and bathy.providerType() != "gdal":  # globemesh reads the raster with GDAL, by its source
            raise QgsProcessingException("bathymetry layer %s: not a GDAL raster (provider %s); save it as a "
                                         "GeoTIFF first" % (bathy.name(), bathy.providerType()))
        return bathy.source() if bathy is not None else None

    def _options(self, parameters, context, feedback):
        """The keywords of globemesh.mesh_ocean() given by the parameters (None: globemesh's default)."""
        coast, layer = self._layer_file(parameters, self.COAST, context, feedback)
        options = {"coast": coast, "coast_layer": layer, "bathy": self._bathy(parameters, context),
                   "hmax": "%rkm" % self.parameterAsDouble(parameters, self.HMAX, context),
                   "hmin": "%rkm" % self.parameterAsDouble(parameters, self.HMIN, context)}
        self._region(parameters, context, feedback, options)
        options["size_regions"], options["size_regions_layer"] = self._size_regions(parameters, context, feedback)
        self._passages(parameters, context, feedback, options)
        for name, keyword, _, default, unit, _ in NUMBER_OPTIONS:
            value = self.parameterAsDouble(parameters, name, context)
            if value != default:  # a number alone as globemesh writes it (a count 3.0 as 3)
                options[keyword] = "%r%s" % (value, unit) if unit else value
        if self.parameterAsBool(parameters, self.KEEP_INLAND_SEAS, context):
            options["keep_inland_seas"] = True
        return {k: v for k, v in options.items() if v is not None}

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

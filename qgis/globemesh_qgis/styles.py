"""How the layers the plugin loads draw: the GeoPackage's faces graduated by quality (the classes
of the style stored in the GeoPackage, src/io/gpkg_write.cpp), its boundary coast and open in two
colours (categorized on the field tag)."""

from qgis.core import (QgsCategorizedSymbolRenderer, QgsGraduatedSymbolRenderer, QgsRendererCategory,
                       QgsRendererRange, QgsSymbol, QgsUnitTypes)
from qgis.PyQt.QtGui import QColor

QUALITY_CLASSES = ((0.0, 0.3, "#d7191c", "poor (below 0.3)"), (0.3, 0.5, "#fdae61", "0.3 - 0.5"),
                   (0.5, 0.7, "#ffffbf", "0.5 - 0.7"), (0.7, 0.9, "#a6d96a", "0.7 - 0.9"),
                   (0.9, 1.000001, "#1a9641", "good (0.9 and above)"))
BOUNDARY_TAGS = (("coast", "#5b3a1a", "coast"), ("open", "#e31a1c", "open boundary"))


def _symbol(layer, colour):
    symbol = QgsSymbol.defaultSymbol(layer.geometryType())
    symbol.setColor(QColor(colour))
    return symbol


def style_faces(layer):
    """Faces coloured by quality, unless QGIS already loaded that style from the GeoPackage."""
    renderer = layer.renderer()
    if isinstance(renderer, QgsGraduatedSymbolRenderer) and renderer.classAttribute() == "quality":
        return
    ranges = [QgsRendererRange(lower, upper, _symbol(layer, colour), label)
              for lower, upper, colour, label in QUALITY_CLASSES]
    layer.setRenderer(QgsGraduatedSymbolRenderer("quality", ranges))


def style_boundary(layer):
    """Boundary lines by tag: coast brown, open red, both wide enough to see over the faces."""
    categories = []
    for tag, colour, label in BOUNDARY_TAGS:
        symbol = _symbol(layer, colour)
        symbol.setWidth(0.6)
        symbol.setWidthUnit(QgsUnitTypes.RenderMillimeters)
        categories.append(QgsRendererCategory(tag, symbol, label))
    layer.setRenderer(QgsCategorizedSymbolRenderer("tag", categories))


STYLES = {"faces": style_faces, "boundary": style_boundary}  # by GeoPackage layer name

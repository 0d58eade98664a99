"""Adds the Processing provider "globemesh" to QGIS while the plugin is loaded."""

from qgis.core import QgsApplication

from .provider import GlobemeshProvider


class GlobemeshPlugin:
    def __init__(self):
        self.provider = None

    def initProcessing(self):  # noqa: N802 (QGIS's name)
        self.provider = GlobemeshProvider()
        QgsApplication.processingRegistry().addProvider(self.provider)

    def initGui(self):  # noqa: N802
        self.initProcessing()

    def unload(self):
        if self.provider is not None:
            QgsApplication.processingRegistry().removeProvider(self.provider)
            self.provider = None

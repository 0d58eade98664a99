"""The Processing provider "globemesh": its algorithms are in algorithms.py."""

from qgis.core import QgsProcessingProvider

from .algorithms import MeshOcean, TriangulatePoints


class GlobemeshProvider(QgsProcessingProvider):
    def id(self):
        return "globemesh"

    def name(self):
        return "globemesh"

    def longName(self):  # noqa: N802 (QGIS's name)
        return "globemesh: ocean meshes on the sphere"

    def loadAlgorithms(self):  # noqa: N802
        self.addAlgorithm(MeshOcean())
        self.addAlgorithm(TriangulatePoints())

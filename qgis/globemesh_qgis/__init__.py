"""QGIS plugin holding the Processing provider "globemesh" (provider.py).

The folder is globemesh_qgis, not globemesh: QGIS imports a plugin as a top-level package named
after its folder, with the plugin folders first on sys.path, so a plugin named globemesh would
hide the Python module globemesh that it runs."""


def classFactory(iface):  # noqa: N802 (QGIS's name)
    from .plugin import GlobemeshPlugin
    return GlobemeshPlugin()

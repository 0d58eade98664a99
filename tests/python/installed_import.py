"""The module globemesh imported from FOLDER (an install prefix's dist-packages, or a build of
python/ alone over the installed package) meshes the fixture as the build tree's does:
    installed_import.py FOLDER FIXTURES_DIR"""

import os
import sys

folder, fixtures = (os.path.abspath(a) for a in sys.argv[1:3])
sys.path.insert(0, folder)
import globemesh  # noqa: E402

assert os.path.dirname(os.path.dirname(os.path.abspath(globemesh.__file__))) == folder, globemesh.__file__
mesh = globemesh.mesh_ocean(coast=os.path.join(fixtures, "coast", "ne_110m_land.gpkg"), coast_layer="land",
                            hmax="1000km")
assert len(mesh.faces) > 100 and mesh.faces.dtype.name == "int32" and mesh.depth is None, mesh
assert mesh.faces.max() == len(mesh.node_lon) - 1 and (mesh.boundary_tags == 1).all()  # all coast: a global ocean
try:
    globemesh.mesh_ocean(coast=os.path.join(fixtures, "none.gpkg"))
    raise AssertionError("no error for a missing coast")
except globemesh.IoError as e:
    assert str(e).startswith("--coast"), e
print("OK: %s from %s, %d faces" % (globemesh.__version__, folder, len(mesh.faces)))

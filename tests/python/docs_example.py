"""Runs the example of docs/python.md (its first python block) as a user would from the
repository's root: in a temporary folder that holds a link to fixtures/, so that its outputs
land there. Usage: docs_example.py DOCS/python.md"""

import os
import re
import sys
import tempfile

doc = sys.argv[1]
root = os.path.dirname(os.path.dirname(os.path.abspath(doc)))
blocks = re.findall(r"```python\n(.*?)```", open(doc, encoding="utf-8").read(), re.S)
assert blocks, doc + " has no python example"
with tempfile.TemporaryDirectory(prefix="globemesh-doc-") as folder:
    os.symlink(os.path.join(root, "fixtures"), os.path.join(folder, "fixtures"))
    os.chdir(folder)
    exec(compile(blocks[0], doc, "exec"), {"__name__": "__main__"})
    written = sorted(f for f in os.listdir(folder) if f != "fixtures")
    # ocean.msh, ocean.nc (with its QGIS style ocean.qml), ocean.gpkg and fort.14, as the example says.
    assert written == ["fort.14", "ocean.gpkg", "ocean.msh", "ocean.nc", "ocean.qml"], written
    os.chdir(root)

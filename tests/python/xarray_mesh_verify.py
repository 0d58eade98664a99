"""to_xarray() round trips through xarray's to_netcdf() to a file that the independent checker
../shared/tools/mesh-verify accepts, with the coast and the size field it checks. Exit 77
(ctest: skipped) when the checker is absent, a failure under CI=true (as tests/support.hpp)."""

import os
import subprocess
import sys
import tempfile

import globemesh

FIXTURES = os.environ["GLOBEMESH_FIXTURES_DIR"]
CHECKER = os.environ.get("GLOBEMESH_MESH_VERIFY",
                         os.path.join(os.environ["GLOBEMESH_SHARED_DIR"], "tools", "mesh-verify"))

if not os.path.exists(CHECKER):
    if os.environ.get("CI") == "true":
        sys.exit("mesh-verify (%s) is missing, and CI=true requires it" % CHECKER)
    print("SKIPPED: mesh-verify (%s) is missing" % CHECKER)
    sys.exit(77)

coast = os.path.join(FIXTURES, "coast", "ne_110m_land.gpkg")
mesh = globemesh.mesh_ocean(coast, os.path.join(FIXTURES, "bathy", "etopo5_global_10min.nc"),
                            coast_layer="land", hmin="150km", hmax="500km", wavelength=30)
with tempfile.TemporaryDirectory(prefix="globemesh-py-") as folder:
    path = os.path.join(folder, "roundtrip.nc")
    mesh.to_xarray().to_netcdf(path)
    status = subprocess.run([CHECKER, path, "--quiet", "--size-var", "target_size"]).returncode
sys.exit(1 if status != 0 else 0)

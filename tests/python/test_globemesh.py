"""The Python module against the command line: the same arrays as its UGRID file (read with
netCDF4), the same errors and messages, cancellation that leaves nothing, the GIL released.
Run by ctest (tests/CMakeLists.txt) with PYTHONPATH at the build tree's python/ folder and
GLOBEMESH_EXE, GLOBEMESH_FIXTURES_DIR set."""

import os
import signal
import subprocess
import sys
import tempfile
import threading
import time
import unittest
import warnings

import netCDF4
import numpy as np

import globemesh

EXE = os.environ["GLOBEMESH_EXE"]
FIXTURES = os.environ["GLOBEMESH_FIXTURES_DIR"]
LAND110 = os.path.join(FIXTURES, "coast", "ne_110m_land.gpkg")
LAND50 = os.path.join(FIXTURES, "coast", "ne_50m_land.gpkg")
ETOPO = os.path.join(FIXTURES, "bathy", "etopo5_global_10min.nc")
STATIONS = os.path.join(FIXTURES, "points", "stations.csv")


def cli(*args):
    """(exit status, stderr) of `globemesh ARGS`."""
    p = subprocess.run([EXE, *args], capture_output=True, text=True)
    return p.returncode, p.stderr


def cli_error(*args):
    """The command line's one-line error (without "globemesh: ") and its exit status."""
    status, err = cli(*args)
    lines = [l for l in err.splitlines() if l.startswith("globemesh: ")]
    assert len(lines) == 1, err
    return lines[0][len("globemesh: "):], status


class TempDir(unittest.TestCase):
    def setUp(self):
        self._dir = tempfile.TemporaryDirectory(prefix="globemesh-py-")
        self.dir = self._dir.name

    def tearDown(self):
        self._dir.cleanup()

    def path(self, name):
        return os.path.join(self.dir, name)


class SameAsCommandLine(TempDir):
    """mesh_ocean's arrays are the command line's file's, variable for variable."""

    def compare(self, result, nc_path):
        with netCDF4.Dataset(nc_path) as nc:
            v = {name: nc[name][:].filled() if np.ma.isMaskedArray(nc[name][:]) else nc[name][:]
                 for name in nc.variables}
            pairs = [("node_lon", "mesh_node_lon"), ("node_lat", "mesh_node_lat"),
                     ("faces", "mesh_face_nodes"), ("edges", "mesh_edge_nodes"),
                     ("edge_tags", "boundary_tag"), ("quality", "quality"), ("face_area", "area")]
            for ours, theirs in pairs:
                np.testing.assert_array_equal(getattr(result, ours), v[theirs], err_msg=ours)
            for name in result.node_fields:
                np.testing.assert_array_equal(result.node_fields[name], v[name], err_msg=name)
            if "mesh_boundary_nodes" in v:
                np.testing.assert_array_equal(result.boundary_edges, v["mesh_boundary_nodes"])
            else:
                self.assertEqual(len(result.boundary_edges), 0)
            # The boundary's tags are those of its edges in the file's per-edge boundary_tag.
            edge_of = {tuple(e): i for i, e in enumerate(v["mesh_edge_nodes"].tolist())}
            tags = [v["boundary_tag"][edge_of[tuple(e)]] for e in result.boundary_edges.tolist()]
            np.testing.assert_array_equal(result.boundary_tags, tags)
            for key, value in result.attributes.items():
                if key not in ("globemesh_configuration", "history"):
                    self.assertEqual(str(nc.getncattr(key)), value, key)
            self.assertEqual(result.faces.dtype, np.int32)

    def test_global_with_bathymetry(self):
        status, err = cli("mesh", "-q", "--coast", LAND110, "--coast-layer", "land", "--bathy", ETOPO,
                          "--hmin", "150km", "--hmax", "600", "--wavelength", "30", "--grade", "0.2",
                          "-o", self.path("cli.nc"))
        self.assertEqual(status, 0, err)
        r = globemesh.mesh_ocean(LAND110, ETOPO, coast_layer="land", hmin="150km", hmax=600,
                                 wavelength=30, grade=0.2)
        self.assertGreater(len(r.faces), 1000)
        self.assertIsNotNone(r.depth)
        self.compare(r, self.path("cli.nc"))
        self.assertEqual(r.report["mesh"]["faces"], len(r.faces))
        self.assertIn("depth", r.report)

    def test_region_with_open_boundary(self):
        status, err = cli("mesh", "-q", "--coast", LAND50, "--coast-layer", "land",
                          "--region", "-12,48,12,64", "--hmax", "60km", "-o", self.path("cli.nc"))
        self.assertEqual(status, 0, err)
        r = globemesh.mesh_ocean(coast=LAND50, coast_layer="land", region=(-12, 48, 12, 64),
                                 hmax="60km")
        self.assertIsNone(r.depth)
        self.assertIn(2, set(r.boundary_tags.tolist()))  # open boundary along the region
        self.compare(r, self.path("cli.nc"))

    def test_flags_and_configuration(self):
        status, err = cli("mesh", "-q", "--coast", LAND110, "--coast-layer", "land", "--hmax", "800",
                          "--keep-straits", "-o", self.path("cli.nc"))
        self.assertEqual(status, 0, err)
        r = globemesh.mesh_ocean(LAND110, coast_layer="land", hmax=800, keep_straits=True,
                                 keep_inland_seas=False)
        self.compare(r, self.path("cli.nc"))
        config = r.attributes["globemesh_configuration"].splitlines()
        self.assertIn("keep-straits=true", config)
        self.assertIn("keep-inland-seas=false", config)
        def run_options(lines):  # the same, but for the outputs and the command line's -q
            return [l for l in lines if not l.startswith(("output=", "quiet="))]

        with netCDF4.Dataset(self.path("cli.nc")) as nc:
            cli_config = nc.getncattr("globemesh_configuration").splitlines()
        self.assertEqual(run_options(config), run_options(cli_config))

    def test_a_config_file_gives_the_inputs(self):
        # config= holds the coast as the command line's --config does: no coast keyword needed.
        config = self.path("run.toml")
        with open(config, "w") as f:
            f.write('coast = "%s"\ncoast-layer = "land"\nhmax = "800km"\n' % LAND110)
        status, err = cli("mesh", "-q", "--config", config, "-o", self.path("cli.nc"))
        self.assertEqual(status, 0, err)
        self.compare(globemesh.mesh_ocean(config=config), self.path("cli.nc"))
        with self.assertRaisesRegex(ValueError, "^--coast is required"):
            globemesh.mesh_ocean(hmax="800km")

    def test_outputs_in_a_config_file_are_said_not_written(self):
        # A config shared with the command line names its outputs: mesh_ocean() writes none of
        # them (the result is in memory), and says so instead of passing over them.
        config = self.path("run.toml")
        with open(config, "w") as f:
            f.write('coast = "%s"\ncoast-layer = "land"\nhmax = "800km"\noutput = "%s"\n'
                    'gpkg = "%s"\n' % (LAND110, self.path("o.nc"), self.path("o.gpkg")))
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            globemesh.mesh_ocean(config=config)
        said = [str(w.message) for w in caught if issubclass(w.category, globemesh.MeshWarning)]
        self.assertIn("--config %s names outputs (--output, --gpkg) that mesh_ocean() does not "
                      "write: write them with its result's write()" % config, said)
        self.assertFalse(os.path.exists(self.path("o.nc")))
        with warnings.catch_warnings(record=True) as caught:  # without outputs: not said
            warnings.simplefilter("always")
            globemesh.mesh_ocean(LAND110, coast_layer="land", hmax="800km")
        self.assertFalse([w for w in caught if "names outputs" in str(w.message)])

    def test_write_is_the_command_lines_file(self):
        r = globemesh.mesh_ocean(LAND110, coast_layer="land", hmax="800km")
        r.write([self.path("py.nc"), self.path("py.gpkg")])
        self.compare(r, self.path("py.nc"))
        self.assertTrue(os.path.getsize(self.path("py.gpkg")) > 0)
        with self.assertRaises(globemesh.IoError):  # exists, no overwrite
            r.write(self.path("py.nc"))
        r.write(self.path("py.nc"), overwrite=True)

    def test_write_refuses_to_replace_an_input_even_after_a_chdir(self):
        # write(..., overwrite=True) replaced the coast it was meshed from (a GeoPackage became
        # the mesh's layers); the command line refuses, naming the input. A relative coast
        # stays the same file after os.chdir.
        import shutil
        coast = self.path("coast.gpkg")
        shutil.copy(LAND110, coast)
        before = open(coast, "rb").read()
        here = os.getcwd()
        os.chdir(self.dir)
        try:
            r = globemesh.mesh_ocean("coast.gpkg", coast_layer="land", hmax="800km")
        finally:
            os.chdir(here)
        with self.assertRaises(globemesh.UsageError) as caught:
            r.write(coast, overwrite=True)
        self.assertIn("is the coast file", str(caught.exception))
        self.assertEqual(open(coast, "rb").read(), before)

    def test_arrays_are_read_only_views(self):
        r = globemesh.mesh_ocean(LAND110, coast_layer="land", hmax="800km")
        faces = r.faces
        self.assertFalse(faces.flags.writeable)
        self.assertFalse(faces.flags.owndata)  # a view of the library's vector
        del r  # the view keeps the mesh alive
        self.assertTrue((faces >= 0).all())

    def test_triangulate_is_the_command_lines(self):
        status, err = cli("triangulate", "-q", STATIONS, "-o", self.path("cli.nc"))
        self.assertEqual(status, 0, err)
        data = np.genfromtxt(STATIONS, delimiter=",", names=True, dtype=None, encoding="utf-8")
        r = globemesh.triangulate(data["lon"], data["lat"])
        with netCDF4.Dataset(self.path("cli.nc")) as nc:
            np.testing.assert_array_equal(r.faces, nc["mesh_face_nodes"][:])
            np.testing.assert_array_equal(r.node_lon, nc["mesh_node_lon"][:])
            np.testing.assert_array_equal(r.edges, nc["mesh_edge_nodes"][:])


class Errors(TempDir):
    """Errors are the command line's messages, as exceptions."""

    def same(self, exception, cli_args, **options):
        message, status = cli_error("mesh", *cli_args, "-o", self.path("x.nc"))
        with self.assertRaises(exception) as caught:
            globemesh.mesh_ocean(**options)
        self.assertEqual(str(caught.exception), message)
        self.assertEqual(status, 2 if issubclass(exception, ValueError) else 1)
        self.assertEqual(os.listdir(self.dir), [])

    def test_bad_length(self):
        self.same(globemesh.UsageError, ["--coast", LAND110, "--hmax", "50 parsecs"],
                  coast=LAND110, hmax="50 parsecs")

    def test_bad_option_value(self):
        self.same(globemesh.UsageError, ["--coast", LAND110, "--hmax", "10km", "--hmin", "20km"],
                  coast=LAND110, hmax="10km", hmin="20km")

    def test_bad_region(self):
        self.same(ValueError, ["--coast", LAND110, "--region", "10,50,20,40"], coast=LAND110,
                  region=[10, 50, 20, 40])

    def test_missing_file(self):
        missing = self.path("nowhere.gpkg")
        self.same(OSError, ["--coast", missing], coast=missing)
        # The passages too are checked before the run (their reader said "unknown error").
        self.same(OSError, ["--coast", LAND110, "--passages", missing], coast=LAND110,
                  passages=missing)

    def test_region_of_five_values(self):
        # Five values: too many values, not "--region is given 5 times".
        self.same(ValueError, ["--coast", LAND110, "--region", "1,2,3,4,5"], coast=LAND110,
                  region=(1, 2, 3, 4, 5))
        with self.assertRaisesRegex(ValueError, "^--region takes 4 values, got 5$"):
            globemesh.mesh_ocean(LAND110, region=(1, 2, 3, 4, 5))

    def test_seed_out_of_range(self):
        # The seed is an unsigned 64-bit number: -1 and 2**70 were wrapped and cut to one.
        for seed in (-1, 2 ** 64, 2 ** 70):
            self.same(ValueError, ["--coast", LAND110, "--seed", str(seed)], coast=LAND110, seed=seed)
            with self.assertRaisesRegex(ValueError, r"--seed: .* in 0\.\.18446744073709551615"):
                globemesh.mesh_ocean(LAND110, seed=seed)

    def test_write_where_no_file_can_be(self):
        # /proc takes no file, though it looks writable to root: no "(the disk is full)".
        r = globemesh.triangulate([0, 90, 180, -90, 0], [0, 0, 0, 0, 90])
        for path in ("/proc/mesh.nc", "/proc/mesh.gpkg"):
            with self.assertRaisesRegex(globemesh.IoError, "^--output: %s: the folder /proc takes no "
                                        "new file \\(" % path):
                r.write(path)

    def test_every_error_is_a_globemesh_error(self):
        for kind, python_kind in ((globemesh.UsageError, ValueError), (globemesh.IoError, OSError),
                                  (globemesh.DataError, RuntimeError),
                                  (globemesh.Cancelled, RuntimeError)):
            self.assertTrue(issubclass(kind, globemesh.Error) and issubclass(kind, python_kind))
        with self.assertRaises(globemesh.Error):
            globemesh.mesh_ocean(self.path("nowhere.gpkg"))

    def test_unknown_keyword_and_output_options(self):
        with self.assertRaises(TypeError):
            globemesh.mesh_ocean(LAND110, hmaxx="50km")
        with self.assertRaises(TypeError):  # outputs are Result.write's
            globemesh.mesh_ocean(LAND110, output="x.nc")

    def test_write_unknown_format(self):
        r = globemesh.triangulate([0, 90, 180, 0], [0, 0, 0, 90])
        with self.assertRaises(globemesh.UsageError) as caught:
            r.write(self.path("mesh.xyz"))
        message, status = cli_error("triangulate", STATIONS, "-o", self.path("mesh.xyz"))
        self.assertEqual(str(caught.exception), message)
        self.assertEqual(status, 2)

    def test_gdal_warnings_are_python_warnings(self):
        # A GDAL warning during a run (the library's readers silence those they expect) comes as
        # a globemesh.GdalWarning, not on stderr as GDAL's default handler prints it; in a child
        # process, to see its stderr.
        script = ("import warnings, globemesh\n"
                  "with warnings.catch_warnings(record=True) as caught:\n"
                  "    warnings.simplefilter('always')\n"
                  "    globemesh._globemesh._gdal_warning_in_a_run('odd raster')\n"
                  "print([(w.category.__name__, str(w.message)) for w in caught])\n")
        run = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True)
        self.assertEqual((run.returncode, run.stdout, run.stderr), (0, "[('GdalWarning', 'GDAL: odd raster')]\n", ""))
        self.assertTrue(issubclass(globemesh.GdalWarning, UserWarning))

    def test_triangulate_bad_points(self):
        with self.assertRaisesRegex(globemesh.UsageError, "same length"):
            globemesh.triangulate([0, 1], [0])
        with self.assertRaisesRegex(globemesh.UsageError, "point 1 .*lat in"):
            globemesh.triangulate([0, 1, 2], [0, 91, 2])
        with self.assertRaisesRegex(globemesh.DataError, "one circle"):
            globemesh.triangulate([0, 10, 20], [0, 0, 0])


class Keywords(TempDir):
    def test_a_result_copies_and_a_triangulation_keeps_its_title(self):
        # copy.copy(result) recursed in __getattr__ (no _mesh yet); triangulate()'s files said
        # "globemesh ocean mesh", where the command line's say what they are.
        import copy
        r = globemesh.triangulate([0, 90, 180, -90, 0], [0, 0, 0, 0, 90])
        self.assertEqual(len(copy.copy(r).faces), len(r.faces))
        r.write(self.path("tri.nc"))
        with netCDF4.Dataset(self.path("tri.nc")) as nc:
            self.assertEqual(nc.title, "globemesh spherical Delaunay triangulation")

    def test_flags_paths_and_a_numpy_false_read_as_they_say(self):
        # keep_straits="false" turned the flag on (a non-empty string); coast=b"path" became
        # "b'path'"; write([]) wrote nothing, silently; a progress callback returning np.False_
        # did not cancel.
        a = globemesh.mesh_ocean(LAND110.encode(), coast_layer="land", hmax="800km",
                                 keep_straits="false")
        self.assertIn("keep-straits=false", a.attributes["globemesh_configuration"].splitlines())
        with self.assertRaises(ValueError):
            globemesh.mesh_ocean(LAND110, coast_layer="land", hmax="800km", keep_straits="maybe")
        with self.assertRaises(ValueError):
            a.write([])
        with self.assertRaises(globemesh.Cancelled):
            globemesh.mesh_ocean(LAND110, coast_layer="land", hmax="800km",
                                 progress=lambda f, stage: np.False_)

    def test_whole_floats_count_and_an_empty_string_is_refused(self):
        # smooth=4.0 or passage_cells=3.0 (numpy scalars, QGIS's numbers) went as "4.0", which
        # the count options refused ("Could not convert"); coast_srs="" took the next keyword
        # as its value ("--coast-srs '--hmax=600km' is not a CRS").
        r = globemesh.mesh_ocean(LAND110, coast_layer="land", hmax=np.float64(800), smooth=4.0,
                                 passage_cells=np.float64(3))
        self.assertGreater(len(r.faces), 0)
        with self.assertRaises(ValueError) as caught:
            globemesh.mesh_ocean(LAND110, coast_layer="land", coast_srs="", hmax="800km")
        self.assertIn("coast_srs='' is empty", str(caught.exception))
        # A size far too small: its node count said -9223372036854775808 (an overflow).
        with self.assertRaisesRegex(globemesh.DataError, r"takes about [0-9.]+e\+[0-9]+ nodes"):
            globemesh.mesh_ocean(LAND110, coast_layer="land", hmax="1e-9km")
        with self.assertRaisesRegex(globemesh.DataError, r"takes too many nodes"):
            globemesh.mesh_ocean(LAND110, coast_layer="land", hmax=1e-300)


class Warnings(TempDir):
    def test_the_command_lines_warnings_come_as_mesh_warnings(self):
        # The command line warns that the Aegean at 20 km closes a strait; Python and QGIS
        # said nothing.
        with self.assertWarnsRegex(globemesh.MeshWarning, "strait narrower than its faces"):
            globemesh.mesh_ocean(LAND50, coast_layer="land", hmax="20km", region=(20, 35, 30, 41))


class Cancel(TempDir):
    """A cancelled run raises, and leaves no file."""

    def test_callback_false_cancels(self):
        calls = []

        def progress(fraction, stage):
            calls.append((fraction, stage))
            return False

        with self.assertRaisesRegex(globemesh.Cancelled, "^cancelled, no output written$"):
            globemesh.mesh_ocean(LAND110, coast_layer="land", hmax="300km", progress=progress)
        self.assertEqual(len(calls), 1)

    def test_ctrl_c_stops_the_run(self):
        # SIGINT to this process while the library runs without the GIL: Python's handler
        # marks it, the next progress tick raises KeyboardInterrupt.
        timer = threading.Timer(0.3, os.kill, (os.getpid(), signal.SIGINT))
        timer.start()
        t0 = time.monotonic()
        with self.assertRaises(KeyboardInterrupt):
            # 2.1 million faces: 3.7 s on the 2-core test machine when the run goes to its end.
            globemesh.mesh_ocean(LAND50, coast_layer="land", hmax="20km")
        timer.join()
        self.assertLess(time.monotonic() - t0, 2)

    def test_cancelled_write_leaves_nothing(self):
        r = globemesh.mesh_ocean(LAND110, ETOPO, coast_layer="land", hmax="100km")
        outputs = [self.path("o.nc"), self.path("o.gpkg"), self.path("o.msh")]
        for stop in (lambda: False, lambda: 1 / 0):
            calls = []

            def progress(fraction, stage):
                calls.append(fraction)
                return stop() if len(calls) == 2 else True  # midway: the first call is at 0

            with self.assertRaises((globemesh.Cancelled, ZeroDivisionError)):
                r.write(outputs, progress=progress)
            self.assertEqual(len(calls), 2)
            self.assertLess(calls[-1], 1)
            self.assertEqual(os.listdir(self.dir), [])

    def test_gil_is_released(self):
        ticks = []
        done = threading.Event()

        def count():
            while not done.is_set():
                ticks.append(1)
                time.sleep(0.001)

        counter = threading.Thread(target=count)
        counter.start()
        try:
            globemesh.mesh_ocean(LAND50, coast_layer="land", hmax="100km")
        finally:
            done.set()
            counter.join()
        # Held for the whole run, the GIL would not let the counter tick at all in between.
        self.assertGreater(len(ticks), 20)


class Progress(TempDir):
    """progress(fraction, stage) goes up to 1, reached at the end of each call."""

    def fractions(self, run):
        calls = []
        run(lambda fraction, stage: calls.append(fraction))
        return calls

    def assert_up_to_one(self, calls):
        self.assertTrue(0 <= calls[0] < 1, calls)
        self.assertEqual(calls[-1], 1)  # the run stopped at 0.97: the mesher's share's end
        self.assertEqual(calls, sorted(calls))

    def test_a_run_and_its_write_each_end_at_one(self):
        # Two parts in two threads, each reporting: the fractions still only go up.
        runs = [dict(), dict(parts=2, threads=2)]
        for options in runs:
            mesh = []
            self.assert_up_to_one(self.fractions(lambda p: mesh.append(globemesh.mesh_ocean(
                LAND50, ETOPO, coast_layer="land", hmax="60km", progress=p, **options))))
        self.assert_up_to_one(self.fractions(lambda p: mesh[0].write(
            [self.path("o.nc"), self.path("o.gpkg")], progress=p)))
        self.assert_up_to_one(self.fractions(lambda p: globemesh.triangulate(
            [0, 90, 180, -90, 0], [0, 0, 0, 0, 90], progress=p)))


class Xarray(TempDir):
    def test_dataset_is_the_file(self):
        try:
            import xarray  # noqa: F401
        except ImportError:
            self.skipTest("xarray missing")
        r = globemesh.mesh_ocean(LAND110, ETOPO, coast_layer="land", hmax="600km")
        ds = r.to_xarray()
        self.assertEqual(ds["mesh"].attrs["cf_role"], "mesh_topology")
        np.testing.assert_array_equal(ds["mesh_face_nodes"].values, r.faces)
        np.testing.assert_array_equal(ds["depth"].values, r.depth)
        self.assertEqual(ds["depth"].attrs["positive"], "down")


if __name__ == "__main__":
    unittest.main()

# Shared by tools/demo and tools/test (sourced, not run): installs the Debian packages that are
# missing (only those; nothing when all are present), then configures and builds in Release.
# Runs as root on Debian 12; under another user it uses sudo when it needs to install.

GLOBEMESH_ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)

# Build and run dependencies of globemesh itself; pybind11 (the binding library, headers only)
# with the Python headers (python3-dev, which pybind11-dev does not pull in) and numpy (its arrays)
# for the Python module.
GLOBEMESH_BUILD_PACKAGES="g++ cmake make ninja-build pkg-config libgdal-dev libsqlite3-dev libgeos-dev libproj-dev
  libgeographiclib-dev libnetcdf-dev libhdf5-dev libdeflate-dev libsleef-dev libcli11-dev libgtest-dev libbenchmark-dev gdal-bin netcdf-bin
  pybind11-dev python3-dev python3-numpy"
# What the tests use besides: GMP as the exact oracle of the predicate tests, mandoc/man for the
# man-page lint, the independent checkers' Python modules, QGIS for qgis-check, and clang with
# its runtime (libFuzzer) for tools/fuzz, gmsh's and meshio's readers of the .msh output, xarray
# for the Python module's to_xarray().
GLOBEMESH_TEST_PACKAGES="libgmp-dev mandoc man-db python3-numpy python3-scipy python3-netcdf4
  python3-gdal python3-shapely qgis python3-qgis clang libclang-rt-14-dev clang-format
  python3-gmsh python3-meshio python3-xarray"

install_missing() {
    local missing=()
    for p in "$@"; do
        dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
    done
    [ ${#missing[@]} -eq 0 ] && return 0
    echo "globemesh: installing missing Debian packages: ${missing[*]}" >&2
    local sudo=""
    [ "$(id -u)" -ne 0 ] && sudo="sudo"
    $sudo apt-get update -q >&2
    DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -q --no-install-recommends "${missing[@]}" >&2
}

# configure_and_build BUILD_DIR [extra cmake args...]
# New build trees (this one and those configured after it) use Ninja when it is there: it
# compiles a target's files while the libraries it links are still building, where make waits
# for each library (the sanitizer build on 2 cores: 8 min 15 s with make, 4 min 42 s with
# Ninja). A tree keeps the generator it was made with; CMAKE_GENERATOR set by the caller wins.
configure_and_build() {
    local dir=$1; shift
    if [ -z "${CMAKE_GENERATOR:-}" ] && command -v ninja >/dev/null; then
        export CMAKE_GENERATOR=Ninja
    fi
    cmake -S "$GLOBEMESH_ROOT" -B "$dir" -DCMAKE_BUILD_TYPE=Release "$@" >/dev/null
    cmake --build "$dir" -j"$(nproc)"
}

# configure_sanitized: the one sanitized tree, build/sanitize: clang with AddressSanitizer and
# UndefinedBehaviorSanitizer on everything and libFuzzer's coverage on the library. tools/test
# builds and runs the sanitizer tests in it and tools/fuzz the fuzz targets, so the library is
# compiled once for both (two trees, g++'s and clang's, took 5.4 + 3.0 min of CI's 22).
# -O1 with line tables (-g1): what AddressSanitizer's documentation recommends.
configure_sanitized() {
    local cxx=${CXX:-clang++}
    if ! command -v "$cxx" > /dev/null; then
        echo "globemesh: $cxx not found: install clang (libFuzzer ships with it)" >&2
        return 2
    fi
    if [ -z "${CMAKE_GENERATOR:-}" ] && command -v ninja >/dev/null; then
        export CMAKE_GENERATOR=Ninja
    fi
    cmake -S "$GLOBEMESH_ROOT" -B "$GLOBEMESH_ROOT/build/sanitize" -DCMAKE_CXX_COMPILER="$cxx" \
        -DCMAKE_BUILD_TYPE=RelWithDebInfo "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O1 -g1" \
        -DGLOBEMESH_FUZZ=ON -DGLOBEMESH_SANITIZE=ON -DGLOBEMESH_BUILD_BENCH=OFF -DGLOBEMESH_PYTHON=OFF
}

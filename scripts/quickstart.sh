#!/usr/bin/env bash
# alefsi quick start on a fresh Debian 12 / Ubuntu 22.04+ machine.
#   scripts/quickstart.sh example   installs what is missing, builds, runs the main example
#   scripts/quickstart.sh test      installs what is missing, builds, runs the test suite
# Installing needs root (or sudo). Build directory: build/release (CMake preset "release").
set -euo pipefail
mode=${1:-example}
cd "$(dirname "$0")/.."

packages=(cmake ninja-build g++ libeigen3-dev catch2 python3-vtk9 ccache libsuitesparse-dev libopenblas-dev)
[ "$mode" = example ] && packages+=(python3-matplotlib)  # the example's PNG plots
[ "$mode" = test ] && packages+=(clang-14 libclang-rt-14-dev)  # libFuzzer: the readers' fuzz tests
# PETSc with MPI (optional for the library): the suite runs the PETSc solvers on 1 and 2 ranks
[ "$mode" = test ] && packages+=(petsc-dev libopenmpi-dev openmpi-bin pkg-config)
# gmsh's library (optional for the library, GPL): the suite runs the 3D mesher and remesher
[ "$mode" = test ] && packages+=(libgmsh-dev)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "quickstart: installing ${missing[*]}"
  sudo=""
  [ "$(id -u)" -ne 0 ] && sudo=sudo
  $sudo apt-get update -q
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -q --no-install-recommends "${missing[@]}"
fi

fuzz=()
[ "$mode" = test ] && fuzz=(-DALEFSI_FUZZ=ON)  # the fuzz tests are part of the suite: required
cmake --preset release "${fuzz[@]}"
case "$mode" in
  example)
    # drafting, kissing and tumbling of two disks (paper 6.2) to t = 0.5 s, a few minutes
    cmake --build --preset release --target dkt
    ./build/release/examples/dkt --output build/release/output/dkt
    /usr/bin/python3 examples/plot_bodies.py build/release/output/dkt
    ;;
  test)
    cmake --build --preset release
    ctest --preset release
    ;;
  *)
    echo "usage: $0 example|test" >&2
    exit 2
    ;;
esac

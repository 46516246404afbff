#!/usr/bin/env bash
# Installs the Debian 12 packages karst needs to build, test and benchmark.
# Idempotent: packages already installed are skipped, and apt is not touched when nothing is missing.
set -euo pipefail

packages=(
    build-essential cmake ninja-build pkg-config
    libeigen3-dev            # small vectors, sparse algebra
    libcgal-dev libgmp-dev libmpfr-dev   # Delaunay / alpha shapes (PFEM mesh)
    libtbb-dev               # the one parallel runtime
    libsuitesparse-dev libopenblas0-pthread   # CHOLMOD; OpenBLAS makes it 15x faster than reference BLAS
    libhypre-dev             # BoomerAMG for large Biot systems (brings Open MPI)
    libopenvdb-dev           # sparse grids and VolumeToMesh for the fluid surface
    povray ffmpeg            # karst render: PNG frames and the MP4
    nlohmann-json3-dev       # scene files
    zlib1g-dev               # compressed VTK frames
    libcli11-dev             # command line
    libfmt-dev libspdlog-dev # messages
    libgtest-dev             # tests (CTest)
    libbenchmark-dev         # micro benchmarks
    clang-format git         # CI's layout check (.clang-format), benchmark provenance
)

missing=()
for p in "${packages[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done

if [ ${#missing[@]} -eq 0 ]; then
    echo "install_deps: all ${#packages[@]} packages present"
    exit 0
fi

echo "install_deps: installing ${missing[*]}"
SUDO=""
[ "$(id -u)" -eq 0 ] || SUDO="sudo"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"

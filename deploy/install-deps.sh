#!/usr/bin/env bash
# The one list of Debian (bookworm) packages levelset needs to build, test and run.
# Idempotent: installs only what is missing, then unpacks CGAL's sample data once.
# Usage: deploy/install-deps.sh            (as root, or via sudo when available)
set -euo pipefail

PACKAGES=(
  # toolchain
  build-essential cmake ninja-build ccache pkg-config git
  # libFuzzer runs (make fuzz): clang with its fuzzer/sanitizer runtimes
  clang-14 libclang-rt-14-dev
  # core library
  libtbb-dev libzstd-dev libxxhash-dev zlib1g-dev
  # command line
  libcli11-dev nlohmann-json3-dev libfmt-dev
  # the daemon (levelsetd serve) and levelsetctl: HTTP server and client (built with OpenSSL,
  # zlib and brotli; see ../shared/notes/stack.md), logs; curl for the README's walk-through
  libcpp-httplib-dev libspdlog-dev curl jq
  # mesh I/O reference and later mesh work
  libopenmesh-dev
  # tests and benchmarks (OpenVDB is linked into the benchmark target only)
  libgtest-dev libgmock-dev libbenchmark-dev libopenvdb-dev
  # daemon benchmark (bench_server): HTTP load generator
  wrk
  # browser viewer tests: headless Chromium driven by Selenium (run by /usr/bin/python3)
  chromium chromium-driver python3-selenium
  # real sample data: CGAL's meshes, point clouds and 3D images
  libcgal-demo
  # applications: kd-tree for distances to point clouds (header-only)
  libnanoflann-dev
  # reconstruction benchmark reference: Open3D's screened Poisson (run by /usr/bin/python3)
  python3-open3d
)

# Where CGAL's sample data is unpacked (tests and benchmarks look here, or in
# $LEVELSET_CGAL_DATA when set).
CGAL_DATA_DIR=${LEVELSET_CGAL_DATA:-/usr/local/share/levelset/cgal-data}

SUDO=""
if [ "$(id -u)" -ne 0 ]; then
  if command -v sudo >/dev/null 2>&1; then SUDO="sudo"; else
    echo "install-deps: not root and no sudo; install as root: ${PACKAGES[*]}" >&2; exit 1
  fi
fi

missing=()
for p in "${PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done

if [ ${#missing[@]} -gt 0 ]; then
  echo "install-deps: installing ${missing[*]}"
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -qq
  $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
else
  echo "install-deps: all ${#PACKAGES[@]} packages present"
fi

# CGAL ships its demo data as one tarball; unpack it once to a fixed place.
if [ ! -f "$CGAL_DATA_DIR/.unpacked" ]; then
  tarball=$(dpkg -L libcgal-demo | grep -E '/data\.tar\.(gz|xz|bz2)$' | head -n 1 || true)
  if [ -z "$tarball" ]; then
    echo "install-deps: libcgal-demo has no data tarball" >&2; exit 1
  fi
  $SUDO mkdir -p "$CGAL_DATA_DIR"
  $SUDO tar -xf "$tarball" -C "$CGAL_DATA_DIR"
  $SUDO touch "$CGAL_DATA_DIR/.unpacked"
  echo "install-deps: CGAL sample data unpacked to $CGAL_DATA_DIR"
fi

#!/usr/bin/env bash
# The one list of Debian (bookworm) packages levelset needs to build, test and run.
# Idempotent: installs only what is missing, then unpacks CGAL's sample data once.
# Usage: deploy/install-deps.sh [build] [runtime] [gui] [test] [container]
#        (default: build runtime gui test; as root, or via sudo)
#        deploy/install-deps.sh list-runtime              (prints the runtime group)
set -euo pipefail

# One list, in groups (issue 18): `make run` installs build + runtime, `make test` all, and the
# container's final stage runtime only (deploy/Dockerfile reads the runtime group from here).
#   build:   compile levelsetd and the libraries (headers and toolchain)
#   runtime: what the levelsetd binary loads (shared libraries, Mesa for offscreen frames)
#   gui:     the desktop client levelset-gui (window, control panel)
#   test:    tests, fuzzing and benchmarks (and the data and tools they use)
#   container: make container-test only (image build and run on this machine)
BUILD_PACKAGES=(
  # toolchain
  build-essential cmake ninja-build ccache pkg-config git
  # core library
  libtbb-dev libzstd-dev libxxhash-dev zlib1g-dev
  # command line
  libcli11-dev nlohmann-json3-dev libfmt-dev
  # the daemon (levelsetd serve) and levelsetctl: HTTP server and client (built with OpenSSL,
  # zlib and brotli; see ../shared/notes/stack.md), logs
  libcpp-httplib-dev libspdlog-dev
  # offscreen rendering (common/render): EGL surfaceless and OSMesa, GLM, JPEG / PNG frames
  libegl-dev libopengl-dev libosmesa6-dev libglm-dev libturbojpeg0-dev libpng-dev libmeshoptimizer-dev
  # libturbojpeg0-dev's CMake package also names libjpeg.so.62 (found missing by the image build)
  libjpeg62-turbo-dev
  # applications: kd-tree for distances to point clouds (header-only)
  libnanoflann-dev
)
RUNTIME_PACKAGES=(
  libtbb12 libzstd1 libxxhash0 zlib1g libcpp-httplib0.11 libspdlog1.10 libfmt9 libssl3 libbrotli1
  libegl1 libopengl0 libegl-mesa0 libgl1-mesa-dri libosmesa6 libturbojpeg0 libpng16-16 libmeshoptimizer2d
  ca-certificates
)
GUI_PACKAGES=(
  # levelset-gui: GLFW window + Dear ImGui panel (libimgui.a holds the glfw/opengl3 backends)
  libglfw3-dev libimgui-dev
)
TEST_PACKAGES=(
  # libFuzzer runs (make fuzz): clang with its fuzzer/sanitizer runtimes
  clang-14 libclang-rt-14-dev
  # mesh I/O reference (test_cgal_data compares with OpenMesh)
  libopenmesh-dev
  # tests and benchmarks (OpenVDB is linked into the benchmark target only)
  libgtest-dev libgmock-dev libbenchmark-dev libopenvdb-dev
  # real sample data: CGAL's meshes, point clouds and 3D images
  libcgal-demo
  # scripts of the integration tests and benchmarks (/usr/bin/python3), the README's curl + jq
  # walk-through, a self-signed certificate for the TLS test
  python3 python3-yaml python3-pil curl jq openssl
  # deployment file checks: systemd-analyze verify of the unit
  systemd
  # daemon benchmark (bench_server): HTTP load generator
  wrk
  # browser viewer tests: headless Chromium driven by Selenium
  chromium chromium-driver python3-selenium
  # reconstruction benchmark reference: Open3D's screened Poisson
  python3-open3d
  # desktop client tests: the real client under a virtual X server
  xvfb xauth
)
CONTAINER_PACKAGES=(
  # make container-test: a local base image from the apt mirror, docker on its own socket, the
  # test script (standard library only)
  debootstrap docker.io python3
)

# Groups named on the command line (default: all of them).
WANTED=("$@")
[ ${#WANTED[@]} -eq 0 ] && WANTED=(build runtime gui test)
PACKAGES=()
for g in "${WANTED[@]}"; do
  case "$g" in
    build) PACKAGES+=("${BUILD_PACKAGES[@]}") ;;
    runtime) PACKAGES+=("${RUNTIME_PACKAGES[@]}") ;;
    gui) PACKAGES+=("${GUI_PACKAGES[@]}") ;;
    test) PACKAGES+=("${TEST_PACKAGES[@]}") ;;
    container) PACKAGES+=("${CONTAINER_PACKAGES[@]}") ;;
    list-runtime) printf '%s\n' "${RUNTIME_PACKAGES[@]}"; exit 0 ;;
    *) echo "install-deps: unknown group '$g' (build, runtime, gui, test, container, list-runtime)" >&2; exit 2 ;;
  esac
done

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

# CGAL ships its demo data as one tarball; unpack it once to a fixed place (tests use it).
if [[ " ${WANTED[*]} " == *" test "* ]] && [ ! -f "$CGAL_DATA_DIR/.unpacked" ]; then
  tarball=$(dpkg -L libcgal-demo | grep -E '/data\.tar\.(gz|xz|bz2)$' | head -n 1 || true)
  if [ -z "$tarball" ]; then
    echo "install-deps: libcgal-demo has no data tarball" >&2; exit 1
  fi
  $SUDO mkdir -p "$CGAL_DATA_DIR"
  $SUDO tar -xf "$tarball" -C "$CGAL_DATA_DIR"
  $SUDO touch "$CGAL_DATA_DIR/.unpacked"
  echo "install-deps: CGAL sample data unpacked to $CGAL_DATA_DIR"
fi

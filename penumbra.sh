#!/usr/bin/env bash
# One entry point for a fresh Debian 12 machine (no X server needed):
#
#   ./penumbra.sh render [SCENE.json [OUT.png]]   set up, build, render a scene with shadows
#   ./penumbra.sh test                            set up, build, run the whole test suite
#   ./penumbra.sh setup                           only install the Debian packages
#   ./penumbra.sh build                           only configure and build
#   ./penumbra.sh sanitize                        build with AddressSanitizer and
#                                                 UndefinedBehaviorSanitizer, run the whole suite (CI)
#
# Idempotent: packages already installed are not fetched again, an existing build is reused.
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
build="${PENUMBRA_BUILD_DIR:-$here/build}"

# openimageio-tools: OpenImageIO's CMake package lists /usr/bin/iconvert & co. as imported
# targets and find_package fails without them (libopenimageio-dev does not depend on it).
packages=(
  build-essential cmake
  libvtk9-dev python3-vtk9 python3-numpy
  libglm-dev libopenmesh-dev libopenimageio-dev openimageio-tools libembree-dev nlohmann-json3-dev
  libegl-dev libegl1-mesa-dev libgl1-mesa-dri libosmesa6-dev libglvnd-dev libglew-dev
)

setup() {
  local missing=()
  for p in "${packages[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
  done
  if [ ${#missing[@]} -eq 0 ]; then
    return 0
  fi
  echo "penumbra: installing ${missing[*]}" >&2
  local sudo=()
  if [ "$(id -u)" -ne 0 ]; then
    sudo=(sudo)
  fi
  "${sudo[@]}" apt-get update
  DEBIAN_FRONTEND=noninteractive "${sudo[@]}" apt-get install -y --no-install-recommends "${missing[@]}"
}

build() {
  cmake -S "$here" -B "$build" -DCMAKE_BUILD_TYPE=Release >/dev/null
  cmake --build "$build" --parallel "$(nproc)"
}

cmd="${1:-render}"
case "$cmd" in
  setup)
    setup
    ;;
  build)
    setup
    build
    ;;
  render)
    setup
    build
    scene="${2:-$here/Data/Scenes/default.json}"
    out="${3:-$here/default.png}"
    # Headless on purpose: the EGL window needs no X server even where one exists.
    PENUMBRA_HEADLESS=1 "$build/bin/penumbra-render" "$scene" -o "$out"
    ;;
  test)
    setup
    build
    cd "$build"
    env -u DISPLAY ctest --output-on-failure --timeout 900
    ;;
  sanitize)
    # Penumbra's own code with ASan + UBSan (PENUMBRA_SANITIZE), in its own build folder, and
    # the whole suite under them: the sanitizer runtime is preloaded so that Debian's
    # (unsanitized) Python interpreter can load the sanitized modules. Leaks are not checked:
    # Mesa and VTK keep process-lifetime allocations (docs/hardening.md).
    setup
    sanitized="${PENUMBRA_SANITIZE_DIR:-$here/build-sanitize}"
    cmake -S "$here" -B "$sanitized" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_FLAGS=-O1 \
      -DPENUMBRA_SANITIZE=ON >/dev/null
    cmake --build "$sanitized" --parallel "$(nproc)"
    cd "$sanitized"
    LD_PRELOAD="$(gcc -print-file-name=libasan.so):$(gcc -print-file-name=libubsan.so)" \
      ASAN_OPTIONS=detect_leaks=0 UBSAN_OPTIONS=print_stacktrace=1 \
      env -u DISPLAY ctest --output-on-failure --timeout 900
    ;;
  *)
    echo "usage: $0 {render [SCENE.json [OUT.png]]|test|sanitize|setup|build}" >&2
    exit 2
    ;;
esac

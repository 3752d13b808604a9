#!/usr/bin/env bash
# One entry point for a fresh Debian 12 machine (no X server needed):
#
#   ./penumbra.sh render [SCENE.json [OUT.png]]   set up, build, render a scene with shadows
#                                                 (default: Data/Scenes/showcase.json to default.png)
#   ./penumbra.sh test                            set up, build, run the whole test suite
#   ./penumbra.sh setup                           only install the Debian packages
#   ./penumbra.sh build                           only configure and build
#   ./penumbra.sh sanitize                        build with AddressSanitizer and
#                                                 UndefinedBehaviorSanitizer, run the whole suite (CI)
#   ./penumbra.sh paraview [OUT.png]              set up ParaView 5.11, build Penumbra and its
#                                                 ParaView plugin against ParaView's VTK, test the
#                                                 plugin (pvpython, pvbatch on MPI ranks, a client
#                                                 on a 2- and a 4-rank pvserver), render
#                                                 paraview-demo.png with pvbatch
#   ./penumbra.sh paraview-run COMMAND...         run COMMAND (pvpython, pvbatch, paraview) where
#                                                 ParaView's Python modules are visible, with the
#                                                 plugin on PV_PLUGIN_PATH
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

# Installs those of the given Debian packages that are missing, without their recommends.
install_packages() {
  local missing=()
  for p in "$@"; do
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

setup() {
  install_packages "${packages[@]}"
}

# ---- ParaView. Debian 12's paraview-dev is unusable without python3-paraview (its
# CMake files name the Python modules, pvpython and the wrapping hierarchy files it ships), and
# python3-paraview conflicts with python3-vtk9, which libvtk9-dev and the default build need:
# both own /usr/lib/python3/dist-packages/vtkmodules. So python3-paraview is never installed:
# it is unpacked (dpkg -x, the version of the installed paraview) under the ParaView build
# folder and shown only inside a private mount namespace (unshare --mount), where read-only
# overlays put its files over /usr. That keeps one Debian root for both setups, changes
# nothing outside the namespace (the default build still finds VTK 9.1), needs no second root
# (a chroot or container would duplicate ~1 GB and need its own apt) and is undone by exiting.
# It needs root, as apt does; CI runs as root.
paraview_packages=(
  paraview paraview-dev
  qtbase5-dev qttools5-dev libqt5svg5-dev libqt5opengl5-dev   # paraview-dev's CMake needs Qt5's
  openmpi-bin                                                 # ParaView is built with MPI
)
paraview_dir="${PENUMBRA_PARAVIEW_DIR:-$here/build-paraview}"
paraview_build="$paraview_dir/build"
paraview_root="$paraview_dir/python3-paraview"
paraview_vtk_dir=/usr/lib/x86_64-linux-gnu/cmake/paraview-5.11/vtk

paraview_setup() {
  # Without recommends (install_packages): paraview recommends python3-paraview, whose
  # conflict would remove libvtk9-dev and python3-vtk9.
  install_packages "${paraview_packages[@]}"
  local version
  version="$(dpkg-query -W -f='${Version}' paraview)"
  if [ "$(cat "$paraview_root/VERSION" 2>/dev/null)" != "$version" ]; then
    rm -rf "$paraview_root"
    mkdir -p "$paraview_root"
    # apt-get update only if the package lists are missing or stale.
    (cd "$paraview_root" && { apt-get download "python3-paraview=$version" ||
      { apt-get update && apt-get download "python3-paraview=$version"; }; })
    dpkg -x "$paraview_root"/python3-paraview_*.deb "$paraview_root/root"
    echo "$version" >"$paraview_root/VERSION"
  fi
}

# Inside the namespace (internal: run by paraview_run through unshare).
paraview_mounts() {
  local r="$paraview_root/root"
  local py=/usr/lib/python3/dist-packages
  mount -t overlay penumbra-pv-python -o "lowerdir=$r$py:$py" "$py"
  # An overlay would merge the two vtkmodules folders; ParaView's must replace Debian's.
  mount --bind "$r$py/vtkmodules" "$py/vtkmodules"
  mount -t overlay penumbra-pv-bin -o "lowerdir=$r/usr/bin:/usr/bin" /usr/bin
  local vtk=/usr/lib/x86_64-linux-gnu/vtk
  mount -t overlay penumbra-pv-vtk -o "lowerdir=$r$vtk:$vtk" "$vtk"
}

paraview_run() {
  if [ "$(id -u)" -ne 0 ]; then
    echo "penumbra: the ParaView setup mounts inside a private mount namespace: run as root" >&2
    exit 1
  fi
  if [ ! -d "$paraview_root/root" ]; then
    echo "penumbra: ParaView is not set up; run ./penumbra.sh paraview first" >&2
    exit 1
  fi
  local cache="$paraview_build/CMakeCache.txt" plugins="" pythonpath=""
  if [ -f "$cache" ]; then
    plugins="$(sed -n 's/^PENUMBRA_PARAVIEW_PLUGIN_DIR:INTERNAL=//p' "$cache")"
    pythonpath="$(sed -n 's/^PENUMBRA_PYTHONPATH:INTERNAL=//p' "$cache")"
  fi
  PV_PLUGIN_PATH="$plugins" PYTHONPATH="$pythonpath${PYTHONPATH:+:$PYTHONPATH}" \
    unshare --mount --propagation private "$here/penumbra.sh" _paraview-namespace "$@"
}

paraview_build_plugin() {
  paraview_run cmake -S "$here" -B "$paraview_build" -DCMAKE_BUILD_TYPE=Release \
    -DVTK_DIR="$paraview_vtk_dir" -DPENUMBRA_PARAVIEW_PLUGIN=ON -DBUILD_TESTING=OFF >/dev/null
  paraview_run cmake --build "$paraview_build" --parallel "$(nproc)"
}

# Shadows across MPI ranks: every technique with 1 rank, then with 4 (the data split over
# them; images and visibility must equal the 1-rank run's), then 20 more 4-rank runs of one
# technique, each of which must finish. 4 ranks oversubscribe a 2-core machine, which
# OpenMPI refuses without --oversubscribe; CI runs as root, which it refuses without the
# two OMPI_ALLOW variables. A hung run is stopped (mpirun forwards the TERM to its ranks).
paraview_mpi_tests() {
  local dir="$paraview_build/Testing/ParaView/mpi" test="$here/Wrapping/ParaView/Testing/test_paraview_mpi.py"
  local env_mpi=(env -u DISPLAY OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1)
  local mpi=("${env_mpi[@]}" timeout -k 10 300 mpirun --oversubscribe)
  local mpi_terrain=("${env_mpi[@]}" timeout -k 10 900 mpirun --oversubscribe)
  local pvbatch=(pvbatch --mpi --symmetric --disable-xdisplay-test "$test" "$dir")
  rm -rf "$dir" && mkdir -p "$dir"
  paraview_run "${mpi[@]}" -np 1 "${pvbatch[@]}"
  paraview_run "${mpi[@]}" -np 4 "${pvbatch[@]}"
  # About 1 M triangles of terrain over 8 oversubscribed ranks, a sun and a point light: the
  # exact techniques' images equal the 1-rank ones and no rank holds more than a third of
  # the casters for the others (the need-based exchange).
  local terrain=raytraced,conservative,llsm-hybrid,volumes,shadowmap
  paraview_run "${mpi_terrain[@]}" -np 1 "${pvbatch[@]}" "$terrain" terrain
  paraview_run "${mpi_terrain[@]}" -np 8 "${pvbatch[@]}" "$terrain" terrain
  local run
  for run in $(seq 1 20); do
    paraview_run "${mpi[@]}" -np 4 "${pvbatch[@]}" raytraced >"$dir/repeat.log" 2>&1 ||
      { cat "$dir/repeat.log"; echo "penumbra: 4-rank run $run of 20 failed" >&2; return 1; }
  done
  echo "paraview MPI: 20 further 4-rank runs passed"
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
    scene="${2:-$here/Data/Scenes/showcase.json}"
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
  paraview)
    # Penumbra built against ParaView's bundled VTK 9.2 in its own folder, with the plugin; the
    # plugin's test (pvpython) and the demo (pvbatch), both with no X server: the plugin
    # registers Penumbra's EGL window when DISPLAY is unset.
    setup
    paraview_setup
    paraview_build_plugin
    # A hang must fail, not block CI; SIGKILL because ParaView's logger catches SIGTERM.
    limit=(timeout -s KILL 900)
    mkdir -p "$paraview_build/Testing/ParaView"
    PENUMBRA_TEST_OUTPUT="$paraview_build/Testing/ParaView" paraview_run env -u DISPLAY \
      "${limit[@]}" pvpython "$here/Wrapping/ParaView/Testing/test_paraview_plugin.py"
    PENUMBRA_TEST_OUTPUT="$paraview_build/Testing/ParaView" paraview_run env -u DISPLAY \
      "${limit[@]}" pvpython "$here/Wrapping/ParaView/Testing/test_paraview_light_size.py"
    paraview_mpi_tests
    # pvpython connected to a headless 2-rank pvserver that the test starts, with and without
    # the plugin on the server's PV_PLUGIN_PATH; then 20 times to a 4-rank pvserver, whose
    # image must equal the 4-rank pvbatch image of the MPI tests.
    paraview_run env -u DISPLAY timeout -s KILL 1800 pvpython \
      "$here/Wrapping/ParaView/Testing/test_paraview_client_server.py" \
      "$paraview_build/Testing/ParaView/client-server" \
      "$paraview_build/Testing/ParaView/mpi/mpi-raytraced-np4.png" 20
    out="$(realpath -m "${2:-$here/paraview-demo.png}")"
    paraview_run env -u DISPLAY "${limit[@]}" pvbatch --disable-xdisplay-test \
      "$here/Wrapping/ParaView/paraview-demo.py" "$out"
    ;;
  paraview-run)
    shift
    paraview_run "$@"
    ;;
  _paraview-namespace)
    shift
    paraview_mounts
    exec "$@"
    ;;
  *)
    echo "usage: $0 {render [SCENE.json [OUT.png]]|test|sanitize|setup|build|paraview [OUT.png]|paraview-run COMMAND...}" >&2
    exit 2
    ;;
esac

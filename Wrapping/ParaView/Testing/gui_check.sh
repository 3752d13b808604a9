#!/usr/bin/env bash
# The plugin in the Qt GUI, under Xvfb, connected to a headless 2-rank pvserver:
#
#   Wrapping/ParaView/Testing/gui_check.sh [OUTDIR]     (default build-paraview/build/Testing/ParaView/gui)
#
# Starts Xvfb on :99, `mpirun -np 2 pvserver --disable-xdisplay-test` without DISPLAY on a
# free port, and `paraview --server-url=... --script=gui_check.py` on :99; once the script
# has rendered, takes OUTDIR/gui.png (import -window root) and checks that
#   - no "Output Messages" window is shown (the server forwards no error on a correct render),
#   - the Properties panel shows the "Shadows" group: the header's image
#     (gui_check_shadows_header.png, cut from a good screenshot) is found in the panel,
#   - the statistics the GUI's Python read are the server's (a gather happened),
#   - the server shadowed the light's Shadow Radius as a disc light (soft shadows).
# Exit status 0 when all hold. Needs root (./penumbra.sh paraview-run), Xvfb, xdotool and
# ImageMagick; not run by ./penumbra.sh paraview. Every process it starts is stopped by pid.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
repo="$(cd "$here/../../.." && pwd)"
out="$(realpath -m "${1:-${PENUMBRA_PARAVIEW_DIR:-$repo/build-paraview}/build/Testing/ParaView/gui}")"

if [ "${2:-}" != "--inside" ]; then
  # Everything below runs in ParaView's mount namespace, so that the pids are the programs'.
  mkdir -p "$out"
  exec "$repo/penumbra.sh" paraview-run bash "$here/gui_check.sh" "$out" --inside
fi

pids=()
cleanup() {  # the GUI first, then the server, then Xvfb
  local i
  for ((i = ${#pids[@]} - 1; i >= 0; i--)); do
    kill "${pids[i]}" 2>/dev/null || true
    wait "${pids[i]}" 2>/dev/null || true
  done
}
trap cleanup EXIT
fail=0
check() {  # check OK WHAT
  if [ "$1" = 0 ]; then echo "ok    $2"; else echo "FAIL  $2"; fail=1; fi
}
wait_for() {  # wait_for FILE PATTERN SECONDS
  local deadline=$((SECONDS + $3))
  until grep -q "$2" "$1" 2>/dev/null; do
    if [ $SECONDS -ge $deadline ]; then echo "penumbra: timed out waiting for $2 in $1" >&2; return 1; fi
    sleep 1
  done
}

rm -f "$out/ready" "$out/gui.png"
Xvfb :99 -screen 0 1600x1000x24 -nolisten tcp >"$out/xvfb.log" 2>&1 &
pids+=($!)
port="$(python3 -c 'import socket; s = socket.socket(); s.bind(("localhost", 0)); print(s.getsockname()[1])')"
env -u DISPLAY OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 \
  timeout -s KILL 300 mpirun --oversubscribe -np 2 pvserver --disable-xdisplay-test \
  --server-port="$port" >"$out/pvserver.log" 2>&1 &
pids+=($!)
wait_for "$out/pvserver.log" "Accepting connection" 120
GUI_CHECK_READY="$out/ready" DISPLAY=:99 timeout -s KILL 300 paraview --dr \
  --server-url="cs://localhost:$port" --script="$here/gui_check.py" >"$out/paraview.log" 2>&1 &
pids+=($!)
wait_for "$out/ready" "RemoteCasterTriangles" 180
sleep 5 # the GUI paints the frame and the panel after the script
DISPLAY=:99 import -window root "$out/gui.png"

shown="$( (DISPLAY=:99 xdotool search --onlyvisible --name "Output Messages" 2>/dev/null || true) | wc -l)"
check "$([ "$shown" = 0 ] && echo 0 || echo 1)" "no Output Messages window is shown ($shown)"
# The Properties panel is the left dock: search the header there (ImageMagick's RMSE of the
# best match, 0 for identical pixels).
convert "$out/gui.png" -crop 560x1000+0+0 +repage "$out/panel.png"
score="$( (compare -metric RMSE -subimage-search "$out/panel.png" \
  "$here/gui_check_shadows_header.png" null: 2>&1 || true) | sed -n 's/.*(\([0-9.e-]*\)).*/\1/p' | head -1)"
check "$(python3 -c "print(0 if float('${score:-1}') < 0.05 else 1)")" \
  "the Shadows group header is in the Properties panel (best match RMSE ${score:-none})"
gathers="$(sed -n 's/^CasterGathers //p' "$out/ready")"
check "$([ "${gathers:-0}" -ge 1 ] && echo 0 || echo 1)" \
  "the GUI reads the server's gather statistics ($(tr '\n' ' ' <"$out/ready"))"
disc="$(grep -c "^Light light 0 (disc light of diameter 2, 52 samples): gears" "$out/ready" || true)"
check "$([ "$disc" = 1 ] && echo 0 || echo 1)" "the server shadows the sphere light as its disc ($(sed -n 's/^Light //p' "$out/ready"))"
errors="$(grep -c " ERR| " "$out/pvserver.log" || true)" # before the GUI is stopped
check "$([ "$errors" = 0 ] && echo 0 || echo 1)" "the server logged no error ($errors)"
echo "screenshot: $out/gui.png"
exit $fail

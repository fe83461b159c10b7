#!/usr/bin/env bash
# Renders what an OR user sees in RViz, headless: the demo (phantom scene, replayed depth bag,
# registration node, one service call with the linearised uncertainty) with rviz:=true under Xvfb, then a screenshot of the
# X screen after the registration has been published. Writes out/rviz/rviz.png (BTR_OUT to
# override) and fails if the picture is blank. Installs rviz, xvfb and imagemagick when missing.
set -euo pipefail
REPO_ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BTR_EXTRA_PACKAGES="rviz xvfb imagemagick libgl1-mesa-dri" bash "$REPO_ROOT/scripts/setup.sh"
OUT="${BTR_OUT:-$REPO_ROOT/out/rviz}"
BIN="$REPO_ROOT/build/ws/devel/lib/breast_tumour_registration"
mkdir -p "$OUT"
echo "[rviz] phantom scene and depth bag into $OUT"
"$BIN/btr_phantom" --out "$OUT/scene" --youngs-modulus 3400 --cell-size 6 --quiet > /dev/null
"$BIN/btr_make_bag" "$OUT/scene/scene.yaml" --out "$OUT/depth.bag" --frames 300 > /dev/null
set +u
# shellcheck disable=SC1091
source "$REPO_ROOT/build/ws/devel/setup.bash"
set -u
export ROS_HOME="$OUT/ros_home" ROS_LOG_DIR="$OUT/ros_log"
export ROS_MASTER_URI="http://localhost:${BTR_ROS_PORT:-11412}"
export LIBGL_ALWAYS_SOFTWARE=1  # Mesa's llvmpipe: no GPU needed
export BIN OUT
xvfb-run -a -s "-screen 0 1100x720x24" bash -c '
  set -u
  roslaunch --port "${BTR_ROS_PORT:-11412}" breast_tumour_registration demo.launch client:=false rviz:=true \
    scene:="$OUT/scene/scene.yaml" bag:="$OUT/depth.bag" > "$OUT/launch.log" 2>&1 &
  launch_pid=$!
  for _ in $(seq 1 60); do rosnode list > /dev/null 2>&1 && break; sleep 0.5; done
  rc=0
  timeout 180 "$BIN/btr_demo_client" _truth:="$OUT/depth.bag.truth.yaml" _preset:=balanced _uncertainty:=linear __name:=demo_client \
    > "$OUT/client.log" 2>&1 || rc=$?
  sleep 4  # RViz draws the latched markers and a few more clouds
  import -window root "$OUT/rviz.png"
  kill -INT "$launch_pid" 2>/dev/null || true
  for _ in $(seq 1 30); do kill -0 "$launch_pid" 2>/dev/null || break; sleep 0.5; done
  kill -KILL "$launch_pid" 2>/dev/null || true
  exit $rc
'
# A blank screen (RViz did not start or drew nothing) has no spread of colours.
spread=$(convert "$OUT/rviz.png" -colorspace Gray -format "%[fx:standard_deviation]" info:)
echo "[rviz] wrote $OUT/rviz.png (grey-level spread $spread)"
awk -v s="$spread" 'BEGIN { exit !(s > 0.02) }' || { echo "[rviz] the picture is blank"; exit 1; }

#!/usr/bin/env bash
# The README's main command: installs what is missing, builds, and runs the main job on the
# built-in default scene (the thesis's synthetic phantom, E = 3400 Pa):
#   1. btr_phantom generates the scene (prone and supine under gravity, tumours, landmarks);
#   2. btr_register registers it on plain files, with the supine scan misaligned by 10 deg / 5 mm;
#   3. btr_make_bag renders the supine phantom as a depth camera sees it (640 x 480, 1 mm noise);
#   4. roslaunch demo.launch starts a master, the registration node, bag replay and a client that
#      calls the service and prints the tumour centroid error and timings; everything stops after.
# Outputs go to out/demo (override with BTR_OUT).
# --from-labels: step 2 starts from the phantom as a segmented image instead (a RAS NIfTI label
# map with LPS Slicer fiducials, as 3D Slicer exports them): btr_scene_from_labels meshes it
# and btr_register registers that scene, with Slicer-ready results in registration/slicer/.
set -euo pipefail
FROM_LABELS=0
for a in "$@"; do
  case "$a" in
    --from-labels) FROM_LABELS=1 ;;
    *) echo "run_demo.sh: unknown option '$a' (known: --from-labels)" >&2; exit 2 ;;
  esac
done
set --
REPO_ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
bash "$REPO_ROOT/scripts/setup.sh"
OUT="${BTR_OUT:-$REPO_ROOT/out/demo}"
BIN="$REPO_ROOT/build/ws/devel/lib/breast_tumour_registration"
mkdir -p "$OUT"
echo
echo "[demo] 1/4 generating the synthetic phantom (thesis Sec. 5.2.1) into $OUT/scene"
if [ "$FROM_LABELS" = 1 ]; then
  "$BIN/btr_phantom" --out "$OUT/scene" --youngs-modulus 3400 --cell-size 6 --quiet --label-map "$OUT/labels"
  echo
  echo "[demo] 2/4 from the label map $OUT/labels/prone_labels.nii.gz: meshing it into a scene, then registering"
  truth=()
  for t in top middle bottom left right; do
    truth+=(--truth "$t,$OUT/labels/tumour_${t}_prone.obj,$OUT/labels/tumour_${t}_supine.obj")
  done
  # The phantom's tissue is homogeneous (a stiffer tumour would be told by the label table) and
  # its prone shape is the rest shape (--not-prone), as in its own scene.
  printf "stiffness: {gland: 1, tumour: 1}\n" > "$OUT/labels/labels.yaml"
  "$BIN/btr_scene_from_labels" "$OUT/labels/prone_labels.nii.gz" --labels "$OUT/labels/labels.yaml" --not-prone \
    --prone-landmarks "$OUT/labels/prone_landmarks.mrk.json" --supine-landmarks "$OUT/labels/supine_landmarks.mrk.json" \
    --supine-surface "$OUT/labels/supine_surface.obj" "${truth[@]}" --out "$OUT/label_scene"
  "$BIN/btr_register" "$OUT/label_scene/scene.yaml" --out "$OUT/registration" --preset balanced --quiet
else
  "$BIN/btr_phantom" --out "$OUT/scene" --youngs-modulus 3400 --cell-size 6 --quiet
  cp "$OUT/scene/scene.yaml" "$OUT/scene/scene_misaligned.yaml"
  echo "misalignment: {rotation_deg: [10, 0, 5], translation_mm: [5, -3, 4]}" >> "$OUT/scene/scene_misaligned.yaml"
  echo
  echo "[demo] 2/4 registering prone -> supine on files (rigid + landmark + surface) into $OUT/registration"
  "$BIN/btr_register" "$OUT/scene/scene_misaligned.yaml" --out "$OUT/registration" --preset balanced --quiet
fi
echo
echo "[demo] 3/4 rendering the supine phantom as a depth camera sees it into $OUT/depth.bag"
"$BIN/btr_make_bag" "$OUT/scene/scene.yaml" --out "$OUT/depth.bag" --frames 150
echo
echo "[demo] 4/4 ROS: registration node + rosbag play + service call (roslaunch starts and stops its own master)"
set +u
# shellcheck disable=SC1091
source "$REPO_ROOT/build/ws/devel/setup.bash"
set -u
export ROS_HOME="${ROS_HOME:-$OUT/ros_home}" ROS_LOG_DIR="${ROS_LOG_DIR:-$OUT/ros_log}"
export ROS_MASTER_URI="http://localhost:${BTR_ROS_PORT:-11411}"
# The node and the bag replay run under roslaunch in the background; the client runs here and
# its exit code is the demo's. Then the launch is stopped with SIGINT (its normal shutdown).
FILTER="TF_REPEATED_DATA|^\s*$|^ \* |PARAMETERS|NODES|SUMMARY|^    |process\[|auto-starting|setting /run_id|Checking log|Done checking|xml is deprecated|started core service|ROS_MASTER_URI|killing on exit|shutting down processing monitor|^\S*done\S*$"
roslaunch --port "${BTR_ROS_PORT:-11411}" breast_tumour_registration demo.launch client:=false \
  scene:="$OUT/scene/scene.yaml" bag:="$OUT/depth.bag" > >(grep --line-buffered -vE "$FILTER") 2>&1 &
launch_pid=$!
for _ in $(seq 1 60); do rosnode list > /dev/null 2>&1 && break; sleep 0.5; done  # the master is up
rc=0
timeout 180 "$BIN/btr_demo_client" _truth:="$OUT/depth.bag.truth.yaml" _preset:=balanced __name:=demo_client || rc=$?
echo "[demo] stopping the node, the bag replay and the ROS master"
kill -INT "$launch_pid" 2>/dev/null || true
for _ in $(seq 1 30); do kill -0 "$launch_pid" 2>/dev/null || break; sleep 0.5; done
kill -KILL "$launch_pid" 2>/dev/null || true
wait "$launch_pid" 2>/dev/null || true
echo
echo "[demo] done (exit $rc). Files: $OUT/registration/report.json, $OUT/registration/cross_section.png,"
echo "[demo] $OUT/registration/registered.vtk and tumour_*_registered.obj (ParaView, 3D Slicer); bag: $OUT/depth.bag"
exit "$rc"

#!/usr/bin/env bash
# Resident memory of the registration node while a depth bag (640 x 480 at 30 Hz) is replayed
# in a loop: one sample after about 100 clouds and then every 1000, up to CLOUDS clouds
# (time-based: the bag plays at 30 Hz). Every cloud is filtered and tracked (ICP); the
# per-cloud processing times the node logs are printed at the end.
# Usage: bash bench/measure_node_memory.sh [clouds]   (after scripts/setup.sh; makes its own scene and bag)
set -euo pipefail
REPO_ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BIN="$REPO_ROOT/build/ws/devel/lib/breast_tumour_registration"
CLOUDS="${1:-10000}"
WORK="${BTR_BENCH_DIR:-$(mktemp -d)}"
"$BIN/btr_phantom" --out "$WORK/scene" --cell-size 6 --quiet > /dev/null
"$BIN/btr_make_bag" "$WORK/scene/scene.yaml" --out "$WORK/depth.bag" --frames 150 > /dev/null
set +u
source "$REPO_ROOT/build/ws/devel/setup.bash"
set -u
export ROS_HOME="$WORK/ros_home" ROS_LOG_DIR="$WORK/ros_log" ROS_MASTER_URI="http://localhost:11421"
roscore -p 11421 > "$WORK/roscore.log" 2>&1 &
CORE=$!
trap 'kill $PLAY $NODE 2>/dev/null; kill $CORE 2>/dev/null; wait 2>/dev/null' EXIT
sleep 3
roslaunch --port 11421 breast_tumour_registration registration_node.launch scene:="$WORK/scene/scene.yaml" \
  initial_model_pose:="[0.11, -0.05, 0.75, 0, 0, 0.0873]" > "$WORK/node.log" 2>&1 &
NODE=$!
sleep 4
rosbag play -q -l "$WORK/depth.bag" > /dev/null 2>&1 &
PLAY=$!
PID=""
for _ in $(seq 1 20); do PID=$(pgrep -f "devel/lib/breast_tumour_registration/registration_node" | head -1 || true); [ -n "$PID" ] && break; sleep 0.5; done
echo "# $(date -u +%F) on $(nproc) cores; node pid $PID; bag replayed in a loop at 30 Hz"
echo "| clouds replayed (approx.) | VmRSS [MiB] | VmHWM [MiB] |"
echo "|---|---|---|"
start=$(date +%s)
for target in 100 $(seq 1000 1000 "$CLOUDS"); do
  while :; do
    n=$(( ($(date +%s) - start) * 30 ))
    [ "$n" -ge "$target" ] && break
    sleep 1
  done
  rss=$(awk '/VmRSS/ {printf "%.1f", $2/1024}' /proc/$PID/status)
  hwm=$(awk '/VmHWM/ {printf "%.1f", $2/1024}' /proc/$PID/status)
  echo "| $target | $rss | $hwm |"
done
echo
echo "Per-cloud processing time in the node (PointCloud2 conversion, filtering and ICP; the tf wait"
echo "excluded), as the node logs it every 300 tracked clouds: wall time, and CPU time of the"
echo "callback thread (without the time the bag player and the master took the cores):"
echo
echo '```'
grep -o "depth tracking per cloud.*percentile" "$WORK/node.log" || echo "(no timing line in $WORK/node.log)"
echo '```'

#!/usr/bin/env bash
# The README's main command: installs what is missing, builds, and runs the main job on
# the built-in default scene. Outputs go to out/demo (override with BTR_OUT).
set -euo pipefail
REPO_ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
bash "$REPO_ROOT/scripts/setup.sh"
OUT="${BTR_OUT:-$REPO_ROOT/out/demo}"
BIN="$REPO_ROOT/build/ws/devel/lib/breast_tumour_registration"
echo "[demo] generating the synthetic phantom (thesis Sec. 5.2.1, E = 3400 Pa) into $OUT"
"$BIN/btr_phantom" --out "$OUT" --youngs-modulus 3400 --cell-size 6 --quiet "$@"
echo "[demo] done. Open $OUT/prone.vtk and $OUT/supine.vtk in ParaView or 3D Slicer; scene: $OUT/scene.yaml"

#!/usr/bin/env bash
# The README's main command: installs what is missing, builds, and runs the main job on the
# built-in default scene: the thesis's synthetic phantom (E = 3400 Pa), registered from prone
# to supine with a simulated 10 deg / 5 mm misalignment of the supine scan.
# Outputs go to out/demo (override with BTR_OUT).
set -euo pipefail
REPO_ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
bash "$REPO_ROOT/scripts/setup.sh"
OUT="${BTR_OUT:-$REPO_ROOT/out/demo}"
BIN="$REPO_ROOT/build/ws/devel/lib/breast_tumour_registration"
echo
echo "[demo] 1/2 generating the synthetic phantom (thesis Sec. 5.2.1) into $OUT/scene"
"$BIN/btr_phantom" --out "$OUT/scene" --youngs-modulus 3400 --cell-size 6 --quiet
# The supine data of the default scene is misaligned on purpose: the rigid step must undo it.
cp "$OUT/scene/scene.yaml" "$OUT/scene/scene_misaligned.yaml"
echo "misalignment: {rotation_deg: [10, 0, 5], translation_mm: [5, -3, 4]}" >> "$OUT/scene/scene_misaligned.yaml"
echo
echo "[demo] 2/2 registering prone -> supine (rigid + landmark + surface steps) into $OUT/registration"
rc=0
"$BIN/btr_register" "$OUT/scene/scene_misaligned.yaml" --out "$OUT/registration" --preset balanced || rc=$?
echo
echo "[demo] done (exit $rc). Report: $OUT/registration/report.json; picture: $OUT/registration/cross_section.png;"
echo "[demo] meshes: $OUT/registration/registered.vtk and tumour_*_registered.obj (open in ParaView or 3D Slicer)."
exit $rc

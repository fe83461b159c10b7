# Shell helpers of a preset study (bench/results/*_preset_*/run.sh source this file):
#   scene_copy SCENE COPY_NAME KEY VALUE   writes a copy of SCENE beside it (its relative paths stay
#                                          valid) with material.KEY: VALUE, and prints its path;
#   run_jobs OUT JOB...                    runs btr_register for each JOB ("VARIANT NAME SCENE ARGS...")
#                                          into OUT/VARIANT/NAME, two at a time, one OpenMP thread
#                                          each, the log and exit code in OUT/VARIANT_NAME.log;
#   study_main MODE OUT NAME=SCENE...      calls the study's jobs_for MODE NAME SCENE for each scene
#                                          (it appends JOBs to the array `jobs`, and returns non-zero
#                                          for an unknown mode), then run_jobs.
BIN=${BTR_BIN:-/work/main/build/ws/devel/lib/breast_tumour_registration}/btr_register
export OMP_NUM_THREADS=1
scene_copy() {
  local copy
  copy="$(dirname "$1")/.$2.yaml"
  /usr/bin/python3 - "$1" "$copy" "$3" "$4" <<'PY'
import sys, yaml
s = yaml.safe_load(open(sys.argv[1]))
s.setdefault('material', {})[sys.argv[3]] = sys.argv[4]
yaml.safe_dump(s, open(sys.argv[2], 'w'))
PY
  echo "$copy"
}
run_jobs() {
  OUT=$1; shift
  mkdir -p "$OUT"
  run() { v=$1; n=$2; sc=$3; shift 3; "$BIN" "$sc" --out "$OUT/$v/$n" -q "$@" > "$OUT/${v}_$n.log" 2>&1; echo "exit $?" >> "$OUT/${v}_$n.log"; }
  export -f run; export OUT BIN
  printf '%s\n' "$@" | xargs -P 2 -L 1 bash -c 'run "$@"' _
}
study_main() {
  local mode=$1 out=$2 spec
  shift 2
  jobs=()
  for spec in "$@"; do jobs_for "$mode" "${spec%%=*}" "${spec#*=}" || exit 2; done
  run_jobs "$out" "${jobs[@]}"
}

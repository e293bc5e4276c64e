#!/usr/bin/env bash
# The default trajectories of a refactoring's "before" and "after", to compare byte for byte (cmp).
#
# Usage: tools/dev/reference-runs.sh BIN_DIR OUT_DIR [DATA_DIR]
#   Renders (once, into DATA_DIR, default ./refdata) the demo sequence (tools/run-demo.sh's 300 frames, 5 cameras)
#   and isec_indoor (BENCHMARKS.md section 1, 857 frames, 7 cameras), then runs BIN_DIR/mcslam-run on each with
#   5 cameras, stereo (1,2), one camera (2) and, on isec_indoor, 3 cameras without overlap (2,5,6), and mcslamd
#   replaying the demo sequence losslessly. Writes OUT_DIR/<run>.tum, <run>.kf.tum, <run>.extrinsics.yaml.
# Compare two such folders: tools/dev/reference-runs.sh --compare OUT_A OUT_B
set -euo pipefail

if [ "${1:-}" = "--compare" ]; then
  a="$2"; b="$3"; status=0
  for f in "$a"/*.tum "$a"/*.yaml; do
    n=$(basename "$f")
    if cmp -s "$f" "$b/$n"; then echo "same     $n"; else echo "DIFFERS  $n"; status=1; fi
  done
  exit $status
fi

bin="$(realpath "$1")"; out="$2"; data="${3:-refdata}"
mkdir -p "$out" "$data"
render() {  # name, mcslam-sim arguments
  local name="$1"; shift
  if [ ! -f "$data/$name/.complete" ]; then
    "$bin/mcslam-sim" --rig isec --world indoor --trajectory ground --no-depth --out "$data/$name" --overwrite "$@"
    touch "$data/$name/.complete"
  fi
}
render demo --frames 300 --cameras 0,1,2,3,4
render isec_indoor --rate 10 --seed 1

run() {  # name, dataset, cameras
  local name="$1" ds="$2" cams="$3"
  "$bin/mcslam-run" --dataset "$data/$ds" ${cams:+--cameras "$cams"} --quiet --out "$out/$name.tum" \
    --keyframes "$out/$name.kf.tum" --extrinsics "$out/$name.extrinsics.yaml" --stats "$out/$name.stats.json"
}
run demo_5cam demo ""
run demo_stereo demo 1,2
run demo_mono demo 2
run isec_5cam isec_indoor 0,1,2,3,4
run isec_stereo isec_indoor 1,2
run isec_mono isec_indoor 2
run isec_3nov isec_indoor 2,5,6

# mcslamd replaying the demo sequence losslessly: its trajectory file.
daemon_dir="$(mktemp -d)"
cat > "$daemon_dir/replay.yaml" <<YAML
log_level: warn
source:
  type: dataset
  dataset: {path: $(realpath "$data/demo"), rate: fastest, at_end: exit}
trigger: {mode: free_running, rate_hz: 20}
publish:
  shm: {name: /mcslam_refrun_$$}
  udp: {destinations: []}
output: {directory: $daemon_dir, trajectory: trajectory.tum}
slam: {}
YAML
"$bin/mcslamd" --config "$daemon_dir/replay.yaml" > "$daemon_dir/log" 2>&1 || { cat "$daemon_dir/log"; exit 1; }
cp "$daemon_dir/trajectory.tum" "$out/daemon_demo_5cam.tum"
rm -rf "$daemon_dir"
echo "reference-runs: wrote $out"

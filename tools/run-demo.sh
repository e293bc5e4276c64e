#!/usr/bin/env bash
# The main job on a built-in default: sets up (packages + build), renders a simulated 5-camera rig (the paper's
# ISEC front cameras) driving through the indoor world, runs the SLAM on it and evaluates the trajectory.
#
# Usage: tools/run-demo.sh [--frames N] [--cameras 0,1,2,3,4] [--world indoor|corridor|courtyard] [--out DIR]
#   --frames 0 renders the whole closed loop (about 76 m; a few minutes of rendering on two cores).
# Writes DIR/dataset (the rendered ASL dataset, reused by the next run with the same settings),
# DIR/trajectory.tum, DIR/keyframes.tum, DIR/stats.json, DIR/extrinsics.yaml and DIR/trajectory.png.
set -euo pipefail
cd "$(dirname "$0")/.."

frames=300
cameras=0,1,2,3,4
world=indoor
out=demo_out
while (($#)); do
  case "$1" in
    --frames) frames="$2"; shift 2 ;;
    --cameras) cameras="$2"; shift 2 ;;
    --world) world="$2"; shift 2 ;;
    --out) out="$2"; shift 2 ;;
    -h|--help) sed -n '2,9p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "run-demo: unknown option '$1' (see --help)" >&2; exit 2 ;;
  esac
done

tools/setup.sh
bin=build/bin
dataset="$out/dataset"
stamp="isec $world ground frames=$frames cameras=$cameras"
mkdir -p "$out"
if [ "$(cat "$dataset/.demo-settings" 2>/dev/null)" != "$stamp" ]; then
  echo "run-demo: rendering $stamp into $dataset"
  "$bin/mcslam-sim" --rig isec --world "$world" --trajectory ground --frames "$frames" --cameras "$cameras" \
    --no-depth --out "$dataset" --overwrite
  echo "$stamp" > "$dataset/.demo-settings"
else
  echo "run-demo: reusing the rendered dataset in $dataset"
fi

echo "run-demo: running mcslam-run"
"$bin/mcslam-run" --dataset "$dataset" --out "$out/trajectory.tum" --keyframes "$out/keyframes.tum" \
  --stats "$out/stats.json" --extrinsics "$out/extrinsics.yaml"
echo
align=()
# One camera's trajectory has an arbitrary unit: compared with the truth after a similarity, not a rigid motion.
case "$cameras" in *,*) ;; *) align=(--align sim3) ;; esac
"$bin/mcslam-eval" ape "$dataset" "$out/trajectory.tum" "${align[@]}" --plot "$out/trajectory.png"
echo
echo "run-demo: trajectory $out/trajectory.tum, timing and states $out/stats.json, top view $out/trajectory.png"

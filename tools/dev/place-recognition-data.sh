#!/usr/bin/env bash
# The data of place recognition's vocabulary and of its precision-recall measurement (BENCHMARKS.md, section 10).
#   tools/dev/place-recognition-data.sh OUT [KITTI_RAW_DIR]
# Renders into OUT: the training sequences (three worlds and a hand-held walk, seeds 11-12, 2 Hz, the isec rig's
# seven cameras) and the evaluation routes (seed 3: each world's ground loop driven twice, the second lap 0.3 m to
# the side and turned by 10 degrees; the corridor also back the other way). With KITTI_RAW_DIR (a KITTI raw drive:
# image_00..03/data), trains the vocabulary on the renders and those real images into OUT/orb_vocabulary.mcvoc.
set -euo pipefail
out="${1:?usage: place-recognition-data.sh OUT [KITTI_RAW_DIR]}"
kitti="${2:-}"
bin="$(cd "$(dirname "$0")/../.." && pwd)/build/bin"
route="$(dirname "$0")/revisit-route.py"
mkdir -p "$out"
cd "$out"
for w in indoor corridor courtyard; do
  "$bin/mcslam-sim" --world "$w" --seed 11 --rate 2 --no-depth --quiet --overwrite --out "train_$w"
done
"$bin/mcslam-sim" --world indoor --seed 12 --trajectory handheld --rate 2 --no-depth --quiet --overwrite --out train_handheld
for w in indoor corridor courtyard; do
  "$bin/mcslam-sim" --world "$w" --seed 3 --rate 10 --cameras 0 --no-depth --quiet --overwrite --out "loop_$w"
  python3 "$route" "loop_$w/groundtruth.txt" "route_$w.txt" --laps 2 --offset 0.3 --yaw 10
  "$bin/mcslam-sim" --world "$w" --seed 3 --trajectory "file:route_$w.txt" --rate 4 --no-depth --quiet --overwrite \
    --out "eval_$w"
done
python3 "$route" loop_corridor/groundtruth.txt route_corridor_reverse.txt --laps 2 --offset 0.2 --yaw 0 --reverse
"$bin/mcslam-sim" --world corridor --seed 3 --trajectory file:route_corridor_reverse.txt --rate 4 --no-depth --quiet \
  --overwrite --out eval_corridor_reverse
if [ -n "$kitti" ]; then
  "$bin/mcslam-places" train-vocabulary --dataset train_indoor --dataset train_corridor --dataset train_courtyard \
    --dataset train_handheld --images "$kitti/image_00/data" --images "$kitti/image_01/data" \
    --images "$kitti/image_02/data" --images "$kitti/image_03/data" --every 1 --branching 10 --depth 4 \
    --out orb_vocabulary.mcvoc
fi

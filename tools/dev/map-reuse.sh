#!/usr/bin/env bash
# Map reuse (BENCHMARKS.md, section 10): the whole sequence in one run, then its first HALF frames with --map-out
# and the rest with --map-in --localize; prints both ATEs (the halves' trajectories together under one alignment).
# Usage: tools/dev/map-reuse.sh TAG DATASET CAMERAS HALF GROUNDTRUTH   (CAMERAS "" = all; files TAG.* here)
set -euo pipefail
B="$(cd "$(dirname "$0")/../.." && pwd)/build/bin"
tag=$1; D=$2; cams=$3; half=$4; G=$5
camopt=""; [ -n "$cams" ] && camopt="--cameras $cams"
$B/mcslam-run --dataset $D $camopt --quiet --out $tag.full.tum --stats $tag.full.json 2>/dev/null
$B/mcslam-run --dataset $D $camopt --quiet --frames $half --out $tag.a.tum --map-out $tag.a.map 2>/dev/null
$B/mcslam-run --dataset $D $camopt --quiet --start $half --map-in $tag.a.map --localize --out $tag.b.tum --stats $tag.b.json 2>$tag.b.log
(cat $tag.a.tum; grep -v "^#" $tag.b.tum) > $tag.ab.tum
full=$($B/mcslam-eval ape $G $tag.full.tum | awk '/rmse  /{print $2}')
ab=$($B/mcslam-eval ape $G $tag.ab.tum | awk '/rmse  /{print $2}')
placed=$(python3 -c "import json;d=json.load(open('$tag.b.json'));p=d['places'];print(p['placed_frame'],p['localization_corrections'],d['tracking_states'])")
echo "$tag full $full halves $ab placed/corrections $placed map $(stat -c %s $tag.a.map)"

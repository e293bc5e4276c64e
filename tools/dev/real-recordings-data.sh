#!/usr/bin/env bash
# The real recordings of BENCHMARKS.md ("Real recordings (issue 22)"), laid out for mcslam-run from git snapshots of
# three public repositories (git directories, e.g. what the fetch tool brings):
#   tools/dev/real-recordings-data.sh OUT MEAM620_GIT OPEN_VINS_GIT SOFT_GIT
# OUT/MH_01_excerpt: EuRoC MH_01_easy frames #100-#699 (30 s of the 182 s, stereo 752x480 at 20 Hz, from
#   iamliguangming/MEAM620) as an EuRoC mav0/ folder, each camera's data.csv listing the frames present, and
#   open_vins' ground truth of the whole sequence (ov_data/euroc_mav/MH_01_easy.txt, TUM, IMU frame) written as
#   mav0/state_groundtruth_estimate0/data.csv.
# OUT/kitti_2011_09_26_drive_0001: the KITTI raw drive's four cameras as downloaded (synced+rectified), from
#   Mayankm96/Stereo-Odometry-SOFT at 01064067.
set -euo pipefail
[ $# -eq 4 ] || { echo "usage: real-recordings-data.sh OUT MEAM620_GIT OPEN_VINS_GIT SOFT_GIT" >&2; exit 2; }
out="$1" meam="$2" ovins="$3" soft="$4"
mkdir -p "$out"
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT

src=meam620-2020-proj2_1/proj2_1/dataset/MachineHall01_reduced
# (git may name the snapshot's absent imu0/data.csv, too large to be stored; it is not needed.)
git --git-dir "$meam" archive HEAD "$src/cam0" "$src/cam1" | tar -x -C "$tmp"
mav0="$out/MH_01_excerpt/mav0"
for c in cam0 cam1; do
  mkdir -p "$mav0/$c/data"
  cp "$tmp/$src/$c/sensor.yaml" "$mav0/$c/"
  mv "$tmp/$src/$c/data/"*.png "$mav0/$c/data/"
  # The snapshot's data.csv lists all 3,682 frames; only 600 are in it.
  { echo "#timestamp [ns],filename"; ls "$mav0/$c/data" | sort | sed 's/\.png$//' | awk '{print $1","$1".png"}'; } \
    >"$mav0/$c/data.csv"
done
mkdir -p "$mav0/state_groundtruth_estimate0"
# TUM "t[s] x y z qx qy qz qw" -> EuRoC "t[ns],x,y,z,qw,qx,qy,qz" (the stamps' decimals kept exactly).
git --git-dir "$ovins" show HEAD:ov_data/euroc_mav/MH_01_easy.txt | awk '
  BEGIN { print "#timestamp [ns], p_RS_R_x [m], p_RS_R_y [m], p_RS_R_z [m], q_RS_w [], q_RS_x [], q_RS_y [], q_RS_z []" }
  /^#/ || NF < 8 { next }
  { split($1, s, "."); frac = substr(s[2] "000000000", 1, 9)
    printf "%s%s,%s,%s,%s,%s,%s,%s,%s\n", s[1], frac, $2, $3, $4, $8, $5, $6, $7 }' \
  >"$mav0/state_groundtruth_estimate0/data.csv"

git --git-dir "$soft" archive 01064067fef51c68b02d7967a84872d0ca300df5 code/data/DataSet1 | tar -x -C "$tmp"
rm -rf "$out/kitti_2011_09_26_drive_0001"
mv "$tmp/code/data/DataSet1" "$out/kitti_2011_09_26_drive_0001"
echo "$out/MH_01_excerpt and $out/kitti_2011_09_26_drive_0001 written"

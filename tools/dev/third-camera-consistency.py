#!/usr/bin/env python3
"""Depths of a camera pair's two-view points against those of the whole rig, on real frames without depth
ground truth (BENCHMARKS.md section 3, "Repeating texture").

  tools/dev/third-camera-consistency.py DATASET --pair 0,1 --rig 0,1,2,3 --frames 0,10,20 [--config FILE]
      [--max-sigma 0.0067]

For every frame, mcslam-features runs twice: with the pair's cameras only (every point has two views, nothing
checks its depth), and with the whole rig. A pair point whose first camera's keypoint is, in the whole rig's run,
part of a track of three or more views (a third ray checks that depth) is judged against it: the share within
2% of that depth and the share more than 5% off. Keypoints are paired by camera, octave and position (within
1.5 px: the alignment may move them); only points whose depth sigma (both) is at most --max-sigma count. --config
runs the pair a second time with that slam: YAML (e.g. a check turned off): its points that the default run lacks
are reported apart (what the default rejects). The rig's run keeps the defaults. Body frame = the first pair
camera's for the range comparison (KITTI raw: rectified camera 0).
"""
import argparse
import json
import math
import os
import subprocess


def features(binary, dataset, cameras, frame, config):
    cmd = [binary, dataset, "--cameras", cameras, "--frame", str(frame), "--json"]
    if config:
        cmd += ["--config", config]
    return json.loads(subprocess.run(cmd, capture_output=True, text=True, check=True).stdout)


def keyed_points(doc, camera, min_views, max_views, max_sigma):
    """(octave, x, y, range) of `camera`'s keypoint for every point with a depth and min..max views."""
    out = []
    for mv in doc["multiview"]:
        n = len(mv["keypoints"])
        if not mv["has_point"] or mv["relative_depth_sigma"] > max_sigma or not min_views <= n <= max_views:
            continue
        for kp in mv["keypoints"]:
            if kp["camera"] == camera:
                out.append((kp["octave"], kp["x"], kp["y"], math.sqrt(sum(v * v for v in mv["point_body"]))))
    return out


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("dataset")
    ap.add_argument("--pair", required=True)
    ap.add_argument("--rig", required=True)
    ap.add_argument("--frames", required=True, help="comma-separated frame indices")
    ap.add_argument("--config", help="slam: YAML for a second run of the pair")
    ap.add_argument("--max-sigma", type=float, default=0.0067, help="relative depth sigma of the points judged")
    ap.add_argument("--bin", default=os.path.join(here, "..", "..", "build", "bin"))
    a = ap.parse_args()
    binary = os.path.join(a.bin, "mcslam-features")
    camera = int(a.pair.split(",")[0])
    counts = {"default": [0, 0, 0, 0], "rejected": [0, 0, 0, 0]}  # points, judged, within 2%, more than 5% off

    def judge(points, rig, c):
        for octave, x, y, r in points:
            c[0] += 1
            near = [q for q in rig if q[0] == octave and (q[1] - x) ** 2 + (q[2] - y) ** 2 <= 1.5 ** 2]
            if not near:
                continue
            truth = min(near, key=lambda q: (q[1] - x) ** 2 + (q[2] - y) ** 2)[3]
            error = abs(r - truth) / truth
            c[1] += 1
            c[2] += error < 0.02
            c[3] += error > 0.05

    for frame in map(int, a.frames.split(",")):
        pair = keyed_points(features(binary, a.dataset, a.pair, frame, None), camera, 2, 2, a.max_sigma)
        rig = keyed_points(features(binary, a.dataset, a.rig, frame, None), camera, 3, 64, a.max_sigma)
        judge(pair, rig, counts["default"])
        if a.config:
            other = keyed_points(features(binary, a.dataset, a.pair, frame, a.config), camera, 2, 2, a.max_sigma)
            kept = {(p[0], round(p[1], 1), round(p[2], 1)) for p in pair}
            judge([p for p in other if (p[0], round(p[1], 1), round(p[2], 1)) not in kept], rig, counts["rejected"])
    for name, (points, judged, within, off) in counts.items():
        if name == "rejected" and not a.config:
            continue
        print(f"pair {a.pair}, {name}: {points} two-view points (depth sigma <= {a.max_sigma}), {judged} also in a "
              f"track of 3+ views of {a.rig}: within 2% {within} ({within / max(judged, 1):.3f}), more than 5% off "
              f"{off} ({off / max(judged, 1):.3f})")

if __name__ == "__main__":
    main()

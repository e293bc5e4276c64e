#!/usr/bin/env python3
"""Local scale of a trajectory: estimated distance over N frames divided by the true one.

A whole-run Sim(3) scale hides a map whose unit drifts (a rig without overlap, one camera); this prints how the
scale wanders along the run. Pairs whose true distance is under --min-distance are skipped (a turn in place says
nothing of the scale). Poses are matched by timestamp (TUM or EuRoC ground truth, seconds or nanoseconds).

  tools/eval/local_scale.py DATASET/groundtruth.txt run.tum [--frames 40] [--series] [--span FIRST LAST]
                            [--from FIRST]

--span prints the unit over one stretch: the path the estimate travelled between two poses over the true path
(indices into the matched poses, negative from the end: --span -120 -1 is how the run finishes).
--from counts only the spans that start at that pose or later (after the scale converged, say).
"""
import argparse
import math
import sys

from tum_poses import load_poses


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument('groundtruth')
    ap.add_argument('estimate')
    ap.add_argument('--frames', type=int, default=40, help='distance over this many frames (default 40)')
    ap.add_argument('--min-distance', type=float, default=0.5, help='metres the truth must move (default 0.5)')
    ap.add_argument('--series', action='store_true', help='also print the local scale every 20 frames')
    ap.add_argument('--from', dest='first', type=int, default=0, metavar='FIRST',
                    help='only spans starting at this pose or later (default 0)')
    ap.add_argument('--span', nargs=2, type=int, metavar=('FIRST', 'LAST'),
                    help='also print the path travelled between these poses over the true one')
    a = ap.parse_args()
    gt, est = load_poses(a.groundtruth, 3), load_poses(a.estimate, 3)
    ts = sorted(t for t in est if t in gt)
    if len(ts) <= a.frames:
        sys.exit(f"only {len(ts)} poses of {a.estimate} have a ground-truth pose at the same time (need > {a.frames})")
    ratios = []
    if not 0 <= a.first < len(ts) - a.frames:
        sys.exit(f"--from {a.first}: needs a pose more than {a.frames} before the last of the {len(ts)} matched")
    for i in range(a.first, len(ts) - a.frames):
        t0, t1 = ts[i], ts[i + a.frames]
        d_true = math.dist(gt[t0], gt[t1])
        if d_true < a.min_distance:
            continue
        ratios.append((i, math.dist(est[t0], est[t1]) / d_true))
    if a.span:
        first, last = (i + len(ts) if i < 0 else i for i in a.span)
        if not 0 <= first < last < len(ts):
            sys.exit(f"--span {a.span[0]} {a.span[1]}: needs two poses in order among the {len(ts)} matched")
        path = lambda p: sum(math.dist(p[ts[i]], p[ts[i + 1]]) for i in range(first, last))
        if path(gt) <= 0:
            sys.exit(f"--span {a.span[0]} {a.span[1]}: the truth does not move there")
        print(f"unit over poses {first}-{last}: {path(est) / path(gt):.3f}")
    if not ratios:
        sys.exit(f"the truth never moves {a.min_distance} m over {a.frames} frames")
    if a.series:
        for i, s in ratios[::20]:
            print(f"frame {i:5d}  {s:.3f}")
    s = sorted(r for _, r in ratios)
    q = lambda f: s[min(len(s) - 1, int(f * len(s)))]
    within = sum(1 for r in s if abs(r - 1) <= 0.05) / len(s)
    print(f"local scale over {a.frames} frames ({len(s)} spans): min {s[0]:.3f} p10 {q(0.1):.3f} "
          f"median {q(0.5):.3f} p90 {q(0.9):.3f} max {s[-1]:.3f}; within 5%: {100 * within:.1f}% of the spans")


if __name__ == '__main__':
    main()

#!/usr/bin/env python3
"""Start-to-end error of a trajectory: its relative pose from its first pose to its last, against the ground
truth's between the same times (translation error in metres, and as a share of the true path between them).
Frame-free: no alignment. For a loop that ends where it started it is the drift a loop closure must remove
(BENCHMARKS.md section 10). Poses are matched by timestamp (TUM or EuRoC ground truth, seconds or nanoseconds).

  tools/eval/start_to_end.py DATASET/groundtruth.txt keyframes.tum
"""
import argparse
import math
import sys

from tum_poses import load_poses


def rotation(qx, qy, qz, qw):
    return ((1 - 2 * (qy * qy + qz * qz), 2 * (qx * qy - qz * qw), 2 * (qx * qz + qy * qw)),
            (2 * (qx * qy + qz * qw), 1 - 2 * (qx * qx + qz * qz), 2 * (qy * qz - qx * qw)),
            (2 * (qx * qz - qy * qw), 2 * (qy * qz + qx * qw), 1 - 2 * (qx * qx + qy * qy)))


def relative_translation(a, b):
    """b's position in a's body frame: R_a^T (t_b - t_a)."""
    R = rotation(*a[3:7])
    d = [b[i] - a[i] for i in range(3)]
    return [sum(R[j][i] * d[j] for j in range(3)) for i in range(3)]


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument('groundtruth')
    ap.add_argument('estimate')
    a = ap.parse_args()
    gt, est = load_poses(a.groundtruth, 7), load_poses(a.estimate, 7)
    ts = sorted(t for t in est if t in gt)
    if len(ts) < 2:
        sys.exit(f"only {len(ts)} poses of {a.estimate} have a ground-truth pose at the same time (need 2)")
    first, last = ts[0], ts[-1]
    error = math.dist(relative_translation(est[first], est[last]), relative_translation(gt[first], gt[last]))
    truth = sorted(t for t in gt if first <= t <= last)
    path = sum(math.dist(gt[s][:3], gt[t][:3]) for s, t in zip(truth, truth[1:]))
    share = f", {100 * error / path:.3f}% of the {path:.1f} m path" if path > 0 else ""
    print(f"start-to-end error {error:.3f} m (t {first:.3f} .. {last:.3f} s{share})")


if __name__ == '__main__':
    main()

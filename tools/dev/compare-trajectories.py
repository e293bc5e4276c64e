#!/usr/bin/env python3
"""Compares trajectories of the same rig frames without ground truth (BENCHMARKS.md, "Real recordings").

  tools/dev/compare-trajectories.py REF.tum EST.tum [EST.tum ...]

Poses are paired by index, not by stamp: a rig frame is stamped by its earliest camera, so runs with different
camera subsets of one recording stamp the same frame differently (KITTI raw: by up to 10 ms). Each trajectory is in
the world frame of its own first pose (mcslam-run's), so no alignment is made. Prints each path length, and for
each EST against REF: the position difference (RMS, at the end), the end orientation difference, and the relative
pose differences over 1 and 10 frames (translation as a share of REF's motion over those frames).
"""
import math
import sys


def load(path):
    rows = [list(map(float, l.split())) for l in open(path) if l.strip() and not l.startswith('#')]
    return [(r[1:4], quat_to_matrix(*r[4:8])) for r in rows]


def quat_to_matrix(x, y, z, w):
    return [[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]]


def transpose(a):
    return [list(r) for r in zip(*a)]


def mul(a, b):
    return [[sum(a[i][k] * b[k][j] for k in range(3)) for j in range(3)] for i in range(3)]


def angle_deg(r):
    return math.degrees(math.acos(max(-1.0, min(1.0, (r[0][0] + r[1][1] + r[2][2] - 1) / 2))))


def relative(a, b):
    """a^-1 b as (translation, rotation)."""
    rt = transpose(a[1])
    d = [b[0][i] - a[0][i] for i in range(3)]
    return [sum(rt[i][k] * d[k] for k in range(3)) for i in range(3)], mul(rt, b[1])


def path_length(t):
    return sum(math.dist(t[i][0], t[i + 1][0]) for i in range(len(t) - 1))


def rms(v):
    return math.sqrt(sum(x * x for x in v) / len(v))


def relative_differences(ref, est, step):
    trans, rot = [], []
    for i in range(min(len(ref), len(est)) - step):
        ta, ra = relative(ref[i], ref[i + step])
        tb, rb = relative(est[i], est[i + step])
        trans.append(math.dist(ta, tb) / max(1e-9, math.hypot(*ta)) * 100)
        rot.append(angle_deg(mul(transpose(ra), rb)))
    return rms(trans), rms(rot)


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    names = sys.argv[1:]
    traj = {n: load(n) for n in names}
    for n in names:
        print(f'{n}: {len(traj[n])} poses, path {path_length(traj[n]):.3f} m')
    ref = traj[names[0]]
    for n in names[1:]:
        est = traj[n]
        m = min(len(ref), len(est))
        d = [math.dist(est[i][0], ref[i][0]) for i in range(m)]
        end_rot = angle_deg(mul(transpose(ref[m - 1][1]), est[m - 1][1]))
        t1, r1 = relative_differences(ref, est, 1)
        t10, r10 = relative_differences(ref, est, 10)
        print(f'{n} vs {names[0]}: position difference RMS {rms(d):.3f} m, end {d[-1]:.3f} m '
              f'({100 * d[-1] / path_length(ref[:m]):.2f}% of the path), end orientation {end_rot:.2f} deg; '
              f'relative over 1 frame {t1:.2f}% / {r1:.3f} deg, over 10 frames {t10:.2f}% / {r10:.3f} deg (RMS)')


if __name__ == '__main__':
    main()

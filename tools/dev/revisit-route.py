#!/usr/bin/env python3
"""A route that revisits itself, for place recognition and loop closure: the ground-truth loop of a rendered
dataset (TUM, closed), driven `--laps` times; every lap after the first is shifted sideways by `--offset` metres
and turned by `--yaw` degrees, so that a revisit is near but not on the first lap's poses. With --reverse the
second lap runs the loop the other way round (the rig turned by 180 degrees). Writes a TUM file for
`mcslam-sim --trajectory file:PATH`.

  tools/dev/revisit-route.py LOOP.txt OUT.txt [--laps 2] [--offset 0.3] [--yaw 10] [--reverse]
"""
import argparse
import math


def read_tum(path):
    rows = []
    for line in open(path):
        if line.strip() and not line.startswith('#'):
            rows.append([float(x) for x in line.split()])
    return rows


def quat_mul(a, b):  # (x, y, z, w)
    ax, ay, az, aw = a
    bx, by, bz, bw = b
    return (aw * bx + ax * bw + ay * bz - az * by, aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw, aw * bw - ax * bx - ay * by - az * bz)


def yaw_quat(deg):
    h = math.radians(deg) / 2
    return (0.0, 0.0, math.sin(h), math.cos(h))


def lateral(rows, i):
    """Unit vector to the left of the direction of travel at pose i (z up)."""
    j, k = max(i - 2, 0), min(i + 2, len(rows) - 1)
    dx, dy = rows[k][1] - rows[j][1], rows[k][2] - rows[j][2]
    n = math.hypot(dx, dy)
    return (0.0, 0.0) if n < 1e-6 else (-dy / n, dx / n)


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument('loop')
    p.add_argument('out')
    p.add_argument('--laps', type=int, default=2)
    p.add_argument('--offset', type=float, default=0.3)
    p.add_argument('--yaw', type=float, default=10.0)
    p.add_argument('--reverse', action='store_true')
    a = p.parse_args()
    loop = read_tum(a.loop)
    period = loop[1][0] - loop[0][0]
    duration = loop[-1][0] - loop[0][0] + period
    out = []
    for lap in range(a.laps):
        reverse = a.reverse and lap % 2 == 1
        order = list(reversed(range(len(loop)))) if reverse else list(range(len(loop)))
        for n, i in enumerate(order):
            t, x, y, z, qx, qy, qz, qw = loop[i]
            q = (qx, qy, qz, qw)
            if lap > 0:
                lx, ly = lateral(loop, i)
                x, y = x + a.offset * lx, y + a.offset * ly
                q = quat_mul(yaw_quat(a.yaw + (180.0 if reverse else 0.0)), q)
            out.append((loop[0][0] + lap * duration + n * period, x, y, z) + q)
    with open(a.out, 'w') as f:
        f.write('# t tx ty tz qx qy qz qw (revisit-route.py from %s, %d laps)\n' % (a.loop, a.laps))
        for r in out:
            f.write('%.6f %.6f %.6f %.6f %.9f %.9f %.9f %.9f\n' % r)


if __name__ == '__main__':
    main()

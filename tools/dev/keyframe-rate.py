#!/usr/bin/env python3
"""Keyframes per frame and per second of a run, over the whole run and in windows of its time, with the path the
estimate travelled in each window (BENCHMARKS.md, "Real recordings").

  tools/dev/keyframe-rate.py TRAJECTORY.tum KEYFRAMES.tum [WINDOW_S]     (mcslam-run --out, --keyframes)
"""
import collections
import math
import sys


def load(path):
    return [list(map(float, l.split())) for l in open(path) if l.strip() and not l.startswith('#')]


def main():
    if len(sys.argv) not in (3, 4):
        sys.exit(__doc__)
    frames, keyframes = load(sys.argv[1]), load(sys.argv[2])
    window = float(sys.argv[3]) if len(sys.argv) == 4 else 0
    t0 = frames[0][0]
    period = (frames[-1][0] - t0) / (len(frames) - 1)
    duration = len(frames) * period
    print(f'{len(frames)} frames, {len(keyframes)} keyframes: {len(keyframes) / len(frames):.3f} per frame, '
          f'{len(keyframes) / duration:.2f} per second')
    a = 0.0
    while window > 0 and any(f[0] - t0 >= a for f in frames):
        inside = [f for f in frames if a <= f[0] - t0 < a + window]
        n = sum(1 for k in keyframes if a <= k[0] - t0 < a + window)
        path = sum(math.dist(inside[i][1:4], inside[i + 1][1:4]) for i in range(len(inside) - 1))
        print(f'  {a:6.1f}-{a + window:6.1f} s: {n} keyframes of {len(inside)} frames '
              f'({n / max(1, len(inside)):.2f} per frame), path {path:.2f} m')
        a += window
    gaps = collections.Counter(round((keyframes[i + 1][0] - keyframes[i][0]) / period) for i in range(len(keyframes) - 1))
    print('frames between keyframes: ' + ', '.join(f'{g}: {gaps[g]}' for g in sorted(gaps)))


if __name__ == '__main__':
    main()

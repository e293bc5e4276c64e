"""Trajectory files for the evaluation scripts: TUM ('timestamp x y z qx qy qz qw', seconds) or EuRoC ground truth
(comma-separated, nanoseconds), comments and blank lines skipped."""
import sys

# What a line must hold, by how many values after the stamp are read.
_EXPECTED = {3: 'timestamp x y z ...', 7: 'timestamp x y z qx qy qz qw'}


def load_poses(path, values):
    """{stamp in seconds (rounded to the millisecond): the first `values` numbers after it}; exits naming the file,
    line and text of a line that does not hold them."""
    expected = _EXPECTED.get(values, f'timestamp and {values} values')
    poses = {}
    with open(path) as f:
        for n, line in enumerate(f, 1):
            if line.startswith('#') or not line.strip():
                continue
            v = line.replace(',', ' ').split()
            try:
                t = float(v[0])
                pose = tuple(float(x) for x in v[1:1 + values])
            except (ValueError, IndexError):
                pose = ()
            if len(pose) != values:
                sys.exit(f"{path}:{n}: expected '{expected}', got: {line.strip()[:60]}")
            if t > 1e12:  # nanoseconds (EuRoC)
                t *= 1e-9
            poses[round(t, 3)] = pose
    return poses

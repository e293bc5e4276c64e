#!/usr/bin/env python3
"""Receives mcslamd's UDP pose records and prints them.

Written from docs/pose-protocol.md alone, with the Python standard library only, to show that the
document is enough. Output lines match mcslam-udp-echo / mcslam-shm-echo:

  seq 12 frame 12 t 1403636579.763555584 state tracking valid 1 kf 0 unscaled 0 unanchored 0 world 3 quality 0.830
  p <x y z> q <x y z w>   (one line)

Usage: pose_client.py [--bind 0.0.0.0] [--port 9870] [--count N] [--timeout S]
"""
import argparse
import socket
import struct
import sys

# Section 1 of the document: 104 bytes, little-endian, no padding.
RECORD = struct.Struct("<4sHHQQqq3d4dBBHf")
MAGIC = b"MCSP"
VERSION = 1
SIZE = 104
TRACKING = {0: "not_initialized", 1: "tracking", 2: "lost", 3: "localizing"}
FLAG_VALID = 1
FLAG_KEYFRAME = 2
FLAG_UNSCALED = 4  # position in an arbitrary unit, not metres
FLAG_UNANCHORED = 8  # the pose's place in the world is a guess since an unbridged loss (docs/pose-protocol.md)
FLAG_ROUGHLY_METRIC = 16  # with FLAG_UNSCALED: metres, but from points too far for the cameras' baseline


def decode(data):
    """Returns a dict, or raises ValueError saying why the datagram is not a pose record."""
    if len(data) < SIZE:
        raise ValueError("too short (%d bytes)" % len(data))
    (magic, version, size, sequence, frame_sequence, capture_ns, publish_ns,
     px, py, pz, qx, qy, qz, qw, state, flags, world_revision, quality) = RECORD.unpack_from(data)
    if magic != MAGIC:
        raise ValueError("bad magic %r" % magic)
    if version != VERSION:
        raise ValueError("unsupported version %d" % version)
    if size < SIZE or size > len(data):
        raise ValueError("size field %d does not fit %d received bytes" % (size, len(data)))
    return {
        "sequence": sequence, "frame_sequence": frame_sequence,
        "capture_time_ns": capture_ns, "publish_time_ns": publish_ns,
        "position": (px, py, pz), "orientation": (qx, qy, qz, qw),
        "tracking": TRACKING.get(state, "unknown"),
        "valid": bool(flags & FLAG_VALID), "keyframe": bool(flags & FLAG_KEYFRAME),
        "unscaled": bool(flags & FLAG_UNSCALED), "unanchored": bool(flags & FLAG_UNANCHORED),
        "roughly_metric": bool(flags & FLAG_ROUGHLY_METRIC),
        "quality": quality, "world_revision": world_revision,
    }


REORDER_WINDOW = 64  # docs/pose-protocol.md, rules for readers, 4


def restarted(sequence, highest):
    """Whether a record comes from a new run of the daemon, which counts `sequence` from 1 again (rule 4)."""
    return highest is not None and (sequence == 1 or sequence + REORDER_WINDOW < highest)


def format_pose(p):
    t = p["capture_time_ns"]
    whole = abs(t) // 1000000000  # truncated toward zero, as C's integer division
    seconds = "%d.%09d" % (-whole if t < 0 else whole, abs(t) % 1000000000)
    return ("seq %d frame %d t %s state %s valid %d kf %d unscaled %d unanchored %d world %d quality %.3f p %s q %s" % (
        p["sequence"], p["frame_sequence"], seconds, p["tracking"], p["valid"], p["keyframe"], p["unscaled"],
        p["unanchored"], p["world_revision"], p["quality"],
        " ".join("%.17g" % v for v in p["position"]), " ".join("%.17g" % v for v in p["orientation"])))


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--bind", default="0.0.0.0", help="local address to listen on")
    ap.add_argument("--port", type=int, default=9870, help="UDP port (publish.udp.destinations)")
    ap.add_argument("--count", type=int, default=0, help="exit after this many poses (0 = forever)")
    ap.add_argument("--timeout", type=float, default=0, help="exit 1 when nothing arrives for this long")
    args = ap.parse_args()

    sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    sock.bind((args.bind, args.port))
    if args.timeout > 0:
        sock.settimeout(args.timeout)
    print("listening on %s:%d" % sock.getsockname(), file=sys.stderr, flush=True)
    printed = 0
    highest = None
    while args.count == 0 or printed < args.count:
        try:
            data = sock.recv(2048)
        except socket.timeout:
            print("pose_client: nothing received for %.1f s" % args.timeout, file=sys.stderr)
            return 1
        try:
            pose = decode(data)
        except ValueError as e:
            print("pose_client: ignored a datagram: %s" % e, file=sys.stderr)
            continue
        if restarted(pose["sequence"], highest):
            print("pose_client: the daemon restarted (sequence %d after %d)" % (pose["sequence"], highest),
                  file=sys.stderr, flush=True)
            highest = None
        highest = pose["sequence"] if highest is None else max(highest, pose["sequence"])
        print(format_pose(pose), flush=True)
        printed += 1
    return 0


if __name__ == "__main__":
    sys.exit(main())

#!/usr/bin/env python3
"""Resident memory of mcslamd over a long run, and whether it stays flat.

Runs mcslamd on a replay (a dataset folder you give, or a synthetic 5-camera ASL dataset made here with
the standard library) until N poses were published, sampling VmRSS from /proc/<pid>/status and the
publish count from the shared-memory header (docs/pose-protocol.md: u64 `published` at offset 48).
Prints the samples and a summary: RSS after warm-up, at the end, the maximum, and the growth between.

  tools/mcslamd/measure_rss.py --mcslamd build/bin/mcslamd [--dataset DIR] [--frames 10000]
                               [--rate fastest|recorded] [--interval 1.0] [--breakdown]

--breakdown: before stopping, split the resident set from /proc/<pid>/status and /proc/<pid>/smaps
(anonymous vs file-backed, the largest mappings, the shared libraries' share).
"""
import argparse
import mmap
import os
import random
import shutil
import signal
import struct
import subprocess
import sys
import tempfile
import time
import zlib

HERE = os.path.dirname(os.path.abspath(__file__))
CALIB_5CAM = os.path.join(HERE, "..", "..", "tests", "data", "calib", "isec_5cam_camchain.yaml")


def write_png(path, width, height, pixels):
    """8-bit greyscale PNG (no filter), standard library only."""
    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)
    raw = b"".join(b"\x00" + pixels[y * width:(y + 1) * width] for y in range(height))
    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 0, 0, 0, 0)) +
                chunk(b"IDAT", zlib.compress(raw, 1)) + chunk(b"IEND", b""))


def make_dataset(root, frames=20, width=720, height=540, cameras=5):
    """An ASL folder: camchain.yaml (the 5-camera ISEC rig of tests/data), camN/data.csv, camN/data/<ns>.png."""
    shutil.copy(CALIB_5CAM, os.path.join(root, "camchain.yaml"))
    rng = random.Random(5)
    for c in range(cameras):
        os.makedirs(os.path.join(root, "cam%d" % c, "data"))
        with open(os.path.join(root, "cam%d" % c, "data.csv"), "w") as csv:
            csv.write("#timestamp [ns],filename\n")
            for f in range(frames):
                t = 1000000000000 + f * 50000000
                # Blocky random texture: cheap to make, has corners for a feature detector.
                bw, bh = (width + 7) // 8, (height + 7) // 8
                blocks = bytes(rng.randrange(256) for _ in range(bw * bh))
                rows = []
                for y in range(height):
                    row = bytes(blocks[(y // 8) * bw + x // 8] for x in range(width))
                    rows.append(row)
                write_png(os.path.join(root, "cam%d" % c, "data", "%d.png" % t), width, height, b"".join(rows))
                csv.write("%d,%d.png\n" % (t, t))


def rss_kb(pid):
    with open("/proc/%d/status" % pid) as f:
        for line in f:
            if line.startswith("VmRSS:"):
                return int(line.split()[1])
    return 0


def breakdown(pid, top=12):
    """Resident set by mapping from /proc/<pid>/smaps: what is anonymous (heap, mmap'ed buffers, thread
    stacks, libraries' relocated data) and what is file-backed (library and executable pages)."""
    with open("/proc/%d/status" % pid) as f:
        status = {l.split(":")[0]: l.split(":")[1].strip() for l in f if l.startswith(("VmRSS", "RssAnon", "RssFile"))}
    print("breakdown: VmRSS %s, RssAnon %s, RssFile %s" % (status.get("VmRSS"), status.get("RssAnon"), status.get("RssFile")))
    by_name, name, libs = {}, None, set()
    with open("/proc/%d/smaps" % pid) as f:
        for line in f:
            head = line.split()
            if head and "-" in head[0] and len(head) >= 5 and all(c in "0123456789abcdef-" for c in head[0]):
                name = head[5] if len(head) > 5 else "[anonymous mmap]"
                if name.startswith("/") and ".so" in name:
                    libs.add(name)
            elif line.startswith("Rss:"):
                by_name[name] = by_name.get(name, 0) + int(head[1])
    lib_kb = sum(v for k, v in by_name.items() if k in libs)
    print("  %d shared libraries mapped, %.1f MB resident (text, data and their relocated pages)"
          % (len(libs), lib_kb / 1024.0))
    # Loaded only when the replay meets a PNG or JPEG (the image codec module; binary PGM needs none).
    codec = sorted(os.path.basename(l) for l in libs if "imgcodecs" in l or "mcslam_image_codec" in l)
    print("  image codec: %s" % (", ".join(codec) if codec else "not mapped"))
    for k, v in sorted(by_name.items(), key=lambda kv: -kv[1])[:top]:
        print("  %8.1f MB  %s" % (v / 1024.0, k))


def published(shm_name):
    try:
        with open("/dev/shm" + shm_name, "rb") as f:
            with mmap.mmap(f.fileno(), 0, prot=mmap.PROT_READ) as m:
                return struct.unpack_from("<Q", m, 48)[0]
    except (OSError, ValueError):
        return 0


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--mcslamd", required=True)
    ap.add_argument("--dataset", help="dataset folder (default: a synthetic 5-camera one)")
    ap.add_argument("--frames", type=int, default=10000)
    ap.add_argument("--rate", default="fastest", choices=["fastest", "recorded"])
    ap.add_argument("--interval", type=float, default=1.0)
    ap.add_argument("--warmup-frames", type=int, default=1000, help="frames before the 'after warm-up' sample")
    ap.add_argument("--slam", default="{}", help="the slam: section (YAML flow text)")
    ap.add_argument("--breakdown", action="store_true", help="print where the resident set is before stopping")
    args = ap.parse_args()

    work = tempfile.mkdtemp(prefix="mcslamd-rss-")
    try:
        data = args.dataset
        if not data:
            data = os.path.join(work, "data")
            os.makedirs(data)
            print("making a synthetic 5-camera dataset in %s ..." % data, file=sys.stderr, flush=True)
            make_dataset(data)
        shm = "/mcslam-rss-%d" % os.getpid()
        config = os.path.join(work, "mcslamd.yaml")
        with open(config, "w") as f:
            f.write("log_level: info\nsource:\n  type: dataset\n  dataset:\n    path: %s\n    rate: %s\n"
                    "    at_end: loop\nstatus_interval_s: 5\npublish:\n  shm:\n    name: %s\noutput:\n  directory: %s\nslam: %s\n"
                    % (data, args.rate, shm, work, args.slam))
        log_path = os.path.join(work, "mcslamd.log")
        log = open(log_path, "w")
        proc = subprocess.Popen([args.mcslamd, "--config", config], stdout=log, stderr=subprocess.STDOUT)
        samples = []
        start = time.time()
        while True:
            time.sleep(args.interval)
            if proc.poll() is not None:
                print("mcslamd exited early with status %d" % proc.returncode, file=sys.stderr)
                return 1
            n, kb = published(shm), rss_kb(proc.pid)
            samples.append((time.time() - start, n, kb))
            print("%8.1f s  %7d poses  VmRSS %8.1f MB" % (samples[-1][0], n, kb / 1024.0), flush=True)
            if n >= args.frames:
                break
        if args.breakdown:
            breakdown(proc.pid)
        proc.send_signal(signal.SIGTERM)
        proc.wait(timeout=30)
        log.close()
        with open(log_path) as f:  # the daemon's totals at stop (allocations after warm-up included)
            lines = f.read().splitlines()
        print("tracking lost %d times; last status: %s" % (
            sum("tracking lost" in l for l in lines), next((l for l in reversed(lines) if "allocs/frame" in l), "-")))
        for line in lines:
            if "stopped:" in line:
                print(line)
        after = [s for s in samples if s[1] >= args.warmup_frames] or samples
        first, last = after[0], samples[-1]
        peak = max(s[2] for s in samples)
        print("\nsummary: %d poses in %.0f s; VmRSS after %d poses %.1f MB, at the end %.1f MB, max %.1f MB, "
              "growth after warm-up %+.1f MB; mcslamd exit status %d"
              % (last[1], last[0], first[1], first[2] / 1024.0, last[2] / 1024.0, peak / 1024.0,
                 (last[2] - first[2]) / 1024.0, proc.returncode))
        return 0
    finally:
        shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    sys.exit(main())

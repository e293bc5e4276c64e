#!/usr/bin/env python3
"""Camera-configuration study: runs mcslam-run on datasets for several camera subsets and tabulates
the accuracy (ATE, evo conventions through mcslam-eval) and the cost, like the paper's Table II.

  tools/study/camera_study.py --dataset DIR [--dataset DIR2 ...] \
      --config "5 OV=0,1,2,3,4" --config "stereo=1,2" --config "mono=2:sim3" [--slam-config FILE] --out OUT

Each --config is NAME=CAMERAS[:ALIGN]; ALIGN is se3 (default) or sim3 (one camera: scale is arbitrary).
For every configuration the Sim(3) scale is also reported (1.0 = metric). Writes OUT/study.md (a
Markdown table), OUT/study.json and, per run, the trajectory, the stats and a top-view plot.
"""
import argparse
import json
import os
import subprocess
import sys


def parse_config(text):
    if "=" not in text:
        sys.exit(f"camera_study: --config '{text}': expected NAME=CAMERAS[:ALIGN], e.g. 'stereo=1,2'")
    name, rest = text.split("=", 1)
    cams, align = (rest.split(":", 1) + ["se3"])[:2]
    if align not in ("se3", "sim3"):
        sys.exit(f"camera_study: --config '{text}': alignment must be se3 or sim3, got '{align}'")
    return name.strip(), cams.strip(), align


def run(cmd):
    result = subprocess.run(cmd, capture_output=True, text=True)
    if result.returncode != 0:
        sys.exit(f"camera_study: {' '.join(cmd)} failed (exit {result.returncode}):\n{result.stderr}")
    return result.stdout


def evaluate(bin_dir, dataset, traj, align, plot=None):
    cmd = [os.path.join(bin_dir, "mcslam-eval"), "ape", dataset, traj, "--align", align, "--json"]
    if plot:
        cmd += ["--plot", plot]
    return json.loads(run(cmd))


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--dataset", action="append", required=True, help="dataset folder (repeatable)")
    ap.add_argument("--config", action="append", required=True, help="NAME=CAMERAS[:ALIGN] (repeatable)")
    ap.add_argument("--slam-config", help="YAML with a slam: section passed to mcslam-run --config")
    ap.add_argument("--bin", default=os.path.join(here, "..", "..", "build", "bin"), help="folder of the executables")
    ap.add_argument("--out", default="study_out", help="output folder")
    args = ap.parse_args()

    configs = [parse_config(c) for c in args.config]
    os.makedirs(args.out, exist_ok=True)
    rows = []
    for dataset in args.dataset:
        seq = os.path.basename(os.path.normpath(dataset))
        for name, cams, align in configs:
            tag = f"{seq}_{name}".replace(" ", "_").replace("/", "_")
            traj = os.path.join(args.out, tag + ".tum")
            stats_path = os.path.join(args.out, tag + "_stats.json")
            cmd = [os.path.join(args.bin, "mcslam-run"), "--dataset", dataset, "--cameras", cams, "--out", traj,
                   "--stats", stats_path, "--quiet"]
            if args.slam_config:
                cmd += ["--config", args.slam_config]
            print(f"camera_study: {seq} / {name} (cameras {cams}) ...", file=sys.stderr, flush=True)
            run(cmd)
            with open(stats_path) as f:
                stats = json.load(f)
            ape = evaluate(args.bin, dataset, traj, align, os.path.join(args.out, tag + ".png"))
            scale = evaluate(args.bin, dataset, traj, "sim3")["scale"]
            states = stats["tracking_states"]
            rows.append({
                "sequence": seq, "config": name, "cameras": cams, "align": align,
                "ate_m": ape["rmse"], "ate_percent": ape["rmse_percent"], "path_m": ape["path_length"],
                "sim3_scale": scale, "frames": stats["frames"], "tracking": states["tracking"],
                "lost": states["lost"], "not_initialized": states["not_initialized"],
                "keyframes": stats["keyframes"], "ms_mean": stats["timing_ms"]["total"]["mean"],
                "ms_p99": stats["timing_ms"]["total"]["p99"],
                # poses whose unit is not metres: one camera, or a rig without overlap before its scale is found
                "unscaled": stats.get("scale", {}).get("frames_unknown_scale", 0),
            })
            r = rows[-1]
            print(f"  ATE {r['ate_m']:.4f} m ({r['ate_percent']:.3f} %), scale {r['sim3_scale']:.4f}, "
                  f"lost {r['lost']}, {r['ms_mean']:.1f} ms/frame", file=sys.stderr, flush=True)

    with open(os.path.join(args.out, "study.json"), "w") as f:
        json.dump(rows, f, indent=2)
    lines = ["| sequence | configuration | cameras | ATE (m) | ATE (% of path) | path (m) | Sim(3) scale | "
             "frames tracked / lost / before init | poses up to scale | keyframes | ms per frame (mean / p99) |",
             "|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        ate = f"{r['ate_m']:.4f}" + (" (Sim3)" if r["align"] == "sim3" else "")
        lines.append(f"| {r['sequence']} | {r['config']} | {r['cameras']} | {ate} | {r['ate_percent']:.3f} | "
                     f"{r['path_m']:.1f} | {r['sim3_scale']:.4f} | {r['tracking']} / {r['lost']} / "
                     f"{r['not_initialized']} | {r['unscaled']} | {r['keyframes']} | {r['ms_mean']:.1f} / "
                     f"{r['ms_p99']:.1f} |")
    table = "\n".join(lines) + "\n"
    with open(os.path.join(args.out, "study.md"), "w") as f:
        f.write(table)
    print(table)


if __name__ == "__main__":
    main()

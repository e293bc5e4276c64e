#!/usr/bin/env python3
"""Camera-configuration study: runs mcslam-run on datasets for several camera subsets and tabulates
the accuracy (ATE, evo conventions through mcslam-eval) and the cost, like the paper's Table II.

  tools/study/camera_study.py --dataset DIR [--dataset DIR2 ...] \
      --config "5 OV=0,1,2,3,4" --config "stereo=1,2" --config "mono=2:sim3" [--slam-config FILE] --out OUT

Each --config is NAME=CAMERAS[:ALIGN]; ALIGN is se3 (default) or sim3 (one camera: scale is arbitrary).
For every configuration the Sim(3) scale is also reported (1.0 = metric). The ATE is that of every frame's pose
as it was published (a loop closure's correction makes the poses after it jump); "keyframes ATE" is that of the
final, loop-corrected keyframe trajectory (mcslam-run --keyframes), under the same alignment. Writes OUT/study.md
(a Markdown table), OUT/study.json and, per run, the trajectories, the stats and a top-view plot.

--repeats N runs every configuration N times with the feature capacity per camera spread evenly over +-5% of
the configured one (N = 7 at 1000: 950, 967, ..., 1050) and reports the mean ATE with its range. One run cannot
rank two configurations: a change of 1-5% in the feature count moves a run's ATE by up to +-30% (BENCHMARKS.md).
"""
import argparse
import json
import os
import re
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


def feature_counts(base, repeats):
    """Feature capacities of the repeats: evenly over +-5% of base, base itself when one."""
    if repeats == 1:
        return [base]
    return [round(base * (0.95 + 0.1 * i / (repeats - 1))) for i in range(repeats)]


# The feature capacity line of a printed configuration; its digits are what the repeats change.
FEATURES_LINE = re.compile(r"(?m)^(\s*max_features_per_camera:\s*)(\d+)")


def effective_config(bin_dir, dataset, cams, slam_config):
    """The run's effective configuration (mcslam-run --print-config): the user's file or the defaults, for this
    rig. The repeats write it back with only the feature capacity changed."""
    cmd = [os.path.join(bin_dir, "mcslam-run"), "--dataset", dataset, "--cameras", cams, "--print-config"]
    if slam_config:
        cmd += ["--config", slam_config]
    text = run(cmd)
    n = len(FEATURES_LINE.findall(text))
    if n != 1:
        sys.exit(f"camera_study: {' '.join(cmd)}: expected one max_features_per_camera line, found {n}")
    return text


def write_variant(config_text, features, path):
    with open(path, "w") as f:
        f.write(FEATURES_LINE.sub(rf"\g<1>{features}", config_text))
    return path


def evaluate(bin_dir, dataset, traj, align, plot=None):
    cmd = [os.path.join(bin_dir, "mcslam-eval"), "ape", dataset, traj, "--align", align, "--json"]
    if plot:
        cmd += ["--plot", plot]
    return json.loads(run(cmd))


def run_once(args, dataset, seq, name, cams, align, features, repeats, config_text):
    """One mcslam-run and its evaluation: a row of the study. config_text: the effective configuration, for
    the repeats (None for a single run)."""
    tag = f"{seq}_{name}".replace(" ", "_").replace("/", "_") + (f"_f{features}" if repeats > 1 else "")
    traj = os.path.join(args.out, tag + ".tum")
    keyframes = os.path.join(args.out, tag + "_keyframes.tum")
    stats_path = os.path.join(args.out, tag + "_stats.json")
    cmd = [os.path.join(args.bin, "mcslam-run"), "--dataset", dataset, "--cameras", cams, "--out", traj,
           "--keyframes", keyframes, "--stats", stats_path, "--quiet"]
    if repeats > 1:
        cmd += ["--config", write_variant(config_text, features, os.path.join(args.out, tag + ".yaml"))]
    elif args.slam_config:
        cmd += ["--config", args.slam_config]
    print(f"camera_study: {seq} / {name} (cameras {cams}"
          + (f", {features} features per camera" if repeats > 1 else "") + ") ...", file=sys.stderr, flush=True)
    run(cmd)
    with open(stats_path) as f:
        stats = json.load(f)
    ape = evaluate(args.bin, dataset, traj, align, os.path.join(args.out, tag + ".png"))
    scale = evaluate(args.bin, dataset, traj, "sim3")["scale"]
    keyframes_ate = evaluate(args.bin, dataset, keyframes, align)["rmse"]
    states = stats["tracking_states"]
    r = {
        "sequence": seq, "config": name, "cameras": cams, "align": align, "features_per_camera": features,
        "ate_m": ape["rmse"], "ate_percent": ape["rmse_percent"], "path_m": ape["path_length"],
        "keyframes_ate_m": keyframes_ate, "loop_closures": stats.get("places", {}).get("loop_closures", 0),
        "sim3_scale": scale, "frames": stats["frames"], "tracking": states["tracking"],
        "lost": states["lost"], "not_initialized": states["not_initialized"],
        "keyframes": stats["keyframes"], "ms_mean": stats["timing_ms"]["total"]["mean"],
        "ms_p99": stats["timing_ms"]["total"]["p99"],
        # poses whose unit is not metres: one camera, or a rig without overlap before its scale is found
        "unscaled": stats.get("scale", {}).get("frames_unknown_scale", 0),
    }
    print(f"  ATE {r['ate_m']:.4f} m ({r['ate_percent']:.3f} %), keyframes {r['keyframes_ate_m']:.4f} m, "
          f"scale {r['sim3_scale']:.4f}, {r['loop_closures']} loop closures, lost {r['lost']}, "
          f"{r['ms_mean']:.1f} ms/frame", file=sys.stderr, flush=True)
    return r


def table_single(rows):
    lines = ["| sequence | configuration | cameras | ATE (m) | ATE (% of path) | path (m) | keyframes ATE (m), "
             "loop closures | Sim(3) scale | frames tracked / lost / before init | poses up to scale | keyframes | "
             "ms per frame (mean / p99) |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        ate = f"{r['ate_m']:.4f}" + (" (Sim3)" if r["align"] == "sim3" else "")
        lines.append(f"| {r['sequence']} | {r['config']} | {r['cameras']} | {ate} | {r['ate_percent']:.3f} | "
                     f"{r['path_m']:.1f} | {r['keyframes_ate_m']:.4f}, {r['loop_closures']} | "
                     f"{r['sim3_scale']:.4f} | {r['tracking']} / {r['lost']} / "
                     f"{r['not_initialized']} | {r['unscaled']} | {r['keyframes']} | {r['ms_mean']:.1f} / "
                     f"{r['ms_p99']:.1f} |")
    return lines


def table_repeated(groups):
    """One line per configuration: means over its repeats, with the range where a single run would mislead."""
    lines = ["| sequence | configuration | cameras | runs (features per camera) | ATE (m), mean (min-max) | "
             "ATE (% of path), mean | keyframes ATE (m), mean (min-max); runs with a loop closure | "
             "Sim(3) scale, mean (min-max) | frames lost, all runs | poses up to scale, mean | keyframes, mean | "
             "ms per frame, mean |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for g in groups:
        n = len(g)
        mean = lambda key: sum(r[key] for r in g) / n
        ates = [r["ate_m"] for r in g]
        scales = [r["sim3_scale"] for r in g]
        keyframe_ates = [r["keyframes_ate_m"] for r in g]
        closed = sum(1 for r in g if r["loop_closures"] > 0)
        r0 = g[0]
        lines.append(f"| {r0['sequence']} | {r0['config']} | {r0['cameras']} | {n} ({g[0]['features_per_camera']}-"
                     f"{g[-1]['features_per_camera']}) | {mean('ate_m'):.4f} ({min(ates):.4f}-{max(ates):.4f})"
                     + (" (Sim3)" if r0["align"] == "sim3" else "")
                     + f" | {mean('ate_percent'):.3f} | {mean('keyframes_ate_m'):.4f} ({min(keyframe_ates):.4f}-"
                     f"{max(keyframe_ates):.4f}); {closed} | {mean('sim3_scale'):.4f} ({min(scales):.4f}-{max(scales):.4f})"
                     f" | {sum(r['lost'] for r in g)} | {mean('unscaled'):.0f} | {mean('keyframes'):.0f} | "
                     f"{mean('ms_mean'):.1f} |")
    return lines


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--dataset", action="append", required=True, help="dataset folder (repeatable)")
    ap.add_argument("--config", action="append", required=True, help="NAME=CAMERAS[:ALIGN] (repeatable)")
    ap.add_argument("--slam-config", help="YAML with a slam: section passed to mcslam-run --config")
    ap.add_argument("--repeats", type=int, default=1,
                    help="runs per configuration, feature capacity spread over +-5%% (default 1)")
    ap.add_argument("--bin", default=os.path.join(here, "..", "..", "build", "bin"), help="folder of the executables")
    ap.add_argument("--out", default="study_out", help="output folder")
    args = ap.parse_args()
    if args.repeats < 1:
        sys.exit(f"camera_study: --repeats {args.repeats}: expected 1 or more")

    configs = [parse_config(c) for c in args.config]
    os.makedirs(args.out, exist_ok=True)
    rows, groups = [], []
    for dataset in args.dataset:
        seq = os.path.basename(os.path.normpath(dataset))
        for name, cams, align in configs:
            text = effective_config(args.bin, dataset, cams, args.slam_config) if args.repeats > 1 else None
            base = int(FEATURES_LINE.search(text).group(2)) if text else None
            group = [run_once(args, dataset, seq, name, cams, align, features, args.repeats, text)
                     for features in feature_counts(base, args.repeats)]
            rows += group
            groups.append(group)

    with open(os.path.join(args.out, "study.json"), "w") as f:
        json.dump(rows, f, indent=2)
    lines = table_single(rows) if args.repeats == 1 else table_repeated(groups)
    table = "\n".join(lines) + "\n"
    with open(os.path.join(args.out, "study.md"), "w") as f:
        f.write(table)
    print(table)


if __name__ == "__main__":
    main()

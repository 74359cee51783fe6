#!/usr/bin/python3
"""Checks --target-psnr and --budget on the tracer's scenes (docs/QUALITY.md).

For each scene: the full render (the reference), a sweep of global contrast
thresholds (the frontier a user could reach knowing the best threshold), one
run with --target-psnr T and one with --budget B (B: the exact fraction the
best single threshold needs for T). Prints a Markdown table.

The rays column is the cost that includes what no exact-pixel count shows
(a goal judged by the tracer's preview traces every pixel with a few rays):
the target run's rays and the best threshold's, as shares of the full
render's.

usage: scripts/quality_check.py DCM OUTDIR [--size 256] [--supersampling 1] [--target 40]
                                [--scenes room,mirror,...] [--extra=--estimate-from=validation]
                                [--scene NAME=PATH ...] [--common=--set=render.shadow_rays=64 ...]
"""
import argparse
import json
import math
import os
import subprocess
import sys

COARSE = [1.0, 0.78, 0.6, 0.45, 0.34, 0.26, 0.2, 0.15, 0.11, 0.08, 0.06, 0.045, 0.034, 0.025, 0.019, 0.014, 0.01]
# With the geometric midpoints (steps of about x0.87): the PSNR jumps by up to
# 5 dB between two neighbouring thresholds where a feature's block is refined
# or not, and a sweep must place that cliff before it can judge a budget by it.
THRESHOLDS = sorted(set(COARSE) | {float(f"{math.sqrt(a * b):.3g}") for a, b in zip(COARSE, COARSE[1:])}, reverse=True)
SCENES = {
    "room": "examples/scenes/room.json",
    "room-paper": "examples/scenes/room-paper.json",
    "cactus": "examples/scenes/cactus/cactus.json",
    "parquet": "examples/scenes/parquet.json",
    "mirror": "examples/scenes/mirror.json",
}


def render(dcm, scene, out, common, extra, reuse=False):
    """One `dcm render`; its --stats. `reuse`: an existing result (the full
    render, the sweep: they do not depend on the quality loop) is read back."""
    stats = out + ".json"
    if reuse and os.path.exists(stats) and os.path.exists(out + ".exr"):
        with open(stats) as f:
            return json.load(f)
    cmd = [dcm, "render", scene, "-o", out + ".exr", "--stats", stats, "-q"] + common + extra
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
    with open(stats) as f:
        return json.load(f)


def db(v):
    """A PSNR as the table shows it (JSON null: +infinity)."""
    return "∞" if v is None else f"{v:.2f}"


def best_within(sweep, fraction):
    """The best PSNR of the sweep's runs that spent at most `fraction`: what
    a user who knew the best single threshold for that budget would get."""
    within = [s["reference"]["psnr"] for s in sweep if s["exact_fraction"] <= fraction]
    return max(within) if within else float("nan")


def at_fraction(sweep, fraction):
    """The sweep's PSNR at `fraction`, interpolated in log fraction."""
    pts = sorted((s["exact_fraction"], s["reference"]["psnr"]) for s in sweep)
    if fraction <= pts[0][0]:
        return pts[0][1]
    for (f0, p0), (f1, p1) in zip(pts, pts[1:]):
        if f0 <= fraction <= f1:
            if f1 == f0:
                return max(p0, p1)
            u = (math.log(fraction) - math.log(f0)) / (math.log(f1) - math.log(f0))
            return p0 + u * (p1 - p0)
    return pts[-1][1]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("dcm")
    ap.add_argument("outdir")
    ap.add_argument("--size", type=int, default=256)
    ap.add_argument("--supersampling", type=int, default=1)
    ap.add_argument("--target", type=float, default=40.0)
    ap.add_argument("--scenes", default=",".join(SCENES))
    ap.add_argument("--extra", action="append", default=[], help="a flag for the target and budget runs")
    ap.add_argument("--scene", action="append", default=[], help="NAME=PATH: another scene (then --scenes "
                    "defaults to these)")
    ap.add_argument("--common", action="append", default=[], help="a flag for every run (the sweep too)")
    a = ap.parse_args()
    os.makedirs(a.outdir, exist_ok=True)
    scenes = dict(SCENES)
    for e in a.scene:
        name, path = e.split("=", 1)
        scenes[name] = path
    names = a.scenes if a.scenes != ",".join(SCENES) or not a.scene else ",".join(e.split("=")[0] for e in a.scene)
    common = ["--size", f"{a.size}x{a.size}", "--supersampling", str(a.supersampling)] + a.common
    print(f"size {a.size}², supersampling {a.supersampling}, target {a.target:g} dB\n")
    print("| scene | target | estimate [90 % interval] | true PSNR | exact | best threshold: exact (thr) | ratio "
          "| budget | true PSNR at budget | best threshold within that fraction (sweep interpolated) | exact at budget "
          "| rays: target, best threshold (of the full render's) |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    for name in names.split(","):
        scene = scenes[name]
        base = os.path.join(a.outdir, f"{name}_{a.size}_{a.supersampling}")
        ref = base + "_full"
        full = render(a.dcm, scene, ref, common, ["--full"], reuse=True)
        rays = lambda s: f"{100 * s['rays']['total'] / full['rays']['total']:.1f} %"
        cmp_ = ["--compare", ref + ".exr"]
        sweep = []
        for t in THRESHOLDS:
            s = render(a.dcm, scene, f"{base}_t{t:g}", common, cmp_ + ["--threshold", f"{t:g}"], reuse=True)
            s["threshold"] = t
            sweep.append(s)
        meeting = [s for s in sweep if s["reference"]["psnr"] >= a.target]
        best = min(meeting, key=lambda s: s["exact_fraction"]) if meeting else None
        q = render(a.dcm, scene, f"{base}_target", common, cmp_ + ["--target-psnr", f"{a.target:g}"] + a.extra)
        line = (f"| {name} | {a.target:g} | {db(q['estimated_psnr'])} [{db(q['estimated_psnr_low'])}, "
                f"{db(q['estimated_psnr_high'])}] | {db(q['reference']['psnr'])} | {100 * q['exact_fraction']:.2f} % | ")
        if best:
            budget = round(best["exact_fraction"], 4)
            line += (f"{100 * best['exact_fraction']:.2f} % ({best['threshold']:g}) | "
                     f"{q['exact_fraction'] / best['exact_fraction']:.2f} | {100 * budget:.2f} % | ")
            try:
                b = render(a.dcm, scene, f"{base}_budget", common, cmp_ + ["--budget", f"{budget:g}"] + a.extra)
                line += (f"{b['reference']['psnr']:.2f} | {best_within(sweep, b['exact_fraction']):.2f} "
                         f"({at_fraction(sweep, b['exact_fraction']):.2f}) | {100 * b['exact_fraction']:.2f} % | ")
            except subprocess.CalledProcessError:
                # A budget below what the coarsest reconstruction needs is an
                # error naming --budget (docs/QUALITY.md): say so, go on.
                line += "refused (below the coarsest reconstruction) | | | "
            line += f"{rays(q)}, {rays(best)} |"
        else:
            line += f"none reaches it | | | | | | {rays(q)} |"
        print(line)
        sys.stdout.flush()


if __name__ == "__main__":
    main()

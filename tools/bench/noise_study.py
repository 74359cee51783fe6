#!/usr/bin/python3
"""Noisy exact samples (issue #8): path-traced renders of the bundled scenes at
a few samples per pixel, reconstructed by dcm, against a converged render.

For each scene: a reference at --ref-spp, then for each spp of --spp: the full
noisy render, dcm (noise-aware, the default), dcm with the noise taken at face
value (--noise-significance 0) and the paper's method as written
(--method paper, which ignores the noise). Writes a Markdown table and plots.

  /usr/bin/python3 tools/bench/noise_study.py --dcm build/tools/dcm/dcm \
      --out out/noise --md docs/NOISE-TABLE.md --plots docs/img
"""
import argparse
import json
import os
import platform
import subprocess
import sys
import time

# A path tracer in the scene's terms: one ray per effect per estimate.
PATH_TRACED = [
    "render.shadow_rays=1", "render.secondary_shadow_rays=1", "render.glossy_rays=1",
    'render.indirect={"bounces": 2, "rays": 1}',
]
METHODS = [
    ("full", ["--full"]),
    ("dcm", []),
    ("dcm, noise ignored", ["--noise-significance", "0"]),
    ("paper", ["--method", "paper"]),
]


def render(dcm, scene, out, spp, seed, size, extra, compare=None):
    cmd = [dcm, "render", scene, "-o", out + ".exr", "--stats", out + ".json", "--quiet",
           "--size", size, "--supersampling", "1", "--spp", str(spp), "--seed", str(seed)]
    for s in PATH_TRACED:
        cmd += ["--set", s]
    cmd += extra
    if compare:
        cmd += ["--compare", compare, "--sample-map", out + "_samples.png"]
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
    return json.load(open(out + ".json"))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--dcm", required=True)
    ap.add_argument("--out", default="out/noise")
    ap.add_argument("--scenes", default="room,parquet,mirror,cactus/cactus")
    ap.add_argument("--spp", default="16,64,256")
    ap.add_argument("--ref-spp", type=int, default=2048)
    ap.add_argument("--size", default="256x256")
    ap.add_argument("--md", help="write the Markdown table here")
    ap.add_argument("--plots", help="write PNG plots into this folder")
    a = ap.parse_args()
    here = os.path.dirname(os.path.abspath(__file__))
    scenes_dir = os.path.join(here, "..", "..", "examples", "scenes")
    os.makedirs(a.out, exist_ok=True)
    spps = [int(s) for s in a.spp.split(",")]
    rows = []
    t0 = time.time()
    for scene in a.scenes.split(","):
        name = os.path.basename(scene)
        path = os.path.join(scenes_dir, scene + ".json")
        ref = os.path.join(a.out, f"{name}_ref")
        print(f"{name}: reference at {a.ref_spp} spp", file=sys.stderr)
        render(a.dcm, path, ref, a.ref_spp, 1, a.size, ["--full"])
        for spp in spps:
            for label, extra in METHODS:
                print(f"{name}: {spp} spp, {label}", file=sys.stderr)
                tag = label.split(",")[0].replace(" ", "") + ("-raw" if "ignored" in label else "")
                s = render(a.dcm, path, os.path.join(a.out, f"{name}_{spp}_{tag}"), spp, 7, a.size, extra,
                           compare=ref + ".exr")
                rows.append({"scene": name, "spp": spp, "method": label, "exact": s["exact_fraction"],
                             "psnr": s["reference"]["psnr"], "relmse": s["reference"]["relmse"],
                             "time": s["time_wall_s"]})
    elapsed = time.time() - t0

    lines = [f"Path-traced at {a.size} (1 shadow, glossy and indirect ray per estimate, 2 bounces), "
             f"reference {a.ref_spp} spp (other seed); {platform.node()}, {os.cpu_count()} cores; "
             f"study took {elapsed:.0f} s.", "",
             "| scene | spp | method | exact % | PSNR dB | relMSE | time s | vs full noisy |",
             "|---|---|---|---|---|---|---|---|"]
    for r in rows:
        full = next(f for f in rows if f["scene"] == r["scene"] and f["spp"] == r["spp"] and f["method"] == "full")
        lines.append(f"| {r['scene']} | {r['spp']} | {r['method']} | {100 * r['exact']:.1f} | {r['psnr']:.2f} | "
                     f"{r['relmse']:.2e} | {r['time']:.2f} | {r['psnr'] - full['psnr']:+.2f} dB |")
    text = "\n".join(lines) + "\n"
    print(text)
    if a.md:
        with open(a.md + ".tmp", "w") as f:
            f.write(text)
        os.replace(a.md + ".tmp", a.md)
    if a.plots:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        scenes = sorted({r["scene"] for r in rows}, key=[r["scene"] for r in rows].index)
        fig, axes = plt.subplots(2, len(scenes), figsize=(4 * len(scenes), 7), squeeze=False)
        for i, sc in enumerate(scenes):
            for label, _ in METHODS:
                pts = [r for r in rows if r["scene"] == sc and r["method"] == label]
                axes[0][i].plot([p["spp"] for p in pts], [p["psnr"] for p in pts], "o-", label=label)
                axes[1][i].plot([p["spp"] for p in pts], [100 * p["exact"] for p in pts], "o-", label=label)
            axes[0][i].set_title(sc)
            for ax in (axes[0][i], axes[1][i]):
                ax.set_xscale("log", base=2)
                ax.set_xlabel("samples per pixel")
                ax.grid(alpha=0.3)
            axes[0][i].set_ylabel("PSNR vs converged (dB)")
            axes[1][i].set_ylabel("exact pixels (%)")
        axes[0][0].legend(fontsize=8)
        fig.tight_layout()
        os.makedirs(a.plots, exist_ok=True)
        fig.savefig(os.path.join(a.plots, "noise_psnr_exact_vs_spp.png"), dpi=90)


if __name__ == "__main__":
    main()

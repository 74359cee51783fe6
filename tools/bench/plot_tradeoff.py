#!/usr/bin/python3
"""Plots of `dcm bench`: error against total time and against exact fraction,
one curve per method, per scene.

    /usr/bin/python3 tools/bench/plot_tradeoff.py OUT/bench.csv OUT [--quiet]

Reads bench.csv (written by `dcm bench`) and writes, for every scene,
SCENE_psnr_vs_time.png and SCENE_psnr_vs_exact.png into OUT (atomically:
a temporary file renamed into place); for the noise sweep SCENE_noise.png,
for a .blend SCENE_cycles.png. Needs Debian's python3-matplotlib.
"""
import csv
import math
import os
import sys
import tempfile

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

CURVES = [  # (method, sweep, style, legend)
    ("dcm", "threshold", dict(color="tab:red", marker="o"), "dcm (default), threshold sweep"),
    ("paper", "threshold", dict(color="tab:orange", marker="s"), "paper (Scheel 2001), threshold sweep"),
    ("guo", "threshold", dict(color="tab:brown", marker="^"), "guo (1998), threshold sweep"),
    ("jbu", "rival", dict(color="tab:blue", marker="D"), "uniform grid + joint bilateral"),
    ("bilinear", "rival", dict(color="tab:cyan", marker="v"), "uniform grid + bilinear"),
]
OTHER_SWEEPS = [  # dcm settings drawn as single points
    ("min_block", "P", "min block"),
    ("block", "X", "elementary block"),
    ("supersampling", "*", "supersampling"),
    ("enhancement", ".", "one enhancement on/off"),
]


def num(s):
    try:
        return float(s)
    except ValueError:
        return float("nan")


def save(fig, path):
    fd, tmp = tempfile.mkstemp(suffix=".png", dir=os.path.dirname(os.path.abspath(path)))
    os.close(fd)
    try:
        fig.savefig(tmp, dpi=90)
        os.chmod(tmp, 0o644)
        os.replace(tmp, path)
    finally:
        if os.path.exists(tmp):
            os.remove(tmp)
    plt.close(fig)


def plot_noise(scene, rows, path):
    """dcm bench --spp: PSNR against the converged reference and exact pixels
    against the samples per pixel, one curve per method."""
    labels = []
    for r in rows:
        label = r["label"].rsplit(" spp=", 1)[0]
        if label not in labels:
            labels.append(label)
    fig, (a, b) = plt.subplots(1, 2, figsize=(10, 4.2))
    for label in labels:
        c = sorted((r for r in rows if r["label"].rsplit(" spp=", 1)[0] == label), key=lambda r: num(r["spp"]))
        x = [num(r["spp"]) for r in c]
        a.plot(x, [num(r["psnr_db"]) for r in c], "o-", label=label)
        b.plot(x, [100 * num(r["exact_fraction"]) for r in c], "o-", label=label)
    for ax in (a, b):
        ax.set_xscale("log", base=2)
        ax.set_xlabel("samples per pixel of the exact evaluation")
        ax.grid(True, which="both", alpha=0.3)
    a.set_ylabel("PSNR against the converged render, dB")
    b.set_ylabel("exact pixels, %")
    a.set_title("%s: error from noisy samples" % scene)
    b.set_title("%s: pixels evaluated" % scene)
    a.legend(fontsize=8)
    fig.tight_layout()
    save(fig, path)


def plot_cycles(scene, rows, path):
    """dcm bench on a .blend: PSNR against the converged render over wall time,
    the full Cycles render and each dcm blender variant as curves over their
    samples per pixel, adaptive sampling as points."""
    fig, ax = plt.subplots(figsize=(7.5, 5.4))
    labels = []
    for r in rows:
        label = r["label"].rsplit(" spp=", 1)[0]
        if r["method"] != "adaptive" and label not in labels:
            labels.append(label)
    styles = [dict(color="k", marker="s", linestyle="--")] + [
        dict(color=c, marker="o") for c in ("tab:red", "tab:blue", "tab:green", "tab:purple", "tab:brown")]
    for label, style in zip(labels, styles):
        c = sorted((r for r in rows if r["method"] != "adaptive" and r["label"].rsplit(" spp=", 1)[0] == label),
                   key=lambda r: num(r["spp"]))
        x, y = [num(r["time_total_s"]) for r in c], [num(r["psnr_db"]) for r in c]
        ax.plot(x, y, label=label if label != "full Cycles" else "full Cycles render", linewidth=1.4, **style)
        for r, xi, yi in zip(c, x, y):
            ax.annotate("%s spp" % r["spp"], (xi, yi), textcoords="offset points", xytext=(5, -11), fontsize=7,
                        color=style["color"])
    adaptive = [r for r in rows if r["method"] == "adaptive"]
    if adaptive:
        ax.scatter([num(r["time_total_s"]) for r in adaptive], [num(r["psnr_db"]) for r in adaptive], marker="^",
                   color="tab:orange", s=40, zorder=3, label="Cycles adaptive sampling (noise threshold)")
        for r in adaptive:
            ax.annotate(r["label"].rsplit(" spp=", 1)[0].split()[-1], (num(r["time_total_s"]), num(r["psnr_db"])),
                        textcoords="offset points", xytext=(5, 4), fontsize=7, color="tab:orange")
    ax.set_xscale("log")
    # Seconds as numbers at 1, 2, 5 x 10^k: a few seconds to minutes rarely span a decade.
    from matplotlib.ticker import FormatStrFormatter, LogLocator, NullFormatter
    ax.xaxis.set_major_locator(LogLocator(base=10, subs=(1.0, 2.0, 5.0)))
    ax.xaxis.set_major_formatter(FormatStrFormatter("%g"))
    ax.xaxis.set_minor_formatter(NullFormatter())
    ax.set_xlabel("wall clock from the command to the EXR, s (Blender's start-up included)")
    ax.set_ylabel("PSNR against the converged render, dB (higher is better)")
    ax.set_title("%s: what accuracy costs in time (Cycles)" % scene)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    save(fig, path)


def main(argv):
    if len(argv) < 3:
        print(__doc__, file=sys.stderr)
        return 2
    csv_path, out_dir = argv[1], argv[2]
    quiet = "--quiet" in argv[3:]
    with open(csv_path, newline="") as f:
        rows = list(csv.DictReader(f))
    scenes = []
    for r in rows:
        if r["scene"] not in scenes:
            scenes.append(r["scene"])
    for scene in scenes:
        pts = [r for r in rows if r["scene"] == scene]
        # A .blend's sweep (Cycles) or the noise sweep: one plot of its own instead of the trade-off pair.
        special = next(((sweep, plot) for sweep, plot in (("cycles", plot_cycles), ("noise", plot_noise))
                        if any(sweep in r["sweeps"].split("|") for r in pts)), None)
        if special:
            sweep, plot = special
            path = os.path.join(out_dir, "%s_%s.png" % (scene, sweep))
            plot(scene, [r for r in pts if sweep in r["sweeps"].split("|")], path)
            if not quiet:
                print("wrote %s" % path, file=sys.stderr)
            continue
        full = [r for r in pts if r["method"] == "full"]
        for xkey, xlabel, name, logx in [
            ("time_total_s", "total time, s (illumination + guides + reconstruction)", "psnr_vs_time", True),
            ("exact_fraction", "exact pixels, % of the working image", "psnr_vs_exact", False),
        ]:
            fig, ax = plt.subplots(figsize=(7, 5.6))
            scale = 100.0 if xkey == "exact_fraction" else 1.0
            for method, sweep, style, legend in CURVES:
                c = [r for r in pts if r["method"] == method and sweep in r["sweeps"].split("|")]
                c = [r for r in c if math.isfinite(num(r["psnr_db"]))]
                c.sort(key=lambda r: num(r["exact_fraction"]))
                if not c:
                    continue
                ax.plot([num(r[xkey]) * scale for r in c], [num(r["psnr_db"]) for r in c], label=legend,
                        linewidth=1.4, markersize=5, **style)
            for sweep, marker, legend in OTHER_SWEEPS:
                c = [r for r in pts if r["method"] in ("dcm", "guo") and r["sweeps"].split("|")[0] == sweep]
                c = [r for r in c if math.isfinite(num(r["psnr_db"]))]
                if not c:
                    continue
                ax.scatter([num(r[xkey]) * scale for r in c], [num(r["psnr_db"]) for r in c], marker=marker,
                           color="0.45", s=28, label="dcm/guo: " + legend, zorder=3)
            if full and xkey == "time_total_s":
                ax.axvline(num(full[0]["time_total_s"]), color="k", linestyle="--", linewidth=1,
                           label="full render (exact): %.2f s" % num(full[0]["time_total_s"]))
            if logx:
                ax.set_xscale("log")
            ax.set_xlabel(xlabel)
            ax.set_ylabel("PSNR against the full render, dB (higher is better)")
            ax.set_title("%s: error against %s" % (scene, "total time" if logx else "exact fraction"))
            ax.grid(True, which="both", alpha=0.3)
            ax.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.13), ncol=2, frameon=False)
            fig.tight_layout()
            path = os.path.join(out_dir, "%s_%s.png" % (scene, name))
            save(fig, path)
            if not quiet:
                print("wrote %s" % path, file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))

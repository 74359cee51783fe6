#!/usr/bin/python3
"""The tables of docs/RESULTS.md from the output of tools/bench/run_results.sh.

    /usr/bin/python3 tools/bench/results_tables.py build/bench-results > tables.md

Reads SCENE/bench.csv and SCENE/summary.md of every bundled scene and prints,
in RESULTS.md's order: the goal table, the paper's tables (as each summary
writes them), the methods at their defaults, the threshold sweep and the
one-setting-at-a-time table. Nothing is typed in by hand.
"""
import csv
import os
import re
import sys

SCENES = ["room", "room-paper", "cactus", "parquet", "mirror"]
THRESHOLDS = ["0.015", "0.03", "0.06", "0.1", "0.12", "0.15", "0.25", "0.5"]
# dcm's default contrast threshold with supersampled input
# (contrastThreshold under the supersampled rules, lib/src/settings.cpp): every bundled scene
# is supersampled. main() checks that each scene's bench has that point.
DEFAULT = "0.15"


def rows(results, scene):
    with open(os.path.join(results, scene, "bench.csv")) as f:
        return list(csv.DictReader(f))


def summary(results, scene):
    with open(os.path.join(results, scene, "summary.md")) as f:
        return f.read()


def pct(r):
    return 100.0 * float(r["exact_fraction"])


def psnr(r):
    p = float(r["psnr_db"])
    return "exact" if p == float("inf") else "%.2f" % p


def by_label(rs, label):
    for r in rs:
        if r["label"] == label:
            return r
    return None


def equal_error(text, rival):
    """The time a rival needs for dcm's error, from the summary's bullets."""
    m = re.search(r"- %s does not reach [\d.]+ dB within the sweep: at 50 %% exact pixels it has ([\d.]+) dB in ([\d.]+) s"
                  % rival, text)
    if m:
        return "not reached (%s dB at 50 %%, %.2f s)" % (m.group(1), float(m.group(2)))
    m = re.search(r"- %s reaches [\d.]+ dB at about ([\d.]+) s total" % rival, text)
    return "%.2f s" % float(m.group(1)) if m else "?"


def goal_table(results):
    print("| scene | dcm default: exact % | PSNR dB | total s | bilinear PSNR (margin) | JBU PSNR (margin) | ≥ 3 dB "
          "| time to dcm's error: bilinear | JBU | full render | faster at equal error |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for scene in SCENES:
        text = summary(results, scene)
        budget = {}
        for method in ("dcm", "bilinear", "jbu"):
            m = re.search(r"^\| %s \| ([\d.]+) \| ([\d.]+) \| [^|]+ \| [^|]+ \| ([\d.]+) \| ([^|]*)\|" % method, text, re.M)
            budget[method] = m.groups() if m else ("?", "?", "?", "?")
        full = re.search(r"the full render \(exact\) takes ([\d.]+) s", text)
        holds = "holds" in re.search(r"Goal, >= 3 dB[^\n]*", text).group(0)
        faster = "holds" in re.search(r"Goal, less total time[^\n]*", text).group(0)
        d = budget["dcm"]
        print("| %s | %s | %s | %.2f | %s (%s) | %s (%s) | %s | %s | %s | %s s | %s |" % (
            scene, d[0], d[1], float(d[2]), budget["bilinear"][1], budget["bilinear"][3].strip(), budget["jbu"][1],
            budget["jbu"][3].strip(), "yes" if holds else "**no**", equal_error(text, "bilinear"),
            equal_error(text, "jbu"), "%.2f" % float(full.group(1)) if full else "?", "yes" if faster else "**no**"))


def paper_tables(results):
    for scene in SCENES:
        text = summary(results, scene)
        for m in re.finditer(r"^### (.*?)\n\n((?:\|.*\n)+)", text, re.M):
            print("#### %s: %s\n" % (scene, m.group(1)))
            print(m.group(2))


def methods_table(results):
    print("| scene | method | exact % | PSNR dB | SSIM | relMSE | illum s | guides s | engine s | total s |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for scene in SCENES:
        rs = rows(results, scene)
        for label in ("full", "dcm t=" + DEFAULT, "paper t=0.06", "guo t=0.06"):
            r = by_label(rs, label)
            if r is None:
                continue
            print("| %s | %s | %.2f | %s | %.4f | %.3g | %.2f | %.2f | %.2f | %.2f |" % (
                scene, label, pct(r), psnr(r), float(r["ssim"]), float(r["relmse"]), float(r["time_illum_s"]),
                float(r["time_guides_s"]), float(r["time_engine_s"]), float(r["time_total_s"])))


def threshold_table(results):
    print("| scene | " + " | ".join("t=%s%s" % (t, " (default)" if t == DEFAULT else "") for t in THRESHOLDS) + " |")
    print("|---|" + "---|" * len(THRESHOLDS))
    for scene in SCENES:
        rs = rows(results, scene)
        cells = []
        for t in THRESHOLDS:
            r = by_label(rs, "dcm t=%s" % t)
            cells.append("%.2f %% / %.1f dB / %.2f s" % (pct(r), float(r["psnr_db"]), float(r["time_total_s"]))
                         if r else "–")
        print("| %s | %s |" % (scene, " | ".join(cells)))


def settings_table(results):
    labels = []
    table = {}
    cell = lambda r: "%.2f / %.2f" % (pct(r), float(r["psnr_db"]))
    for scene in SCENES:
        rs = rows(results, scene)
        for r in rs:
            if r["method"] not in ("dcm", "guo") or r["label"].startswith(("dcm t=", "guo t=")):
                continue
            if r["label"] not in labels:
                labels.append(r["label"])
            table[(r["label"], scene)] = cell(r)
        table[("dcm default (t=%s)" % DEFAULT, scene)] = cell(by_label(rs, "dcm t=" + DEFAULT))
        table[("guo default (t=0.06, block 8)", scene)] = cell(by_label(rs, "guo t=0.06"))
    # The supersampling rows together, in order (a scene's own rate is its
    # default and has no row).
    dcm = [l for l in labels if l.startswith("dcm") and not l.startswith("dcm ss=")]
    ss = sorted((l for l in labels if l.startswith("dcm ss=")), key=lambda l: int(l.split("=")[1]))
    at = next((i for i, l in enumerate(dcm) if not l.startswith(("dcm min_block", "dcm block"))), len(dcm))
    order = ["dcm default (t=%s)" % DEFAULT] + dcm[:at] + ss + dcm[at:] + \
            ["guo default (t=0.06, block 8)"] + [l for l in labels if l.startswith("guo")]
    print("| setting | " + " | ".join(SCENES) + " |")
    print("|---|" + "---|" * len(SCENES))
    for label in order:
        print("| %s | %s |" % (label, " | ".join(table.get((label, s), "=") for s in SCENES)))


def main():
    if len(sys.argv) != 2:
        sys.exit("usage: results_tables.py RESULTS_DIR (the output folder of tools/bench/run_results.sh)")
    results = sys.argv[1]
    for scene in SCENES:
        r = by_label(rows(results, scene), "dcm t=" + DEFAULT)
        m = re.search(r"Equal budget \(dcm default, ([\d.]+) % exact\)", summary(results, scene))
        if r is None or m is None or abs(pct(r) - float(m.group(1))) > 0.006:
            sys.exit("%s: the bench's default point is not dcm t=%s; update DEFAULT" % (scene, DEFAULT))
    for title, fn in (("The goal", goal_table), ("The paper's tables", paper_tables),
                      ("Methods at their defaults", methods_table), ("The threshold", threshold_table),
                      ("One setting at a time: exact % / PSNR dB", settings_table)):
        print("### %s\n" % title)
        fn(results)
        print()


if __name__ == "__main__":
    main()

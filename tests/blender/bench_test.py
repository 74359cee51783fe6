"""`dcm bench` on a .blend, the noise axis for Cycles: the full render and
`dcm blender` at each --spp and adaptive sampling, each timed as a process of
its own, all compared with one converged render. Checks that each PSNR in the
table is the one of the EXR it wrote, that the full render is the file's own
render at those samples, the rendered reference's other seed, the tables and
the plot, and that bad input or a signal leaves no output and no Blender.

    /usr/bin/python3 bench_test.py DCM BLENDER SOURCE_DIR run|errors
Exit 77 (skipped) when Blender is missing."""
import csv
import json
import math
import os
import re
import shutil
import signal
import subprocess
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import blender_support as bs  # noqa: E402


def psnr(a, b):
    return 10 * np.log10(1 / bs.display_mse(a, b))


def bench(dcm, args, env=None):
    p = subprocess.run([dcm, "bench"] + args, capture_output=True, text=True, env=env, timeout=600)
    return p.returncode, p.stdout, p.stderr


def run(dcm, blender, src, tmp):
    blend = bs.make_scene(blender, src, tmp)  # 64x48, 16 spp, adaptive sampling and denoising off
    out = os.path.join(tmp, "out")
    code, so, se = bench(dcm, [blend, "--spp", "4,16", "--reference-spp", "64", "--adaptive", "0.05,0.2",
                               "--out", out, "--blender", blender])
    assert code == 0, se
    d = os.path.join(out, "scene")
    for f in ("reference.exr", "full_4.exr", "full_16.exr", "dcm_4.exr", "dcm_16.exr", "dcm_4.json", "dcm_16.json",
              "adaptive_0.05.exr", "adaptive_0.2.exr"):
        assert os.path.isfile(os.path.join(d, f)), (f, os.listdir(d))
    rows = list(csv.DictReader(open(os.path.join(out, "bench.csv"))))
    assert [(r["method"], r["spp"]) for r in rows] == [
        ("full", "4"), ("dcm blender", "4"), ("full", "16"), ("dcm blender", "16"), ("adaptive", "16"),
        ("adaptive", "16")], rows
    ref = bs.read_exr(os.path.join(d, "reference.exr"))[0]
    files = ["full_4", "dcm_4", "full_16", "dcm_16", "adaptive_0.05", "adaptive_0.2"]
    for r, f in zip(rows, files):
        # The table's PSNR is its EXR's against the reference: dcm's (float) and
        # numpy's (double) sums differ far below 0.01 dB.
        mine = psnr(bs.read_exr(os.path.join(d, f + ".exr"))[0], ref)
        assert abs(float(r["psnr_db"]) - mine) < 0.01, (f, r["psnr_db"], mine)
        assert float(r["time_total_s"]) > 0, r
    for r, f in zip(rows[1::2][:2], ("dcm_4", "dcm_16")):
        stats = json.load(open(os.path.join(d, f + ".json")))
        assert abs(float(r["exact_fraction"]) - stats["exact_fraction"]) < 1e-6, (r, stats["exact_fraction"])
        assert 0 < stats["exact_fraction"] < 1, stats["exact_fraction"]
    # The full render is the file's own render at its 16 samples: equal but for
    # the order of float additions (the Blender tests' bound).
    own = bs.render_full(blender, src, blend, tmp)
    full16 = bs.read_exr(os.path.join(d, "full_16.exr"))[0]
    assert np.allclose(full16, own, rtol=1e-5, atol=1e-7), float(np.abs(full16 - own).max())
    # The reference has a seed of its own: its first 16 samples are not the
    # full render's (with the same seed they would be, nearly).
    same_seed = bs.render_full(blender, src, blend, tmp, samples=64, seed=0)
    assert psnr(ref, same_seed) < 60, psnr(ref, same_seed)
    # Noise falls with samples: 4x the samples is 4x less variance, which the
    # reference's own noise (64 spp) caps at +5.3 dB; 2 dB leaves the display
    # curve and the pixel filter room.
    assert float(rows[2]["psnr_db"]) > float(rows[0]["psnr_db"]) + 2, (rows[0]["psnr_db"], rows[2]["psnr_db"])
    summary = open(os.path.join(out, "summary.md")).read()
    assert "| 16 | dcm blender |" in summary and "| 16 | adaptive 0.05 |" in summary, summary
    j = json.load(open(os.path.join(out, "bench.json")))
    assert j["inputs"][0]["kind"] == "blend" and j["inputs"][0]["reference_spp"] == 64, j["inputs"]
    assert [p.get("adaptive_threshold") for p in j["points"]][-2:] == [0.05, 0.2], j["points"][-2:]
    # Each dcm run beside the full renders and the adaptive runs at its wall time:
    # their PSNR linear in log time between the two runs around it.
    def at_time(curve, t):
        curve = sorted(curve, key=lambda p: p["time_total_s"])
        for a, b in zip(curve, curve[1:]):
            if a["time_total_s"] <= t <= b["time_total_s"]:
                x = math.log(t / a["time_total_s"]) / math.log(b["time_total_s"] / a["time_total_s"])
                return a["psnr_db"] + x * (b["psnr_db"] - a["psnr_db"])
        return None
    for kind, key in (("full", "full_psnr_at_time"), ("adaptive", "adaptive_psnr_at_time")):
        curve = [p for p in j["points"] if p["method"] == kind]
        for p in (p for p in j["points"] if p["method"] == "dcm blender"):
            want = at_time(curve, p["time_total_s"])
            assert (p[key] is None) == (want is None) and (want is None or abs(p[key] - want) < 1e-9), (key, p, want)
            row = next(r for r in summary.splitlines() if r.startswith("| %d | dcm blender |" % p["spp"]))
            cell = row.split("|")[8 if kind == "full" else 9].strip()
            # Outside the curve's times: which end of it the run passed.
            assert (cell.startswith("%.2f dB" % want) if want is not None else
                    re.fullmatch(r"(faster|slower) than the (adaptive [0-9.]+|[0-9]+-spp render)'s [0-9.]+ s", cell)), \
                (kind, row)
    try:
        import matplotlib  # noqa: F401
        assert os.path.isfile(os.path.join(out, "scene_cycles.png")), os.listdir(out)
    except ImportError:
        pass
    # A given reference is read (Blender's Combined layer) instead of rendered;
    # --repeat 3 times each run three times and reports the median.
    out2 = os.path.join(tmp, "out2")
    code, so, se = bench(dcm, [blend, "--spp", "4", "--reference", os.path.join(d, "reference.exr"), "--out", out2,
                               "--blender", blender, "--no-plots", "-q", "--repeat", "3"])
    assert code == 0, se
    assert not os.path.exists(os.path.join(out2, "scene", "reference.exr"))
    rows2 = list(csv.DictReader(open(os.path.join(out2, "bench.csv"))))
    mine = psnr(bs.read_exr(os.path.join(out2, "scene", "full_4.exr"))[0], ref)
    assert abs(float(rows2[0]["psnr_db"]) - mine) < 0.01, (rows2[0], mine)
    for p in json.load(open(os.path.join(out2, "bench.json")))["points"]:
        assert len(p["times_s"]) == 3, p
        assert p["time_total_s"] == sorted(p["times_s"])[1], p


def errors(dcm, blender, src, tmp):
    blend = bs.make_scene(blender, src, tmp)
    out = os.path.join(tmp, "out")

    def refused(args, code, *words, env=None):
        c, so, se = bench(dcm, args + ["--out", out] + ([] if "--blender" in args else ["--blender", blender]), env=env)
        assert c == code, (args, c, se)
        for w in words:
            assert w in se, (args, w, se)
        assert not os.path.exists(out), (args, os.listdir(out))
        assert bs.no_blender_left(blend), (args, "a Blender is still running")

    refused([blend], 2, "--spp")
    refused([os.path.join(tmp, "none.blend"), "--spp", "4"], 1, "none.blend", "no such file")
    text = os.path.join(tmp, "text.blend")
    open(text, "w").write("not a blend")
    refused([text, "--spp", "4"], 1, "text.blend", "not a .blend")
    refused([blend, "--spp", "4", "--blender", os.path.join(tmp, "no-blender")], 1, "no-blender")
    small = os.path.join(tmp, "small.exr")
    subprocess.run(["oiiotool", "--pattern", "constant:color=0.5,0.5,0.5", "8x8", "3", "-o", small], check=True)
    refused([blend, "--spp", "4", "--reference", small], 1, "full_4.exr", "64x48", "--reference", "small.exr", "8x8")
    refused([os.path.join(src, "examples/scenes/room.json"), "--adaptive", "0.01", "--quick"], 2, "--adaptive")
    # Blender fails mid-run: the step, Blender's own words, no output.
    crash = os.path.join(tmp, "crash.py")
    open(crash, "w").write("raise RuntimeError('the render script failed on purpose')\n")
    refused([blend, "--spp", "4"], 1, "the reference, 64 spp", "failed on purpose",
            env=dict(os.environ, DCM_BLENDER_RENDER=crash))
    # A signal while Blender renders: no output, no Blender, no scratch folder.
    scratch = os.path.join(tmp, "scratch")
    os.mkdir(scratch)
    for sig in (signal.SIGTERM, signal.SIGKILL):
        p = subprocess.Popen([dcm, "bench", "-q", blend, "--spp", "4", "--reference-spp", "100000", "--out", out,
                              "--blender", blender], env=dict(os.environ, TMPDIR=scratch),
                             stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        deadline = time.time() + 60
        while time.time() < deadline and bs.no_blender_left(blend):
            time.sleep(0.1)
        assert not bs.no_blender_left(blend), "no Blender started in 60 s"
        time.sleep(1)
        assert p.poll() is None, "dcm ended before the signal"
        p.send_signal(sig)
        assert p.wait(timeout=30) == -sig, p.returncode
        # The guardians remove the scratch folders up to 3 s after dcm's death.
        deadline = time.time() + 10
        while time.time() < deadline and (os.listdir(scratch) or not bs.no_blender_left(blend)):
            time.sleep(0.1)
        assert bs.no_blender_left(blend), (sig, "a Blender is still running")
        assert os.listdir(scratch) == [], (sig, os.listdir(scratch))
        if sig == signal.SIGTERM:  # SIGKILL cannot be handled: it may leave temporaries (docs/PROMISES.md)
            assert not os.path.exists(out), (sig, os.listdir(out))
        shutil.rmtree(out, ignore_errors=True)


if __name__ == "__main__":
    sys.exit(bs.main({"run": run, "errors": errors}, "dcm-bench-test-"))

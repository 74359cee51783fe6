"""`dcm blender` on the tiny test scene: with --variance off the exact pixels
equal a full Cycles render of the same file; by default they are the mean of
two renders at half the samples with two seeds, and the engine gets their
variance; --target-psnr and --budget are met, in about one render call per
run of the quality search (judged by validation pixels, or by the preview's
estimate where it can tell); the .blend is unchanged, and bad input ends with a message naming
the file and the step, exit 1, no output and no Blender left; a signal to dcm
(SIGTERM, SIGKILL) leaves no output, no Blender and no scratch folder.

    /usr/bin/python3 dcm_blender_test.py DCM BLENDER SOURCE_DIR exact|variance|quality|preview_target|errors
Exit 77 (skipped) when Blender is missing."""
import hashlib
import json
import math
import os
import signal
import subprocess
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import blender_support as bs  # noqa: E402


def run(dcm, args, env=None, quiet=False):
    # Progress goes to a terminal only: captured, stderr has warnings and errors alone either way.
    p = subprocess.run([dcm, "blender"] + (["-q"] if quiet else []) + args, capture_output=True, text=True, env=env,
                       timeout=120)
    return p.returncode, p.stdout, p.stderr


def exact(dcm, blender, src, tmp):
    blend = bs.make_scene(blender, src, tmp)
    digest = hashlib.sha256(open(blend, "rb").read()).hexdigest()
    ref = bs.render_full(blender, src, blend, tmp)
    h, w = ref.shape[:2]
    for schedule in ("preview", "levels"):
        out, stats, smap = (os.path.join(tmp, schedule + e) for e in (".exr", ".json", ".png"))
        code, so, se = run(dcm, [blend, "-o", out, "--stats", stats, "--sample-map", smap, "--schedule", schedule,
                                 "--blender", blender, "--max-rounds", "8", "--min-round-share", "0", "--variance", "off",
                                 "--pool-preview", "off", "--preview-samples", "8"], quiet=schedule == "levels")
        assert code == 0, se
        # -q as in every command: no summary on stdout.
        assert ("exact pixels" in so) == (schedule == "preview") and (schedule == "preview" or so == ""), so
        img, spec = bs.read_exr(out)
        assert spec.channelnames == ("ViewLayer.Combined.R", "ViewLayer.Combined.G", "ViewLayer.Combined.B",
                                     "ViewLayer.Combined.A") or sorted(spec.channelnames) == sorted(
            ["ViewLayer.Combined." + c for c in "RGBA"]), spec.channelnames
        j = json.load(open(stats))
        b = j["blender"]
        assert b["preview_stand_ins"] == 0, b
        assert b["variance"] == "none" and len(b["seeds"]) == 1 and not j["settings"]["noisy"], (b, j["settings"])
        # The sample map's image part: dark grey (40, 40, 40) where interpolated.
        import OpenImageIO as oiio
        m = oiio.ImageInput.open(smap)
        sm = m.read_image("uint8")[:h, :w, :3]
        m.close()
        is_exact = (sm != 40).any(axis=2)
        assert is_exact.sum() == j["exact_pixels"], (is_exact.sum(), j["exact_pixels"])
        assert 0 < j["exact_fraction"] < 0.6, j["exact_fraction"]
        # Exact pixels: the same Cycles samples as the full render, equal but
        # for the order of float additions in the film (relative 1e-5, far
        # below the 16-spp noise of about 10 %).
        assert bs.as_rendered(img[is_exact], ref[is_exact]).all(), np.abs(img - ref)[is_exact].max()
        rounds = len(b["rounds"])
        if schedule == "preview":
            assert 1 <= rounds <= 8, b
        identical = (img[is_exact] == ref[is_exact]).all(axis=1).mean()
        print("%s: %.1f %% exact in %d render calls, %.1f %% bit-identical to the full render; %.2f s" % (
            schedule, 100 * j["exact_fraction"], rounds, 100 * identical, b["wall_s"]))
        if schedule == "preview":
            pooled(dcm, blender, src, tmp, blend, img, is_exact, b)
    assert hashlib.sha256(open(blend, "rb").read()).hexdigest() == digest, "the .blend changed"
    assert bs.no_blender_left(blend)


def pooled(dcm, blender, src, tmp, blend, alone, is_exact, b):
    """By default (--pool-preview on) each exact pixel ends as the inverse-variance mean of its
    samples and its preview's, rendered on seeds of their own: the same run otherwise (the same
    pixels exact, the interpolated ones unchanged), and the exact pixels closer to the converged
    image by 1 / (1 + s), s the preview's samples over theirs."""
    out, stats = os.path.join(tmp, "pooled.exr"), os.path.join(tmp, "pooled.json")
    code, so, se = run(dcm, [blend, "-o", out, "--stats", stats, "--schedule", "preview", "--blender", blender,
                             "--max-rounds", "8", "--min-round-share", "0", "--variance", "off", "--preview-samples", "8"])
    assert code == 0, se
    img = bs.read_exr(out)[0]
    j = json.load(open(stats))
    assert j["blender"]["pooled_pixels"] == j["exact_pixels"] == is_exact.sum(), (j["blender"], is_exact.sum())
    assert "pooled         %d exact pixels" % is_exact.sum() in so, so
    assert (img[~is_exact] == alone[~is_exact]).all(), "pooling changed an interpolated pixel"
    s = b["exact_noise_share"]["assumed"]  # 8 preview samples of the file's 16: 0.5
    # The converged image: 1024 samples, whose own noise is 1/64 of the exact pixels'.
    conv = bs.render_full(blender, src, blend, tmp, samples=1024, seed=101)[..., :3]
    mse = [float(np.mean((x[is_exact][:, :3] - conv[is_exact]) ** 2)) for x in (alone, img)]
    # Expected 1 / (1 + s) = 0.67 (0.68 with the reference's noise). About 1000 pixels whose noise
    # is one path per channel: the ratio's sd is a few per cent, so 0.82 is far above chance and
    # far below the 1.0 of no pooling.
    assert mse[1] < 0.82 * mse[0], (mse, s)
    assert mse[1] > 0.5 * mse[0], ("pooled past its weight", mse, s)
    print("pooled: the exact pixels' squared error against 1024 spp %.3g -> %.3g (%.2f; 1/(1+s) = %.2f)" % (
        mse[0], mse[1], mse[1] / mse[0], 1 / (1 + s)))


def exact_mask(smap, h, w):
    """Where the sample map says exact: its image part is dark grey (40, 40, 40) where interpolated."""
    import OpenImageIO as oiio
    m = oiio.ImageInput.open(smap)
    sm = m.read_image("uint8")[:h, :w, :3]
    m.close()
    return (sm != 40).any(axis=2)


def variance(dcm, blender, src, tmp):
    """By default the exact pixels of the first round are two renders of half
    the samples with the file's seed and the next; the engine weighs their
    variance where the preview's halves say their noise matters (always with
    --variance on). Later rounds are one render of all the samples, their
    variance the preview's times the share the first round measured
    (--variance-from preview), or two halves as the first (halves)."""
    blend = bs.make_scene(blender, src, tmp)  # 16 spp, seed 0
    half_a = bs.render_full(blender, src, blend, tmp, 8, 0)
    half_b = bs.render_full(blender, src, blend, tmp, 8, 1)
    whole = bs.render_full(blender, src, blend, tmp, 16, 0)
    h, w = half_a.shape[:2]
    runs = {}
    # "on" and the runs compared with it have no error round (it depends on the correction's estimate);
    # "error round" has it, as by default. "raw" and "error round" keep the exact samples as
    # rendered (not pooled with the preview, `pooled` above) to compare them with the renders.
    no_error_round = ["--error-round", "0"]
    for name, flags in (("auto", []), ("on", ["--variance", "on"] + no_error_round),
                        ("raw", ["--variance", "on", "--no-denoise-samples", "--pool-preview", "off"] + no_error_round),
                        ("raw halves", ["--variance", "on", "--no-denoise-samples", "--pool-preview", "off",
                                        "--variance-from", "halves"] + no_error_round),
                        ("exact preview", ["--variance", "on", "--preview-samples", "16"] + no_error_round),
                        ("uncorrected", ["--variance", "on", "--preview-correction", "0"]),
                        ("unfiltered", ["--variance", "on", "--preview-filter", "0"] + no_error_round),
                        ("error round", ["--variance", "on", "--pool-preview", "off"])):
        out, stats, smap = (os.path.join(tmp, name + e) for e in (".exr", ".json", ".png"))
        # The preview at 8 of the file's 16 samples (the default, at least 16, would be all of them).
        preview = [] if name == "exact preview" else ["--preview-samples", "8"]
        code, so, se = run(dcm, [blend, "-o", out, "--stats", stats, "--sample-map", smap, "--blender", blender,
                                 "--max-rounds", "8", "--min-round-share", "0", "--schedule", "preview"] + preview + flags)
        assert code == 0, se
        j = json.load(open(stats))
        b = j["blender"]
        assert b["seeds"] == [0, 1], b
        # auto: the variance goes to the engine when the noise costs less than 42 dB.
        used = name != "auto" or b["noise_psnr"] < 42
        assert b["variance"] == ("halves" if used else "halves, not used"), b
        assert b.get("later_rounds_variance") == (None if not used else "halves" if "halves" in name else "preview"), b
        # The variance reached the engine: it runs its noise regime.
        assert j["settings"]["noisy"] == used, j["settings"]
        # Every pixel a round rendered is paid for, also where the noise regime's final run interpolated it.
        assert j["exact_pixels"] == sum(r["pixels"] for r in b["rounds"]) + b["extra_pixels"], (j["exact_pixels"], b)
        # The first round (256 pixels or more) measures the exact pixels' variance against
        # the preview's, used or not: 16 samples against 8 assume half, and leave less
        # noise than the preview's (1) but some (0). A preview of 16 samples (seeds of its
        # own) has the exact pixels' variance: their ratio, two sums over some 500 pixels
        # of a path tracer's heavy-tailed squared differences, within a factor of 1.4 of 1
        # (a ratio of samples applied twice or not at all would be off by 2).
        share = b["exact_noise_share"]
        assert b["rounds"][0]["pixels"] >= 256 and share["pixels"] == b["rounds"][0]["pixels"], (share, b["rounds"])
        if name == "exact preview":
            assert share["assumed"] == 1 and abs(math.log2(share["measured"])) < 0.5, share
        else:
            assert share["assumed"] == 0.5 and 0 < share["measured"] < 1, share
        runs[name] = (bs.read_exr(out)[0], exact_mask(smap, h, w), j)
    # The preview (8 samples of the exact pixels' 16) comes with its variance: the engine tests its contrasts
    # against its noise, and its first round asks for no more than a plan on a preview of the exact pixels'
    # samples (16), but for the two previews' different noise (25 %). Without the variance the
    # preview's noise passed for edges: 996 pixels against 761 at 16 samples.
    first = {k: runs[k][2]["blender"]["rounds"][0]["pixels"] for k in ("on", "exact preview")}
    assert first["on"] <= 1.25 * first["exact preview"], first
    # The engine denoises exact samples with their neighbours on the same surface.
    assert runs["on"][2]["denoised_samples"] > 0, runs["on"][2]
    assert runs["raw"][2]["denoised_samples"] == 0, runs["raw"][2]
    # Without the denoising an exact pixel rendered in halves is the mean of the two seeds'
    # renders (relative 1e-5: the order of float additions in Cycles' film, far below the
    # 8-spp noise), which differ: two seeds, each seen by Cycles' persistent session.
    def same(a, b, where):
        return bs.as_rendered(a[where][:, :3], b[where][:, :3]).all(axis=1)
    img, is_exact = runs["raw halves"][0], runs["raw halves"][1]
    mean = (half_a + half_b) / 2
    assert same(img, mean, is_exact).all(), np.abs(img - mean)[is_exact].max()
    differ = (np.abs(half_a - half_b)[is_exact][:, :3] > 1e-4).any(axis=1).mean()
    assert differ > 0.5, differ
    # By default only the first round is in halves: every later pixel is the file's own render
    # at all 16 samples (seed 0), and no more pixels are the halves' mean than the first round
    # and its extra pixels hold. Constant pixels equal both (58 of the exact ones here, 17 of
    # the 94 later): at least half the later ones must be the whole render's alone.
    img, is_exact, b = runs["raw"][0], runs["raw"][1], runs["raw"][2]["blender"]
    as_halves, as_whole = same(img, mean, is_exact), same(img, whole, is_exact)
    assert (as_halves | as_whole).all(), "an exact pixel is neither the halves' mean nor the whole render"
    later = sum(r["pixels"] for r in b["rounds"][1:])
    assert later > 0 and (as_whole & ~as_halves).sum() >= 0.5 * later, ((as_whole & ~as_halves).sum(), b["rounds"])
    assert (as_halves & ~as_whole).sum() <= b["rounds"][0]["pixels"] + b["extra_pixels"], b
    # The preview correction (the preview carries its halves' variance) moves
    # interpolated pixels only: the same exact pixels, the same values there,
    # and the pixels that differ are among those it says it moved (a move
    # smaller than half a float step of the value leaves it: 384 of 390 differ).
    on, unc = runs["on"], runs["uncorrected"]
    assert (on[1] == unc[1]).all(), "the correction changed which pixels are exact"
    assert (on[0][on[1]] == unc[0][unc[1]]).all(), "the correction changed an exact pixel"
    moved = (on[0][:, :, :3] != unc[0][:, :, :3]).any(axis=2)
    assert unc[2]["blender"]["preview_corrected"] == 0, unc[2]["blender"]
    corrected = on[2]["blender"]["preview_corrected"]
    assert 0.9 * corrected <= moved.sum() <= corrected and corrected > 0, (moved.sum(), on[2]["blender"])
    # The preview filter (on by default) changes interpolated pixels only, those it says it
    # took halfway to their filtered preview: the correction's shares come before it.
    unf = runs["unfiltered"]
    assert (on[1] == unf[1]).all() and (on[0][on[1]] == unf[0][unf[1]]).all(), "the filter changed an exact pixel"
    filtered = on[2]["blender"]["preview_filtered"]
    changed = (on[0][:, :, :3] != unf[0][:, :, :3]).any(axis=2)
    assert unf[2]["blender"]["preview_filtered"] == 0, unf[2]["blender"]
    assert 0 < changed.sum() <= filtered <= (~on[1]).sum(), (changed.sum(), filtered, on[2]["blender"])
    # The error round renders, after the same rounds, the interpolated pixels the preview says the
    # interpolation missed most, and keeps them exact as rendered (not denoised, though the samples
    # are noisy).
    er = runs["error round"]
    n_error = er[2]["blender"]["error_round_pixels"]
    added = er[1] & ~on[1]
    assert (er[1] | ~on[1]).all() and added.sum() == n_error > 0, (added.sum(), er[2]["blender"])
    assert len(er[2]["blender"]["rounds"]) == len(on[2]["blender"]["rounds"]) + 1, (er[2]["blender"], on[2]["blender"])
    # (Some were extra pixels of the first round, its halves' mean; those its own call rendered
    # are whole.)
    as_halves, as_whole = same(er[0], mean, added), same(er[0], whole, added)
    assert (as_halves | as_whole).all() and as_whole.sum() >= er[2]["blender"]["rounds"][-1]["pixels"], (
        as_halves.sum(), as_whole.sum(), er[2]["blender"]["rounds"])
    # The corrected run estimates its PSNR against the converged image from the
    # preview where the preview's own noise costs less than 25 dB; without the
    # correction there is no estimate.
    assert "estimated_psnr" not in unc[2] and "preview_psnr" not in unc[2]["blender"], unc[2]
    for k in ("on", "exact preview"):
        j = runs[k][2]
        has = "estimated_psnr" in j
        assert has == (j["blender"]["preview_psnr"] >= 25), (k, j["blender"], j.get("estimated_psnr"))
        if has:
            assert j["estimated_psnr_against"] == "converged" and j["estimated_psnr_from"] == "preview", j
            assert j["estimated_psnr_low"] <= j["estimated_psnr"], j
            # Beside it the full render's own (the exact pixels' noise, a share of the preview's):
            # finite, and the claim that the result is closer needs its interval's lower end.
            r = j["estimated_render_psnr"]
            assert 0 < r < 99 and j["closer_than_render"] == (j["estimated_psnr_low"] >= r), j
    # --target-psnr render aims at the full render's own error, which only the variance tells: it
    # goes to the engine whatever auto would decide.
    out, stats = os.path.join(tmp, "render.exr"), os.path.join(tmp, "render.json")
    code, so, se = run(dcm, [blend, "-o", out, "--stats", stats, "--blender", blender, "--target-psnr", "render"])
    assert code == 0, se
    j = json.load(open(stats))
    assert j["blender"]["variance"] == "halves" and j["settings"]["noisy"], (j["blender"], j["settings"])
    # Validation pixels judge it, by each one's own variance: every round in halves.
    assert j["blender"]["later_rounds_variance"] == "halves", j["blender"]
    assert j["quality"]["target_render"] and j["estimated_render_psnr"] > 0, j
    # Two judges, the validation and the preview's estimate: the lower is reported (JSON null: +inf),
    # the summary names the other.
    judges = {"preview": j["quality"].get("second_estimate"), "validation": j["quality"].get("validation_estimate")}
    assert all(judges.values()), j["quality"]
    psnr = {k: math.inf if v["psnr"] is None else v["psnr"] for k, v in judges.items()}
    lower = min(psnr, key=psnr.get)
    other = "validation" if lower == "preview" else "preview"
    assert j["estimated_psnr_from"] == lower and j["estimated_psnr"] == psnr[lower], (j, psnr)
    assert "the lower of two judges, the %s's estimate %.2f dB" % (other, psnr[other]) in so, (psnr, so)
    print("%.1f %% exact; %.0f %% of them differ between the seeds; %d denoised; auto: noise %.1f dB, %s; first "
          "round %d pixels (%d with an exact preview); with it, the preview's own PSNR %.1f dB, estimate %s"
          % (100 * is_exact.mean(), 100 * differ, runs["on"][2]["denoised_samples"],
             runs["auto"][2]["blender"]["noise_psnr"], runs["auto"][2]["blender"]["variance"], first["on"],
             first["exact preview"], runs["exact preview"][2]["blender"]["preview_psnr"],
             runs["exact preview"][2].get("estimated_psnr")))
    assert bs.no_blender_left(blend)


def display_psnr(a, b):
    """PSNR of a against b as the stats' (blender_support.display_mse); +inf where they are equal (a
    search whose runs and the pixels their render calls computed besides cover the frame keeps them all)."""
    mse = bs.display_mse(a, b)
    return 10 * np.log10(1 / mse) if mse > 0 else float("inf")


def quality(dcm, blender, src, tmp):
    """--target-psnr and --budget: the quality search with preview-planned runs. With
    --variance off the exact pixels are the full render's, so the PSNR the search
    estimates (against the full render) can be checked against the full render."""
    blend = bs.make_scene(blender, src, tmp)
    ref = bs.render_full(blender, src, blend, tmp)
    total = ref.shape[0] * ref.shape[1]
    target = 32.0
    out, stats = os.path.join(tmp, "target.exr"), os.path.join(tmp, "target.json")
    code, so, se = run(dcm, [blend, "-o", out, "--stats", stats, "--blender", blender, "--variance", "off",
                             "--schedule", "preview", "--target-psnr", str(target), "--estimate-from", "validation"])
    assert code == 0, se
    j = json.load(open(stats))
    q, b = j["quality"], j["blender"]
    true = display_psnr(bs.read_exr(out)[0], ref)
    assert q["target_reached"] and q["confirmed"] and j["estimated_psnr_from"] == "validation", q
    # The estimate's lower bound reached the target; the truth is below it only by chance, not by 0.5 dB.
    assert true >= target - 0.5, (true, j["estimated_psnr_low"])
    # Two render calls per run of the search at most (the first validation draw with the first
    # run's first), one per later draw: at most three where the estimate's bound falls short, and
    # up to three confirming draws (kMaxConfirmations).
    assert 1 <= len(b["rounds"]) <= 2 * q["runs"] + 6, (b["rounds"], q["runs"])
    # Every pixel rendered once, and every one rendered counted, with those the rounds rendered
    # besides (the test scene's Blackman-Harris filter: extra pixels).
    assert b["extra_pixels"] > 0, b
    assert sum(r["pixels"] for r in b["rounds"]) + b["extra_pixels"] == j["exact_pixels"] == q["exact_pixels"], \
        (b["rounds"], b["extra_pixels"], q)
    assert "quality" in so, so
    # Noise-free, every pixel the search paid for is in the result with its exact value (on this
    # small frame the rounds and what their calls computed besides cover it all: the truth is +inf).
    held = sum(n for why, n in j["by_reason"].items() if why not in ("interpolated", "preview_stand_in"))
    assert held == j["exact_pixels"], (j["by_reason"], j["exact_pixels"])
    print("--target-psnr %g: estimated %.2f dB (low %.2f), true %.2f dB, %.1f %% exact, %d runs, %d render calls"
          % (target, j["estimated_psnr"], j["estimated_psnr_low"], true, 100 * j["exact_fraction"], q["runs"],
             len(b["rounds"])))
    budget = 0.3
    code, so, se = run(dcm, [blend, "-o", out, "--stats", stats, "--blender", blender, "--variance", "off",
                             "--schedule", "preview", "--budget", str(budget), "--estimate-from", "validation"])
    assert code == 0, se
    j = json.load(open(stats))
    rendered = sum(r["pixels"] for r in j["blender"]["rounds"])
    assert j["exact_fraction"] <= budget and rendered <= budget * total, (j["exact_fraction"], rendered)
    assert rendered <= j["exact_pixels"] <= rendered + j["blender"]["extra_pixels"], (j["exact_pixels"], rendered)
    print("--budget %g: %.1f %% exact (%d pixels rendered), estimated %.2f dB, true %.2f dB"
          % (budget, 100 * j["exact_fraction"], rendered, j["estimated_psnr"], display_psnr(bs.read_exr(out)[0], ref)))
    assert bs.no_blender_left(blend)


def preview_target(dcm, blender, src, tmp):
    """--target-psnr judged by the preview's estimate (auto where the preview can tell;
    without a goal or a threshold, a target of 40 dB): 64 samples in two halves, a 32-sample preview (the render's own noise
    about 36 dB against the converged image), against a 1024-sample render of another seed (the converged image
    within 1/16 of the render's variance). A preview of 16 samples (8 + 8) is too few on this scene for the
    estimate: the red sphere's specular highlight, two or three pixels, shows in one half and not the other,
    and the estimate misses its loss (1.3 to 3.0 dB high at --target-psnr 34 over eight seeds; docs/QUALITY.md,
    "Where the preview cannot see")."""
    blend = bs.make_scene(blender, src, tmp)
    converged = bs.render_full(blender, src, blend, tmp, 1024, 7)
    total = converged.shape[0] * converged.shape[1]
    out, stats = os.path.join(tmp, "preview_target.exr"), os.path.join(tmp, "preview_target.json")
    runs = {}
    for target in (30.0, 34.0):
        code, so, se = run(dcm, [blend, "-o", out, "--stats", stats, "--blender", blender, "--samples", "64",
                                 "--preview-samples", "32", "--target-psnr", str(target), "--schedule", "preview",
                                 "-v"])
        assert code == 0, se
        assert "judged by the preview's estimate" in se, se
        j = json.load(open(stats))
        q, b = j["quality"], j["blender"]
        assert j["estimated_psnr_from"] == "preview" and j["estimated_psnr_against"] == "converged", j
        assert q["validation_pixels"] == 0 and not q["confirmed"], q
        true = display_psnr(bs.read_exr(out)[0], converged)
        # Reached: its lower bound at the target. The truth is at most 0.5 dB below it
        # (the bound) but for the reference's own noise, 1/16 of the 64-sample
        # render's (about 36 + 12 dB): it reads 0.2 dB low at 34 dB.
        assert q["target_reached"] and j["estimated_psnr_low"] >= target, q
        assert true >= target - 0.7, (target, true, j["estimated_psnr"])
        # The ladder steps down; every pixel is rendered once and counted, with those the rounds
        # rendered besides (the test scene's Blackman-Harris filter: extra pixels).
        ladder = [r["threshold"] for r in q["ladder"]]
        assert ladder == sorted(ladder, reverse=True) and len(ladder) == q["runs"], q["ladder"]
        # It starts an octave above 0.42 for each prediction on the preview 1 dB past the target.
        preds = q["start_predictions"]
        passed = [p for p in preds if p["low"] is not None and p["low"] >= target + 1]
        assert preds and abs(preds[0]["threshold"] - 0.84) < 1e-6 and preds[:len(passed)] == passed, preds
        assert abs(ladder[0] / (0.42 * 2 ** len(passed)) - 1) < 1e-6, (ladder, preds)
        assert b["extra_pixels"] > 0, b
        assert sum(r["pixels"] for r in b["rounds"]) + b["extra_pixels"] == q["exact_pixels"] == j["exact_pixels"], \
            (b["rounds"], b["extra_pixels"], q)
        runs[target] = (true, j)
        print("--target-psnr %g from the preview: estimated %.2f dB (low %.2f), true %.2f dB against 1024 spp, "
              "%.1f %% exact, thresholds %s, %d render calls; predicted %s"
              % (target, j["estimated_psnr"], j["estimated_psnr_low"], true, 100 * j["exact_fraction"], ladder,
                 len(b["rounds"]), [(round(p["threshold"], 2), p["pixels"], p["low"] and round(p["low"], 2))
                                    for p in preds]))
    # A higher target costs at least as many exact pixels.
    assert runs[34.0][1]["exact_fraction"] >= runs[30.0][1]["exact_fraction"], runs
    # Where the engine does not weigh the exact pixels' variance (at 1024 samples their noise costs
    # more than 42 dB: --variance auto leaves it out), it is measured (the first round in two halves,
    # a render call more) only where it can move the estimate: the render's own noise from the ratio
    # of samples (about 48 dB) within 6 dB of the target. At 40 dB it is not: the same first round
    # (the ladder starts at the same threshold) in half the render calls.
    meas = {}
    for target in (40.0, 44.0):
        code, so, se = run(dcm, [blend, "-o", out, "--stats", stats, "--blender", blender, "--samples", "1024",
                                 "--preview-samples", "64", "--target-psnr", str(target), "--schedule", "preview",
                                 "-v"])
        assert code == 0 and "judged by the preview's estimate" in se, se
        b = json.load(open(stats))["blender"]
        assert b["variance"] == "halves, not used", b
        # The exact pixels at half, a quarter, ... of the samples while a full render at as few would
        # lose at most a fifth of the target's squared error (the render's own noise from the ratio),
        # no fewer than the preview's, and their noise left clean (42 dB) as the engine takes it.
        j = 0
        while (1024 >> (j + 1)) >= 64 and b["noise_psnr"] - 10 * math.log10(2 << j) >= 42 and \
                ((2 << j) - 1) * 10 ** (-b["render_psnr_from_ratio"] / 10) <= (1 - 10 ** -0.1) * 10 ** (-target / 10):
            j += 1
        assert b["samples"] == 1024 and b["exact_samples"] == 1024 >> j, (target, b)
        # The exact pixels' variance against the preview's, as the ratio of their samples says.
        assert b["exact_noise_share"]["assumed"] == 64 / (1024 >> j), (target, b)
        assert ("blender: exact pixels at %d of 1024 samples" % (1024 >> j) in se) == (j > 0), se
        print("--target-psnr %g at 1024 samples: exact pixels at %d (the render from the ratio %.2f dB)"
              % (target, b["exact_samples"], b["render_psnr_from_ratio"]))
        meas[target] = (b, se.count("dcm-blender: render eval1 "), se)
    (low, low_calls, low_se), (high, high_calls, _) = meas[40.0], meas[44.0]
    assert low["exact_noise_share"]["pixels"] == 0 and low["exact_noise_share"]["measured"] is None, low
    assert "noise is not measured" in low_se, low_se
    ratio = low["render_psnr_from_ratio"]
    assert 40 + 6 <= ratio < 44 + 6 and high["render_psnr_from_ratio"] == ratio, (low, high)
    assert high["exact_noise_share"]["pixels"] == high["rounds"][0]["pixels"] >= 256, high
    assert low["rounds"][0]["pixels"] == high["rounds"][0]["pixels"], (low["rounds"], high["rounds"])
    assert high_calls == 2 * low_calls > 0, (low_calls, high_calls)
    assert high["exact_samples"] == 1024, high  # 44 dB: a fifth of its error is less than the render's
    # --fixed-samples: every exact pixel at --samples whatever the goal.
    code, so, se = run(dcm, [blend, "-o", out, "--stats", stats, "--blender", blender, "--samples", "1024",
                             "--preview-samples", "64", "--target-psnr", "40", "--fixed-samples"])
    assert code == 0 and json.load(open(stats))["blender"]["exact_samples"] == 1024, se
    # --schedule auto (the default) plans on the preview, which the guides render gives (preview_cost=0),
    # also where a render call costs fewer than the 1000 samples of the rule for an unknown preview cost:
    # at 4096 samples a call (its fixed time, the masked pixels until they stop at 16) costs a few hundred.
    code, so, se = run(dcm, [blend, "-o", out, "--stats", stats, "--blender", blender, "--samples", "4096",
                             "--preview-samples", "256", "--threshold", "0.3", "-v"])
    assert code == 0, se
    j = json.load(open(stats))
    b = j["blender"]
    assert j["schedule"] == "preview", (j["schedule"], se)
    print("--samples 4096: round latency %.3f s, %.3g s per pixel (%.0f pixels' cost), schedule %s"
          % (b["round_latency_s"], b["sample_cost_s"], b["round_latency_s"] / b["sample_cost_s"], j["schedule"]))
    # A target beyond the render's own noise (about 42 dB here at 256 samples, where --variance auto
    # takes the exact samples as clean) is searched for all the same (that estimate of the render can
    # err low): the ladder runs until its estimate stops rising or it ends, keeps its best run, and
    # warns that the target was not reached and what more samples would do.
    code, so, se = run(dcm, [blend, "-o", out, "--stats", stats, "--blender", blender, "--samples", "256",
                             "--preview-samples", "16", "--target-psnr", "60", "--schedule", "preview"])
    assert code == 0 and "--target-psnr 60: not reached" in se and "more --samples raise both" in se, se
    j = json.load(open(stats))
    q = j["quality"]
    assert j["blender"]["variance"] == "halves, not used" and j["blender"]["noise_psnr"] >= 42, j["blender"]
    assert j["estimated_psnr_from"] == "preview" and not q["target_reached"], q
    assert len(q["ladder"]) >= 2 and j["estimated_render_psnr"] < 59.5, j
    assert j["estimated_psnr"] == max(r["psnr"] for r in q["ladder"]), q
    # With the exact samples' variance the engine denoises them and may pass the render's own
    # noise: validation pixels judge, and -v says why.
    code, so, se = run(dcm, [blend, "-o", out, "--stats", stats, "--blender", blender, "--samples", "64",
                             "--preview-samples", "16", "--target-psnr", "60", "--schedule", "preview",
                             "--variance", "on", "--max-rounds", "1", "-v"])
    assert code == 0 and "validation pixels: the render's own noise" in se, se
    assert "denoised exact samples may pass" in se, se
    assert json.load(open(stats))["estimated_psnr_from"] == "validation"
    # Without --threshold or a goal, dcm's default goal is --target-psnr 40 where the preview can
    # judge it. At 64 samples the render itself is about 36 dB from the converged image, noisy enough
    # that the engine weighs the exact samples' variance: the default threshold, said with -v, and
    # no warning (the user asked for nothing).
    code, so, se = run(dcm, [blend, "-o", out, "--stats", stats, "--blender", blender, "--samples", "64",
                             "--preview-samples", "16", "--schedule", "preview", "-v"])
    assert code == 0 and "warning" not in se, se
    assert "the default threshold: the preview cannot judge the default goal" in se and "own noise" in se, se
    j = json.load(open(stats))
    assert j["settings"]["noisy"] and abs(j["settings"]["contrast_threshold"] - 0.14) < 1e-6, j["settings"]
    assert "quality" not in j, j["quality"]  # no goal was searched for
    # At 256 samples (the render about 42 dB) the ladder reaches it.
    code, so, se = run(dcm, [blend, "-o", out, "--stats", stats, "--blender", blender, "--samples", "256",
                             "--preview-samples", "16", "--schedule", "preview", "-v"])
    assert code == 0 and "the default goal, --target-psnr 40 judged by the preview" in se, se
    j = json.load(open(stats))
    q = j["quality"]
    assert q["target_default"] and q["target_reached"] and j["estimated_psnr_low"] >= 40, q
    true = display_psnr(bs.read_exr(out)[0], converged)
    # The T - 0.5 dB, less what the reference's own noise (about 48 dB) takes from the
    # PSNR measured against it at 40 dB (0.64 dB).
    assert true >= 40 - 0.5 - 0.64, (true, j["estimated_psnr"])
    # A round the target did not need is not rendered: its pixels keep their preview value.
    b = j["blender"]
    assert not b["stopped_at_target"] or b["preview_stand_ins"] > 0, b
    print("default goal at 256 spp: estimated %.2f dB (low %.2f), true %.2f dB, %.1f %% exact, thresholds %s, "
          "rounds %s%s" % (j["estimated_psnr"], j["estimated_psnr_low"], true, 100 * j["exact_fraction"],
                           [round(r["threshold"], 4) for r in q["ladder"]], [r["pixels"] for r in b["rounds"]],
                           ", the last round not rendered" if b["stopped_at_target"] else ""))
    # The published methods and an explicit threshold keep the threshold: no goal.
    for flags in (["--method", "paper"], ["--threshold", "0.14"], ["--estimate-from", "validation"]):
        code, so, se = run(dcm, [blend, "-o", out, "--stats", stats, "--blender", blender, "--samples", "256",
                                 "--preview-samples", "16", "--schedule", "preview"] + flags)
        assert code == 0 and "quality" not in json.load(open(stats)), (flags, se)
    # --budget is judged by the preview too: one run at the finest threshold whose plan on the
    # preview fits (the rounds' extra pixels of the Blackman-Harris filter counted in it), no
    # validation pixels, the estimate against the converged image.
    budget = 0.3
    code, so, se = run(dcm, [blend, "-o", out, "--stats", stats, "--blender", blender, "--samples", "256",
                             "--preview-samples", "16", "--schedule", "preview", "--budget", str(budget), "-v"])
    assert code == 0 and "--budget judged by the preview's estimate" in se, se
    j = json.load(open(stats))
    q, b = j["quality"], j["blender"]
    assert j["estimated_psnr_from"] == "preview" and q["validation_pixels"] == 0 and len(q["ladder"]) == 1, q
    # The rounds' extra pixels are kept while the budget lasts; the ones past it are dropped.
    asked = sum(r["pixels"] for r in b["rounds"])
    assert asked <= j["exact_pixels"] <= min(asked + b["extra_pixels"], budget * total), \
        (b["rounds"], b["extra_pixels"], j["exact_pixels"])
    # Most of it spent: the plan may ask for 0.9 of the budget, the rounds after it for the rest.
    assert j["exact_pixels"] >= 0.6 * budget * total, j["exact_pixels"]
    true = display_psnr(bs.read_exr(out)[0], converged)
    # The 1.5 dB low; high, what this scene allows: the red sphere's specular highlight,
    # which the 16-sample preview's halves show one at a time, makes the estimate err 0.1 to 2.5 dB
    # high over eight seeds (docs/QUALITY.md, "Where the preview cannot see"); 3 dB catches worse.
    assert -1.5 <= j["estimated_psnr"] - true <= 3, (j["estimated_psnr"], true)
    print("--budget %g from the preview: %.2f %% exact, estimated %.2f dB, true %.2f dB, threshold %.4f"
          % (budget, 100 * j["exact_fraction"], j["estimated_psnr"], true, q["threshold"]))
    # With a target as well, whichever binds first, never past the budget.
    code, so, se = run(dcm, [blend, "-o", out, "--stats", stats, "--blender", blender, "--samples", "256",
                             "--preview-samples", "16", "--schedule", "preview", "--budget", "0.2",
                             "--target-psnr", "41"])
    assert code == 0, se
    j = json.load(open(stats))
    q = j["quality"]
    assert j["estimated_psnr_from"] == "preview" and j["exact_pixels"] <= 0.2 * total, j
    assert q["target_reached"] != q["budget_bound"], q
    # Asked for explicitly where it cannot tell (a 4-sample preview, about 23 dB): a usage error
    # naming the flag; without the preview schedule or with --target-psnr render.
    for flags in (["--preview-samples", "4", "--schedule", "preview"], ["--schedule", "levels"]):
        code, so, se = run(dcm, [blend, "-o", out, "--blender", blender, "--samples", "64", "--target-psnr", "30",
                                 "--estimate-from", "preview"] + flags)
        assert code == 2 and "--estimate-from preview" in se, (flags, code, se)
    code, so, se = run(dcm, [blend, "-o", out, "--blender", blender, "--samples", "64", "--target-psnr", "render",
                             "--estimate-from", "preview", "--schedule", "preview"])
    assert code == 2 and "--estimate-from preview" in se, (code, se)
    assert bs.no_blender_left(blend)


def errors(dcm, blender, src, tmp):
    blend = bs.make_scene(blender, src, tmp)
    out = os.path.join(tmp, "out.exr")

    def refused(args, *parts, env=None, code=1):
        c, so, se = run(dcm, args, env)
        assert c == code, (args, c, se)
        for part in parts:
            assert part in se, (args, part, se)
        assert not os.path.exists(out), args
        assert not [f for f in os.listdir(tmp) if f.startswith("out")], os.listdir(tmp)
        assert bs.no_blender_left(blend), "a Blender is still running"

    missing = os.path.join(tmp, "missing.blend")
    refused([missing, "-o", out, "--blender", blender], missing, "no such file", "reading the scene")
    text = os.path.join(tmp, "notes.blend")
    open(text, "w").write("not a blend file\n")
    refused([text, "-o", out, "--blender", blender], text, "not a .blend file")
    refused([blend, "-o", out, "--blender", os.path.join(tmp, "no-blender")], "no-blender", "not found")
    # Blender dies mid-round: its scratch folder (made by dcm under TMPDIR) goes too.
    scratch = os.path.join(tmp, "scratch")
    os.mkdir(scratch)
    env = dict(os.environ, DCM_BLENDER_TEST_FAULT="crash-on-eval", TMPDIR=scratch)
    refused([blend, "-o", out, "--blender", blender], blend, "signal", env=env)
    assert os.listdir(scratch) == [], os.listdir(scratch)
    signalled(dcm, blender, blend, out, scratch)
    refused([blend, "-o", os.path.join(tmp, "no-such-dir", "out.exr"), "--blender", blender], "no-such-dir")
    refused([blend, "-o", out, "--blender", blender, "--target-psnr", "40", "--full"],
            "--target-psnr: not with --full", code=2)
    refused([blend, "-o", out, "--blender", blender, "--target-psnr", "render", "--variance", "off"],
            "--target-psnr render", "--variance off", code=2)
    # The rounds' numbers are refused before Blender starts, NaN too, the flag named.
    for flag in ("--plan-significance", "--error-round", "--min-round-share"):
        for value in ("nan", "-1"):
            refused([blend, "-o", out, "--blender", blender, flag, value], flag, code=2)
    # A scene set to Eevee: the child says why it cannot render it.
    eevee = os.path.join(tmp, "eevee.blend")
    subprocess.run([blender, "-b", blend, "--python-expr",
                    "import bpy; bpy.context.scene.render.engine = 'BLENDER_EEVEE'; "
                    "bpy.ops.wm.save_as_mainfile(filepath=%r)" % eevee], check=True, capture_output=True)
    refused([eevee, "-o", out, "--blender", blender], eevee, "Cycles only")


def signalled(dcm, blender, blend, out, scratch):
    """A signal to dcm while Blender renders: dcm's handler (SIGTERM) or its
    supervisor (SIGKILL) ends Blender, and the scratch folder's guardian
    removes the folder once dcm is gone (its last removal 3 s after dcm's
    death; 10 s allow for a loaded machine)."""
    env = dict(os.environ, TMPDIR=scratch)

    def guardian_left():
        return subprocess.run(["pgrep", "-f", "dcm-scratch-guardian " + scratch + "/"],
                              capture_output=True).returncode == 0

    for sig in (signal.SIGTERM, signal.SIGKILL):
        # Enough samples that the full render is still running when the signal comes.
        p = subprocess.Popen([dcm, "blender", "-q", blend, "-o", out, "--blender", blender, "--full",
                              "--samples", "100000"], env=env, stdout=subprocess.DEVNULL,
                             stderr=subprocess.DEVNULL)
        deadline = time.time() + 60
        while time.time() < deadline and not os.listdir(scratch):
            time.sleep(0.1)
        assert os.listdir(scratch), "dcm made no scratch folder in 60 s"
        time.sleep(2)
        assert p.poll() is None, "dcm ended before the signal"
        p.send_signal(sig)
        assert p.wait(timeout=30) == -sig, p.returncode
        deadline = time.time() + 10
        while time.time() < deadline and (os.listdir(scratch) or guardian_left() or not bs.no_blender_left(blend)):
            time.sleep(0.1)
        assert os.listdir(scratch) == [], (sig, os.listdir(scratch))
        assert not guardian_left(), sig
        assert bs.no_blender_left(blend), (sig, "a Blender is still running")
        assert not os.path.exists(out), sig


if __name__ == "__main__":
    sys.exit(bs.main({"exact": exact, "variance": variance, "quality": quality,
                      "preview_target": preview_target, "errors": errors}, "dcm-blender-test-"))

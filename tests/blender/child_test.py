"""The dcm-pipe child inside Blender (plugins/blender), driven over the
protocol: the pixels of two rounds equal a full Cycles render of the same
file, each round renders its own mask (not the last one), the scene is
restored and the .blend is unchanged.

    /usr/bin/python3 child_test.py BLENDER SOURCE_DIR
Exit 77 (skipped) when Blender is missing."""
import hashlib
import os
import shutil
import subprocess
import sys
import tempfile

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import blender_support as bs  # noqa: E402


def main():
    blender, src = sys.argv[1], sys.argv[2]
    if not shutil.which(blender):
        print("blender not found: skipped")
        return 77
    tmp = tempfile.mkdtemp(prefix="dcm-blender-child-test-")
    # Every Blender this test starts makes its session folder here, removed with tmp.
    os.environ["TMPDIR"] = os.path.join(tmp, "tmpdir")
    os.mkdir(os.environ["TMPDIR"])
    try:
        blend = bs.make_scene(blender, src, tmp)
        digest = hashlib.sha256(open(blend, "rb").read()).hexdigest()
        ref = bs.render_full(blender, src, blend, tmp)
        h, w = ref.shape[:2]
        keep = os.path.join(tmp, "renders")
        # Tiles of 8 px, always within render borders: rounds 1 and 2 render six
        # rows of tiles each, round 3 one tile.
        child = bs.Child(blender, src, blend, ["--verify-restore", "--keep-renders", keep, "--border-tile", "8"])
        assert (child.width, child.height) == (w, h), (child.width, child.height)
        assert "preview" in child.caps and "split" in child.caps, child.caps
        assert child.round_latency > 0 and child.sample_cost > 0, child.hello
        # The preview comes with the guides render: it costs no schedule anything more.
        assert " preview_cost=0 " in child.hello, child.hello
        # 16 samples: a sixteenth would be 1; the preview takes the floor of 16 (at most
        # the file's samples; docs/BLENDER.md, *Guides, preview and rounds*).
        assert child.preview_samples == 16, child.hello

        ids, shaders, tau, normal = child.guides()
        # On a surface whose DiffCol (the guides render's) is below 0.02 in every channel at
        # most pixels, the texture guide is the Denoising Albedo (at least 0.02), which
        # continues through mirrors. Here that is the sky alone.
        import glob
        guides_npz = np.load(glob.glob(os.path.join(keep, "*_guides.npz"))[0])
        diffcol = np.stack([guides_npz["DiffCol." + c] for c in "RGB"], -1)
        albedo = np.stack([guides_npz["Denoising Albedo." + c] for c in "RGB"], -1)
        sky = guides_npz["CryptoObject00.r"].view(np.uint32)
        sky = sky == sky[0, 0]  # the top row is sky
        through_mirror = sky
        assert (diffcol[sky] < 0.02).all() and not sky.all(), sky.mean()
        tau = tau.reshape(h, w, 3)
        assert np.allclose(tau[through_mirror], np.maximum(albedo[through_mirror], 0.02), atol=1e-6)
        assert np.allclose(tau[~through_mirror], diffcol[~through_mirror], atol=1e-6)
        # Floor, cube, the two spheres, the shade and the sky: six objects and materials.
        assert len(set(ids.tolist())) == 6 and len(set(shaders.tolist())) == 6, (set(ids), set(shaders))

        rng = np.random.default_rng(7)
        order = rng.permutation(w * h)
        block = np.array([y * w + x for y in range(10, 14) for x in range(19, 25)])  # tiles 2 and 3 of row 1: one border
        rounds = [order[: w * h // 10], order[w * h // 10: w * h // 5], block]
        lit_by_round = []
        for r, sel in enumerate(rounds):
            xs, ys = sel % w, sel // w
            L, Li, Lc = child.eval(xs, ys)
            # Through a mirror L_i is the light it reflects (GlossCol * GlossInd) over the
            # texture guide; the sky reflects none: L_i = 0, L_c = L.
            mirror = through_mirror[ys, xs]
            assert r == 2 or mirror.any(), "round %d: no sky pixel to look at" % r
            assert (Li[mirror] == 0).all() and np.array_equal(Lc[mirror], L[mirror])
            lit_by_round.append(Li.max(axis=1) > 0)
            want = ref[ys, xs]
            # The same samples of the same pixels: equal but for the order of
            # float additions in Cycles' film (relative 1e-5 is far below the
            # 16-spp noise, about 10 %, and far above float rounding).
            assert bs.as_rendered(L, want).all(), "round %d: max |L - full render| = %g" % (r, np.abs(L - want).max())
            # L = L_i * tau + L_c with the guides' tau, as the engine composes it.
            assert np.allclose(Li * tau[ys, xs] + Lc, L, rtol=1e-5, atol=1e-6)
            # Pixels not asked for whose whole reach (Blackman-Harris 1.5 px) lay in
            # the mask are rendered as in the full render: the same tolerance.
            ex, ey, eL, eLi, eLc = child.extra
            assert not np.isin(ey * w + ex, sel).any(), "an extra pixel was asked for"
            ewant = ref[ey, ex]
            assert bs.as_rendered(eL, ewant).all(), \
                "round %d, extra pixels: max |L - full render| = %g" % (r, np.abs(eL - ewant).max())
            assert np.allclose(eLi * tau[ey, ex] + eLc, eL, rtol=1e-5, atol=1e-6)
            print("round %d: %d pixels, %.1f %% bit-identical to the full render; %d extra"
                  % (r, len(sel), 100 * (L == want).all(axis=1).mean(), len(ex)))
            # A tenth of the pixels at random: many a pixel between them has its reach covered.
            assert r == 2 or len(ex) > 0, "round %d rendered no extra pixel" % r
        # The mask rendered was the mask asked for: the second round shows
        # surfaces (diffuse colour) only around its own pixels, not around the first's.
        second = np.zeros((h, w), bool)
        for f in sorted(glob.glob(os.path.join(keep, "*_eval2.npz"))):
            second |= np.load(f)["DiffCol.R"] > 0
        assert len(glob.glob(os.path.join(keep, "*_eval3.npz"))) == 1, os.listdir(keep)
        first_only = np.zeros((h, w), bool)
        first_only.flat[rounds[0]] = True
        near_second = np.zeros((h, w), bool)
        for dy in range(-2, 3):
            for dx in range(-2, 3):
                near_second[np.clip(rounds[1] // w + dy, 0, h - 1), np.clip(rounds[1] % w + dx, 0, w - 1)] = True
        assert not (second & first_only & ~near_second).any(), "round 2 rendered pixels of round 1"
        # Its own pixels where its diffuse light came back (the same render's samples hit a
        # diffuse surface) show that surface's colour. (The guides' tau is no test of that:
        # the preview has seeds of its own, and an edge pixel's few samples may miss.)
        assert second.flat[rounds[1]][lit_by_round[1]].all(), "round 2 did not render its own pixels"
        assert lit_by_round[1].mean() > 0.5, "round 2: too few pixels with diffuse light to tell"
        prev = child.preview(0, 0, w, h)
        assert prev.shape == (w * h, 3) and np.isfinite(prev).all()
        assert child.quit() == 0, "the child did not exit cleanly (or the scene was not restored)"
        assert hashlib.sha256(open(blend, "rb").read()).hexdigest() == digest, "the .blend changed"

        # With halves the texture guide is the mean of the two guide renders' DiffCol, and the
        # preview carries its covariance with L, (tau_A - tau_B)(L_A - L_B) nA nB / N^2, as the
        # variance (L_A - L_B)^2 nA nB / N^2 (8 preview samples: 4 + 4).
        keep_h = os.path.join(tmp, "renders_halves")
        child = bs.Child(blender, src, blend, ["--variance-halves", "--keep-renders", keep_h])
        assert "texture_covariance" in child.caps and "variance" in child.caps, child.caps
        tau = child.guides()[2].reshape(-1, 3)
        rec = child.preview(0, 0, w, h, "L,split,variance,texcov")
        assert child.quit() == 0
        halves = [np.load(f) for f in sorted(glob.glob(os.path.join(keep_h, "*_guides.npz")))]
        assert len(halves) == 2, os.listdir(keep_h)
        rgb = lambda d, name: np.stack([d[name + "." + c] for c in "RGB"], -1).reshape(-1, 3)
        (ta, tb), (la, lb), (aa, ab) = ([rgb(d, name) for d in halves]
                                        for name in ("DiffCol", "Combined", "Denoising Albedo"))
        objects = halves[0]["CryptoObject00.r"].view(np.uint32).reshape(-1)
        mirror = objects == objects[0]  # the sky, as above
        ta[mirror], tb[mirror] = np.maximum(aa[mirror], 0.02), np.maximum(ab[mirror], 0.02)
        assert np.allclose(tau[~mirror], ((ta + tb) / 2)[~mirror], atol=1e-6)
        assert np.allclose(tau[mirror], np.maximum((aa + ab)[mirror] / 2, 0.02), atol=1e-6)
        assert np.allclose(rec[:, 9:12], (la - lb) ** 2 / 4, rtol=1e-5, atol=1e-9)
        assert np.allclose(rec[:, 12:15], (ta - tb) * (la - lb) / 4, rtol=1e-5, atol=1e-9)
        assert (rec[:, 12:15] != 0).any(), "no pixel where the halves' tau and L co-vary: a flat scene"

        # A masked pixel stops after a few samples (adaptive sampling on its
        # all-zero samples); a requested pixel takes every sample. At 64 spp:
        # Cycles judges convergence every 16 samples.
        keep64 = os.path.join(tmp, "renders64")
        child = bs.Child(blender, src, blend, ["--keep-renders", keep64, "--border-tile", "8", "--samples", "64"])
        child.guides()
        child.eval(block % w, block // w)
        assert child.quit() == 0
        kept = np.load(glob.glob(os.path.join(keep64, "*_eval1.npz"))[0])
        count = kept["Debug Sample Count.X"]
        asked = np.zeros((h, w), bool)
        asked.flat[block] = True
        # Masked and stopping: inside the render border (count > 0), black, and 3 px
        # or more from anything rendered. Rendered are the requested pixels, their
        # neighbours that a Blackman-Harris pixel's rays reach, and the world,
        # which is not masked; Cycles' convergence filter marks the neighbours of
        # a pixel still sampling in x, then in y.
        lit = kept["Combined.R"] != 0
        far = (count > 0) & ~lit
        for y, x in zip(*np.nonzero(lit)):
            far[max(y - 2, 0):y + 3, max(x - 2, 0):x + 3] = False
        assert (count[asked] == 1).all(), "requested pixels took fewer samples: %s" % count[asked]
        assert far.any() and (count[far] <= 0.25).all(), \
            "masked pixels took more than 16 of 64 samples: %s" % np.unique(count[far])

        # Exact pixels that stop early are rendered again: at a noise threshold of
        # 0.05 half of these exact pixels converge before 64 samples (measured:
        # 160 of 307), and every exact pixel must still equal the full render
        # (the tolerance of the rounds above).
        keep1 = os.path.join(tmp, "renders-threshold")
        child = bs.Child(blender, src, blend, ["--keep-renders", keep1, "--samples", "64",
                                               "--adaptive-threshold", "0.05", "--keep-alive", "off"])
        child.guides()
        sel = order[: w * h // 10]
        L, _, _ = child.eval(sel % w, sel // w)
        assert child.quit() == 0
        first = np.load(sorted(glob.glob(os.path.join(keep1, "*_eval1.npz")))[0])["Debug Sample Count.X"]
        assert (first.flat[sel] < 1).mean() > 0.25, "the threshold did not stop exact pixels early"
        # Scattered over the whole frame, they are rendered again in one render
        # of it, not a render per 16-px run of tiles (the child's cost model).
        again = glob.glob(os.path.join(keep1, "*_eval1_again.npz"))
        assert len(again) == 1, os.listdir(keep1)
        ref64 = bs.render_full(blender, src, blend, tmp, samples=64, seed=0)  # make_scene's seed
        want = ref64.reshape(-1, ref64.shape[-1])[sel][:, :3]
        assert bs.as_rendered(L, want).all(), "max |L - full render| = %g" % np.abs(L - want).max()

        # The keep-alive: with it on, exact pixels whose samples are all 0 (the cube,
        # made black: its diffuse colour, no other closure) take every sample
        # instead of stopping at Cycles' first check, and every exact pixel still
        # equals the full render.
        dtmp = os.path.join(tmp, "dark")
        os.mkdir(dtmp)
        dblend = os.path.join(dtmp, "dark.blend")
        subprocess.run([blender, "-b", blend, "--python-expr",
                        "import bpy; bpy.data.materials['NoNodes'].diffuse_color = (0, 0, 0, 1); "
                        "bpy.ops.wm.save_as_mainfile(filepath=%r)" % dblend], check=True, stdout=subprocess.DEVNULL)
        dref = bs.render_full(blender, src, dblend, dtmp, samples=64, seed=0)
        black = np.flatnonzero((dref[..., :3] == 0).all(axis=-1))
        assert len(black) >= 20, "the black cube covers %d pixels" % len(black)
        dsel = np.union1d(black, order[: w * h // 10])
        keepd = os.path.join(tmp, "renders-dark")
        child = bs.Child(blender, src, dblend, ["--keep-renders", keepd, "--samples", "64", "--keep-alive", "on"])
        child.guides()
        L, _, _ = child.eval(dsel % w, dsel // w)
        assert child.quit() == 0, "the child did not exit cleanly"
        count = np.load(sorted(glob.glob(os.path.join(keepd, "*_eval1.npz")))[0])["Debug Sample Count.X"]
        assert (count.flat[black] == 1).all(), "black exact pixels stopped early: %s" % np.unique(count.flat[black])
        assert not glob.glob(os.path.join(keepd, "*_again.npz")), "exact pixels were rendered again"
        want = dref.reshape(-1, dref.shape[-1])[dsel][:, :3]
        assert bs.as_rendered(L, want).all(), "keep-alive: max |L - full render| = %g" % np.abs(L - want).max()
        # The keep-alive adds at most 1e-20 to a pixel (lost in any float sum above 1e-13).
        dark = np.abs(L[np.isin(dsel, black)])
        assert (dark <= 1e-20).all(), "black exact pixels: up to %g" % dark.max()

        # A Gaussian's rays leave up to 1.5 widths from the pixel's centre, 2.25 px at 1.5 px.
        # A mask over half its width missed some of them: the child's check refused the round,
        # and the pixels missed their rays' share (the tolerance of the rounds above).
        gtmp = os.path.join(tmp, "gaussian")
        os.mkdir(gtmp)
        gblend = bs.make_scene(blender, src, gtmp, pixel_filter="GAUSSIAN:1.5")
        gref = bs.render_full(blender, src, gblend, gtmp)
        child = bs.Child(blender, src, gblend)
        child.guides()
        L, _, _ = child.eval(sel % w, sel // w)
        assert child.quit() == 0
        want = gref.reshape(-1, gref.shape[-1])[sel][:, :3]
        assert bs.as_rendered(L, want).all(), "Gaussian 1.5 px: max |L - full render| = %g" % np.abs(L - want).max()
        print("ok")
        return 0
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


if __name__ == "__main__":
    sys.exit(main())

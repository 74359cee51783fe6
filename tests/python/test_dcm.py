#!/usr/bin/python3
"""The installed Python module dcm, run with Debian's /usr/bin/python3.

Environment (set by installed_module_test.cmake): PYTHONPATH=<prefix>/lib/python3/dist-packages,
DCM_PREFIX (the prefix: the module must come from there), DCM_EXE (<prefix>/bin/dcm),
DCM_MAKE_AOVS (examples/aov/make_aovs.py), DCM_EXAMPLE (examples/python/reconstruct.py).
"""
import json
import os
import subprocess
import sys
import tempfile
import unittest
import warnings

import numpy as np
import OpenImageIO as oiio

import dcm

PREFIX = os.environ["DCM_PREFIX"]
DCM = os.environ["DCM_EXE"]
MAKE_AOVS = os.environ["DCM_MAKE_AOVS"]
EXAMPLE = os.environ["DCM_EXAMPLE"]
# Wall times, and the time per stage (an object of them), differ from run to run.
TIME_KEYS = {"time_s", "time_illum_s", "time_guides_s", "time_reconstruct_s", "stage_times_s"}


def read_exr(path):
    inp = oiio.ImageInput.open(path)
    assert inp, oiio.geterror()
    pixels = inp.read_image("float")
    inp.close()
    return pixels


class Installed(unittest.TestCase):
    def test_module_comes_from_the_prefix(self):
        self.assertTrue(os.path.realpath(dcm.__file__).startswith(os.path.realpath(PREFIX)), dcm.__file__)
        out = subprocess.run([DCM, "--version"], capture_output=True, text=True, check=True).stdout
        self.assertEqual(out.strip(), "dcm " + dcm.__version__)

    def test_example_runs(self):
        out = subprocess.run([sys.executable, EXAMPLE], capture_output=True, text=True, check=True).stdout
        self.assertRegex(out, r"rendered \d+ pixels \([0-9.]+ %\) in \d+ calls")


class ReconstructExr(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.TemporaryDirectory()
        cls.aovs = os.path.join(cls.tmp.name, "aovs.exr")
        subprocess.run([sys.executable, MAKE_AOVS, cls.aovs, "96"], check=True, capture_output=True)

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    def command(self, name, *flags):
        out = os.path.join(self.tmp.name, name + ".exr")
        stats = os.path.join(self.tmp.name, name + ".json")
        # --ch: the beauty alone (the output also carries the input's passes).
        subprocess.run([DCM, "reconstruct", self.aovs, "--preset", "generic", "-o", out, "--stats", stats,
                        "--ch", "R,G,B", "--quiet", *flags], check=True, capture_output=True)
        with open(stats) as f:
            return read_exr(out), json.load(f)

    def check_same(self, result, image, stats):
        self.assertEqual(result.image.dtype, np.float32)
        self.assertEqual(result.image.shape, image.shape)
        # The same code path: the same bits, not merely close.
        self.assertTrue(np.array_equal(result.image, image), "pixels differ from the command's")
        # The same statistics, but for the wall times.
        self.assertEqual({k: v for k, v in result.stats.items() if k not in TIME_KEYS},
                         {k: v for k, v in stats.items() if k not in TIME_KEYS})
        # The sample map agrees with the counts by reason.
        counts = np.bincount(result.sample_map.ravel(), minlength=len(dcm.REASON_NAMES))
        self.assertEqual({name: int(c) for name, c in zip(dcm.REASON_NAMES, counts)}, stats["by_reason"])

    def test_defaults_bit_identical_to_the_command(self):
        image, stats = self.command("default")
        result = dcm.reconstruct_exr(self.aovs, preset="generic")
        self.check_same(result, image, stats)
        self.assertGreater(stats["reference"]["psnr"], 30)

    def test_options_by_c_api_names_as_the_flags(self):
        image, stats = self.command("paper", "--method", "paper", "--threshold", "0.1", "--min-block", "2")
        result = dcm.reconstruct_exr([self.aovs], "generic", method="paper", contrast_threshold=0.1, min_block=2)
        self.check_same(result, image, stats)
        self.assertEqual(result.stats["method"], "paper")

    def test_none_is_the_regimes_default(self):
        # None leaves an option with a per-regime default unset: the command's defaults, bit for bit.
        image, stats = self.command("default")
        result = dcm.reconstruct_exr([self.aovs], "generic", elementary_block=None, contrast_threshold=None,
                                     contrast_metric=None, directions=None, thin_objects=None)
        self.check_same(result, image, stats)
        # Options without one take no None.
        with self.assertRaises(ValueError) as e:
            dcm.reconstruct_exr(self.aovs, preset="generic", min_block=None)
        self.assertIn("min_block", str(e.exception))

    def test_target_bit_identical_to_the_command(self):
        image, stats = self.command("target", "--target-psnr", "45")
        result = dcm.reconstruct_exr(self.aovs, preset="generic", target_psnr=45)
        self.check_same(result, image, stats)
        self.assertEqual(result.stats["quality"]["target_psnr"], 45)
        self.assertIn("estimated_psnr", result.stats)

    def test_noisy_default_bit_identical_to_the_command(self):
        # With the variance estimated and no goal, the command's noisy default (--target-psnr render,
        # at most 35 % exact) runs here too: the same bits and statistics, on all threads (a run the
        # bound refuses evaluates none of the request it refused, whichever batch came first).
        image, stats = self.command("noisy", "--estimate-variance")
        result = dcm.reconstruct_exr(self.aovs, preset="generic", estimate_variance=True)
        self.check_same(result, image, stats)
        self.assertTrue(result.stats["quality"]["target_render"])
        self.assertEqual(result.stats["quality"]["budget"], 0.35)

    def test_missing_file_names_it(self):
        missing = os.path.join(self.tmp.name, "no-such-render.exr")
        with self.assertRaises(dcm.Error) as e:
            dcm.reconstruct_exr(missing)
        self.assertIn("no-such-render.exr", str(e.exception))

    def test_bad_option_name_and_value(self):
        with self.assertRaises(ValueError) as e:
            dcm.reconstruct_exr(self.aovs, preset="generic", contrast_treshold=0.1)
        self.assertIn("contrast_treshold", str(e.exception))
        with self.assertRaises(ValueError) as e:
            dcm.reconstruct_exr(self.aovs, preset="generic", method="fast")
        self.assertIn("fast", str(e.exception))
        with self.assertRaises(TypeError) as e:
            dcm.reconstruct_exr(self.aovs, preset="generic", elementary_block="8")
        self.assertIn("elementary_block", str(e.exception))
        with self.assertRaises(ValueError) as e:  # the range check of the engine
            dcm.reconstruct_exr(self.aovs, preset="generic", elementary_block=12)
        self.assertIn("elementaryBlock", str(e.exception))
        with self.assertRaises(ValueError) as e:
            dcm.reconstruct_exr(self.aovs, preset="cycles")
        self.assertIn("cycles", str(e.exception))
        # 96 is no multiple of 5: an output pixel would be a partial box.
        with self.assertRaises(ValueError) as e:
            dcm.reconstruct_exr(self.aovs, preset="generic", downsample=5)
        self.assertIn("multiple of 5", str(e.exception))


def two_regions(width, height):
    """A slanted edge between object 1 (a linear gradient) and object 2 (constant)."""
    y, x = np.mgrid[0:height, 0:width]
    left = x < 0.4 * width + 0.3 * y
    ids = np.where(left, 1, 2).astype(np.uint32)
    truth = np.empty((height, width, 3), np.float32)
    truth[..., 0] = np.where(left, 0.1 + 0.5 * x / width, 0.8)
    truth[..., 1] = np.where(left, 0.2 + 0.3 * y / height, 0.6)
    truth[..., 2] = np.where(left, 0.3, 0.2)
    return ids, truth


def display_psnr(image, truth):
    """The stats' PSNR: sRGB of each channel clipped to [0, 1], peak 1 (tools/common/metrics.cpp)."""
    def srgb(v):
        v = np.clip(v, 0, 1)
        return np.where(v <= 0.0031308, 12.92 * v, 1.055 * np.power(v, 1 / 2.4) - 0.055)
    return 10 * np.log10(1 / np.mean((srgb(image.astype(np.float64)) - srgb(truth.astype(np.float64))) ** 2))


def highlights(width, height):
    """two_regions' edge, shaded, with 40 soft highlights (sigma 4 px) that no guide shows."""
    y, x = np.mgrid[0:height, 0:width].astype(np.float32)
    left = x < 0.4 * width + 0.3 * y
    ids = np.where(left, 1, 2).astype(np.uint32)
    image = np.where(left, 0.2 + 0.4 * x / width, 0.5)[..., None] * np.array([1, 0.8, 0.6], np.float32)
    for cx, cy in np.random.default_rng(7).uniform(0, 1, (40, 2)) * [width, height]:
        image += 0.8 * np.exp(-((x - cx) ** 2 + (y - cy) ** 2) / (2 * 4.0 ** 2))[..., None]
    return ids, image.astype(np.float32)


class PythonProvider(unittest.TestCase):
    def test_two_regions(self):
        width, height = 96, 64
        ids, truth = two_regions(width, height)
        calls = []

        def evaluate(xy):
            self.assertEqual(xy.dtype, np.int32)
            self.assertEqual(xy.ndim, 2)
            self.assertEqual(xy.shape[1], 2)
            calls.append(xy.copy())
            return truth[xy[:, 1], xy[:, 0]]

        r = dcm.reconstruct(width, height, guides={"id": ids}, evaluate=evaluate)
        self.assertEqual(r.image.shape, (height, width, 3))
        self.assertEqual(r.image.dtype, np.float32)
        evaluated = np.concatenate(calls)
        # Each exact pixel evaluated once, in one call per round.
        self.assertEqual(len(evaluated), r.stats["exact_pixels"])
        self.assertEqual(len({(int(x), int(y)) for x, y in evaluated}), len(evaluated))
        self.assertEqual(len(calls), r.stats["provider_calls"])
        exact = r.sample_map > 0
        self.assertEqual(int(exact.sum()), r.stats["exact_pixels"])
        self.assertTrue(exact[evaluated[:, 1], evaluated[:, 0]].all())
        self.assertLess(r.stats["exact_fraction"], 0.5)
        # The exact pixels are evaluate's values, bit for bit.
        self.assertTrue(np.array_equal(r.image[exact], truth[exact]))
        self.check_interpolated(r.image, truth, ids)

    def check_interpolated(self, image, truth, ids):
        """The interpolated pixels take samples of their own surface only (the ID guide)."""
        height, width = ids.shape
        err = np.abs(image - truth).max(axis=-1)
        # Object 2 is constant: what remains is float32 rounding of the
        # interpolation weights (values <= 1, a few ulps of 6e-8).
        self.assertLess(float(err[ids == 2].max()), 1e-5)
        # Object 1 is a linear gradient, which interpolation between two
        # samples reproduces, but an oriented line meets the block border
        # between pixel centres and takes the nearest sample: at most one
        # pixel's step of the gradient (0.5 / width in R, 0.3 / height in G).
        # A sample of object 2 (0.8 against <= 0.6 in R) would be far above.
        self.assertLess(float(err[ids == 1].max()), max(0.5 / width, 0.3 / height))

    def test_split_and_variance(self):
        width, height = 64, 64
        ids, li = two_regions(width, height)
        y, x = np.mgrid[0:height, 0:width]
        checker = ((x // 8 + y // 8) % 2).astype(np.float32)
        tau = np.stack([0.3 + 0.6 * checker, 0.4 + 0.4 * checker, 0.5 + 0.2 * checker], axis=-1).astype(np.float32)
        lc = np.zeros_like(li)
        lc[ids == 2] = (0.05, 0.05, 0.05)
        truth = li * tau + lc

        def evaluate(xy):
            px = (xy[:, 1], xy[:, 0])
            return {"Li": li[px], "Lc": lc[px], "var": np.zeros((len(xy), 3), np.float32)}

        r = dcm.reconstruct(width, height, guides={"id": ids, "tau": tau}, evaluate=evaluate, split=True,
                            variance=True)
        self.assertTrue(r.stats["used"]["split"])
        exact = r.sample_map > 0
        # L = Li * tau + Lc made by dcm in float32, as numpy does.
        self.assertTrue(np.allclose(r.image[exact], truth[exact], rtol=0, atol=1e-6))
        # The texture is divided out and put back, so the checker is no edge:
        # the bounds of test_two_regions hold (tau <= 0.9 scales Li's error).
        self.check_interpolated(r.image, truth, ids)

    def run_goal(self, ids, truth, **goal):
        """dcm.reconstruct to a goal; asserts that no pixel is evaluated twice across the search."""
        height, width = ids.shape
        seen = []

        def evaluate(xy):
            seen.append(xy.copy())
            return truth[xy[:, 1], xy[:, 0]]

        r = dcm.reconstruct(width, height, guides={"id": ids}, evaluate=evaluate, **goal)
        evaluated = np.concatenate(seen)
        self.assertEqual(len({(int(x), int(y)) for x, y in evaluated}), len(evaluated))
        self.assertEqual(len(evaluated), r.stats["exact_pixels"])
        return r

    def test_target_and_budget(self):
        ids, truth = highlights(256, 192)
        plain = self.run_goal(ids, truth)
        # The default threshold misses most highlights: the target has work to do.
        self.assertLess(display_psnr(plain.image, truth), 35)

        r = self.run_goal(ids, truth, target_psnr=40)
        q = r.stats["quality"]
        self.assertTrue(q["target_reached"])
        self.assertEqual(q["target_psnr"], 40)
        self.assertGreaterEqual(r.stats["estimated_psnr_low"], 40)
        # Issue #22's tolerance for the truth of a reached target: T - 0.5 dB.
        self.assertGreaterEqual(display_psnr(r.image, truth), 39.5)

        r = self.run_goal(ids, truth, budget=0.03)
        self.assertLessEqual(r.stats["exact_pixels"], 0.03 * 256 * 192)  # never exceeded, validation included
        self.assertTrue(r.stats["quality"]["budget_bound"])

        # A target the budget cannot reach: a RuntimeWarning naming it, the best reached returned.
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            r = self.run_goal(ids, truth, target_psnr=60, budget=0.03)
        self.assertFalse(r.stats["quality"]["target_reached"])
        self.assertLessEqual(r.stats["exact_pixels"], 0.03 * 256 * 192)
        self.assertTrue(any("target_psnr 60: not reached" in str(w.message) for w in caught), caught)
        self.assertTrue(any("target_psnr 60" in w for w in r.stats["warnings"]))

    def test_errors(self):
        ids, truth = two_regions(32, 32)

        def exact(xy):
            return truth[xy[:, 1], xy[:, 0]]

        for goal, error, text in [({"target_psnr": 0}, ValueError, "target_psnr: must be in (0, 99]"),
                                  ({"target_psnr": 100}, ValueError, "target_psnr: must be in (0, 99]"),
                                  ({"target_psnr": "best"}, ValueError, "target_psnr"),
                                  ({"budget": 1.5}, ValueError, "budget: must be a share"),
                                  ({"budget": "5%"}, TypeError, "budget"),
                                  ({"target_psnr": 40, "contrast_threshold": 0.1}, ValueError,
                                   "target_psnr: not with contrast_threshold"),
                                  ({"budget": 0.1, "full_evaluation": True}, ValueError,
                                   "budget: not with full_evaluation"),
                                  ({"target_psnr": "render"}, dcm.Error, "variance")]:
            with self.assertRaises(error, msg=str(goal)) as e:
                dcm.reconstruct(32, 32, evaluate=exact, **goal)
            self.assertIn(text, str(e.exception))

        def wrong_shape(xy):
            return np.zeros((len(xy), 4), np.float32)

        with self.assertRaises(ValueError) as e:
            dcm.reconstruct(32, 32, guides={"id": ids}, evaluate=wrong_shape)
        self.assertIn("evaluate()", str(e.exception))
        self.assertIn(", 3)", str(e.exception))

        class RendererCrashed(Exception):
            pass

        def crash(xy):
            raise RendererCrashed("out of licences")

        with self.assertRaises(RendererCrashed) as e:
            dcm.reconstruct(32, 32, evaluate=crash)
        self.assertIn("out of licences", str(e.exception))

        with self.assertRaises(ValueError) as e:
            dcm.reconstruct(32, 32, guides={"id": ids[:16]}, evaluate=wrong_shape)
        self.assertIn("guides['id']", str(e.exception))
        with self.assertRaises(ValueError) as e:  # (W, H, 3) for (H, W, 3)
            dcm.reconstruct(32, 16, guides={"tau": np.zeros((32, 16, 3), np.float32)}, evaluate=wrong_shape)
        self.assertIn("guides['tau']: expected shape (16, 32, 3)", str(e.exception))
        with self.assertRaises(ValueError) as e:
            dcm.reconstruct(32, 32, guides={"albedo": ids}, evaluate=wrong_shape)
        self.assertIn("albedo", str(e.exception))
        with self.assertRaises(ValueError) as e:
            dcm.reconstruct(32, 32, evaluate=lambda xy: truth[xy[:, 1], xy[:, 0]], no_such_option=1)
        self.assertIn("no_such_option", str(e.exception))
        with self.assertRaises(ValueError) as e:
            dcm.reconstruct(32, 32, evaluate=lambda xy: truth[xy[:, 1], xy[:, 0]], split=True,
                            guides={"tau": truth})
        self.assertIn("'Li'", str(e.exception))


if __name__ == "__main__":
    unittest.main(verbosity=2)

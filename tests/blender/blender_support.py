"""Shared by the Blender tests: the test scene, a full reference render, and
a driver of the dcm-pipe child."""
import os
import subprocess

import numpy as np


def make_scene(blender, src, tmp, res="64x48", samples=16, pixel_filter="BLACKMAN_HARRIS:1.5"):
    out = os.path.join(tmp, "scene.blend")
    subprocess.run([blender, "-b", "--factory-startup", "--python",
                    os.path.join(src, "tests/blender/make_scene.py"), "--", "--out", out,
                    "--res", res, "--samples", str(samples), "--filter", pixel_filter],
                   check=True, stdout=subprocess.DEVNULL)
    return out


def as_rendered(a, want):
    """Where a equals want but for the order of float additions in Cycles' film:
    relative 1e-5, far below any test scene's noise and far above float rounding."""
    return np.abs(a - want) <= 1e-5 * np.maximum(np.abs(want), 1) + 1e-7


def display_mse(a, b):
    """Mean squared difference of a and b [..., 3+] on sRGB-encoded values clipped to [0, 1], as the
    stats' PSNR measures it (tools/common/metrics.h)."""
    enc = lambda x: np.clip(np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.power(np.maximum(x, 0), 1 / 2.4) - 0.055),
                            0, 1)
    return float(np.mean((enc(a[..., :3].astype(np.float64)) - enc(b[..., :3].astype(np.float64))) ** 2))


def no_blender_left(marker):
    """No process but this one has `marker` in its command line (pgrep -f)."""
    out = subprocess.run(["pgrep", "-f", marker], capture_output=True, text=True).stdout.split()
    return not [pid for pid in out if int(pid) != os.getpid()]


def read_exr(path, layer="ViewLayer.Combined."):
    import OpenImageIO as oiio
    inp = oiio.ImageInput.open(path)
    if inp is None:
        raise RuntimeError("cannot open " + path)
    spec = inp.spec()
    px = inp.read_image("float")
    inp.close()
    names = list(spec.channelnames)
    return px[:, :, [names.index(layer + c) for c in "RGB"]], spec


def render_full(blender, src, blend, tmp, samples=None, seed=None):
    """The file rendered in full (at `samples` with `seed` when given): RGBA [h, w, 4]."""
    out = os.path.join(tmp, "full.exr" if samples is None else "full_%d_%d.exr" % (samples, seed))
    extra = [] if samples is None else [str(samples), str(seed)]
    subprocess.run([blender, "-b", blend, "--python", os.path.join(src, "tests/blender/render_full.py"), "--", out]
                   + extra, check=True, stdout=subprocess.DEVNULL)
    return read_exr(out)[0]


class Child:
    """The child started as `dcm blender` starts it; speaks the protocol."""

    def __init__(self, blender, src, blend, args=()):
        cmd = "'%s' -b '%s' --python '%s' -- --protocol-fd 3 %s 3>&1 1>&2" % (
            blender, blend, os.path.join(src, "plugins/blender/child_main.py"), " ".join(args))
        self.p = subprocess.Popen(["/bin/sh", "-c", cmd], stdin=subprocess.PIPE, stdout=subprocess.PIPE)
        self.hello = self._ask(b"dcm-pipe 1\n")
        t = self.hello.split()
        assert t[:2] == ["dcm-pipe", "1"], self.hello
        kv = dict(x.split("=", 1) for x in t[2:])
        self.width, self.height = int(kv["width"]), int(kv["height"])
        self.caps = kv["caps"].split(",")
        self.round_latency, self.sample_cost = float(kv["round_latency"]), float(kv["sample_cost"])
        self.preview_samples = int(kv["preview_samples"])

    def _ask(self, request):
        self.p.stdin.write(request)
        self.p.stdin.flush()
        return self.p.stdout.readline().decode()

    def _read(self, dtype, count):
        return np.frombuffer(self.p.stdout.read(np.dtype(dtype).itemsize * count), dtype)

    def guides(self):
        w, h = self.width, self.height
        line = self._ask(b"guides 0 0 %d %d object_id,shader_id,texture,normal\n" % (w, h))
        assert line.split() == ["guides", str(w * h)], line
        n = w * h
        ids, shaders = self._read("<u4", n), self._read("<u4", n)
        tau, normal = self._read("<f4", 3 * n).reshape(h, w, 3), self._read("<f4", 3 * n).reshape(h, w, 3)
        return ids, shaders, tau, normal

    def eval(self, xs, ys):
        xy = np.stack([xs, ys], 1).astype("<i4")
        line = self._ask(b"eval %d L,split\n" % len(xs) + xy.tobytes())
        assert line.split() == ["samples", str(len(xs))], line
        rec = self._read("<f4", 9 * len(xs)).reshape(-1, 9)
        # Capability `extra`: the pixels the round rendered exactly besides, as
        # self.extra = (x, y, L, L_i, L_c).
        self.extra = None
        if "extra" in self.caps:
            t = self.p.stdout.readline().decode().split()
            assert len(t) == 2 and t[0] == "extra", t
            m = int(t[1])
            exy = self._read("<i4", 2 * m).reshape(-1, 2)
            erec = self._read("<f4", 9 * m).reshape(-1, 9)
            self.extra = exy[:, 0], exy[:, 1], erec[:, 0:3], erec[:, 3:6], erec[:, 6:9]
        return rec[:, 0:3], rec[:, 3:6], rec[:, 6:9]

    def preview(self, x0, y0, x1, y1, what="L"):
        """The preview's records [n, 3 * parts] (L; split: L_i, L_c; variance; texcov)."""
        line = self._ask(b"preview %d %d %d %d %s\n" % (x0, y0, x1, y1, what.encode()))
        n = (x1 - x0) * (y1 - y0)
        assert line.split() == ["samples", str(n)], line
        parts = 1 + 2 * ("split" in what) + ("variance" in what) + ("texcov" in what)
        return self._read("<f4", 3 * parts * n).reshape(n, 3 * parts)

    def quit(self):
        self.p.stdin.write(b"quit\n")
        self.p.stdin.close()
        return self.p.wait(timeout=60)


def main(cases, prefix):
    """`SCRIPT DCM BLENDER SOURCE_DIR CASE`: runs cases[CASE](dcm, blender, src, tmp) in a
    temporary folder (removed after), every Blender's session folder in it; exit 77 when
    Blender is missing."""
    import shutil
    import sys
    import tempfile
    dcm, blender, src, what = sys.argv[1:5]
    if not shutil.which(blender):
        print("blender not found: skipped")
        return 77
    tmp = tempfile.mkdtemp(prefix=prefix)
    os.environ["TMPDIR"] = os.path.join(tmp, "tmpdir")
    os.mkdir(os.environ["TMPDIR"])
    try:
        cases[what](dcm, blender, src, tmp)
        print("ok")
        return 0
    finally:
        shutil.rmtree(tmp, ignore_errors=True)

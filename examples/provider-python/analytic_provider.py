#!/usr/bin/python3
"""An out-of-process dcm provider: a small analytic scene served over the
dcm-pipe protocol (plugins/pipe/PROTOCOL.md) on stdin/stdout.

    dcm pipe --provider-cmd "/usr/bin/python3 analytic_provider.py --width 192 --height 144" -o out.exr

The scene: a background lit by smooth gradients (object 1), a disc with a
checker texture (object 2) and a thin bright diagonal bar (object 3). Every
pixel is closed-form, so the guides are exact and the "render" of a pixel is
cheap; a real renderer would trace rays in `radiance()`.

Debian packages only: /usr/bin/python3 with python3-numpy.
Logging goes to stderr; stdout carries nothing but the protocol.
"""
import argparse
import sys

import numpy as np

PROTOCOL_VERSION = 1
# The sd of one preview sample's L_i (--preview-samples).
PREVIEW_SD = 0.2


class ProtocolError(Exception):
    """A request this provider cannot parse."""


class AnalyticScene:
    """Closed-form guides and radiance of every pixel."""

    def __init__(self, width, height):
        self.width = width
        self.height = height

    def _geometry(self, x, y):
        """Object ID per pixel (numpy arrays of pixel coordinates)."""
        px = x.astype(np.float64) + 0.5
        py = y.astype(np.float64) + 0.5
        cx, cy, r = 0.6 * self.width, 0.5 * self.height, 0.28 * min(self.width, self.height)
        disc = (px - cx) ** 2 + (py - cy) ** 2 < r * r
        # A bar 1.5 px wide along y = 0.35 x + 0.1 h, in front of everything.
        bar = np.abs(py - (0.35 * px + 0.1 * self.height)) < 0.75
        obj = np.where(bar, 3, np.where(disc, 2, 1)).astype(np.uint32)
        return obj

    def guides(self, x, y):
        """(object ID, shader ID, tau) per pixel."""
        obj = self._geometry(x, y)
        shader = np.where(obj == 2, 7, np.where(obj == 3, 9, 3)).astype(np.uint32)
        check = ((x // 8) + (y // 8)) % 2 == 1
        tau = np.ones((x.size, 3), np.float32)
        on_disc = obj == 2
        tau[on_disc & check] = (0.9, 0.7, 0.3)
        tau[on_disc & ~check] = (0.3, 0.5, 0.8)
        return obj, shader, tau

    def split_radiance(self, x, y):
        """(L_i, L_c) per pixel, L = L_i * tau + L_c."""
        obj = self._geometry(x, y)
        u = x.astype(np.float32) / self.width
        v = y.astype(np.float32) / self.height
        li = np.empty((x.size, 3), np.float32)
        lc = np.zeros((x.size, 3), np.float32)
        li[:, 0] = 0.2 + 0.6 * u * u
        li[:, 1] = 0.3 + 0.3 * np.sin(3.0 * v)
        li[:, 2] = 0.5
        disc = obj == 2
        shade = 0.4 + 0.5 * (1.0 - v[disc]) ** 2
        li[disc] = shade[:, None]
        lc[disc, 2] = 0.05 * u[disc]
        lc[disc, 0:2] = 0.02
        bar = obj == 3
        li[bar] = (4.0, 3.5, 2.0)
        return li, lc

    def radiance(self, x, y):
        """L, L_i, L_c per pixel."""
        _, _, tau = self.guides(x, y)
        li, lc = self.split_radiance(x, y)
        return li * tau + lc, li, lc


class Provider:
    """Serves a scene over the dcm-pipe protocol."""

    def __init__(self, scene, name="analytic-python", noise=0.0, normals=False, round_latency=0.0,
                 preview_samples=0):
        self.scene = scene
        self.round_latency = round_latency
        self.preview_samples = preview_samples
        self.name = name
        self.noise = noise
        self.normals = normals
        self.evaluated = 0
        self.batches = 0

    # --- I/O -------------------------------------------------------------
    def read_line(self, inp):
        line = inp.readline()
        if not line:
            return None
        return line.decode("ascii").rstrip("\r\n")

    @staticmethod
    def read_exact(inp, size):
        data = inp.read(size)
        if len(data) != size:
            raise ProtocolError("payload ended after %d of %d bytes" % (len(data), size))
        return data

    # --- the protocol ----------------------------------------------------
    def handshake_line(self):
        caps = ("object_id,shader_id,texture,split" + (",normal" if self.normals else "") +
                (",variance" if self.noise > 0 else ""))
        cost = ""
        if self.round_latency > 0 or self.preview_samples > 0:
            caps += ",preview"
        if self.round_latency > 0:
            cost = " round_latency=%g sample_cost=1e-6" % self.round_latency
        if self.preview_samples > 0:
            cost += " preview_samples=%d" % self.preview_samples
        return "dcm-pipe %d width=%d height=%d caps=%s name=%s%s\n" % (
            PROTOCOL_VERSION, self.scene.width, self.scene.height, caps, self.name, cost)

    def answer_guides(self, tokens, out):
        x0, y0, x1, y1 = (int(t) for t in tokens[1:5])
        kinds = tokens[5].split(",") if len(tokens) > 5 else []
        if not (0 <= x0 < x1 <= self.scene.width and 0 <= y0 < y1 <= self.scene.height):
            raise ProtocolError("guide region outside the image")
        ys, xs = np.mgrid[y0:y1, x0:x1]
        obj, shader, tau = self.scene.guides(xs.ravel(), ys.ravel())
        out.write(b"guides %d\n" % obj.size)
        if "object_id" in kinds:
            out.write(obj.astype("<u4").tobytes())
        if "shader_id" in kinds:
            out.write(shader.astype("<u4").tobytes())
        if "texture" in kinds:
            out.write(tau.astype("<f4").tobytes())
        if "normal" in kinds:
            # The disc faces the camera (z), the background and the bar face up (y).
            normal = np.zeros((obj.size, 3), np.float32)
            normal[obj == 2, 2] = 1.0
            normal[obj != 2, 1] = 1.0
            out.write(normal.astype("<f4").tobytes())

    def answer_eval(self, tokens, inp, out):
        n = int(tokens[1])
        split = len(tokens) > 2 and "split" in tokens[2].split(",")
        xy = np.frombuffer(self.read_exact(inp, 8 * n), dtype="<i4").reshape(n, 2)
        x, y = xy[:, 0], xy[:, 1]
        if n and (x.min() < 0 or y.min() < 0 or x.max() >= self.scene.width or y.max() >= self.scene.height):
            raise ProtocolError("pixel outside the image")
        want_variance = len(tokens) > 2 and "variance" in tokens[2].split(",")
        L, li, lc = self.scene.radiance(x, y)
        if self.noise > 0:
            # A Monte Carlo estimate in miniature: Gaussian noise of sd `noise`
            # on L_i, the same deviate for a pixel in every batch.
            dev = np.array([np.random.default_rng(int(py) * 65536 + int(px)).standard_normal()
                            for px, py in zip(x, y)], np.float32)[:, None]
            tau = self.scene.guides(x, y)[2]
            li = li + self.noise * dev
            L = li * tau + lc
        parts = [L] + ([li, lc] if split else [])
        if want_variance:
            tau = self.scene.guides(x, y)[2]
            parts.append(np.full((n, 3), self.noise ** 2, np.float32) * tau * tau)
        record = np.hstack(parts)
        out.write(b"samples %d\n" % n)
        out.write(record.astype("<f4").tobytes())
        self.evaluated += n
        self.batches += 1

    def answer_preview(self, tokens, out):
        """With --preview-samples N, a Monte Carlo preview in miniature: every
        pixel's L_i with Gaussian noise of sd PREVIEW_SD / sqrt(N), and that
        variance; else a half-resolution preview: each pixel gets its 2x2
        block's top-left value."""
        x0, y0, x1, y1 = (int(t) for t in tokens[1:5])
        if not (0 <= x0 < x1 <= self.scene.width and 0 <= y0 < y1 <= self.scene.height):
            raise ProtocolError("preview region outside the image")
        what = tokens[5].split(",") if len(tokens) > 5 else []
        split = "split" in what
        want_variance = "variance" in what
        if want_variance and not (self.noise > 0 or self.preview_samples > 0):
            raise ProtocolError("preview: variance asked for, and not announced")
        ys, xs = np.mgrid[y0:y1, x0:x1]
        x, y = xs.ravel(), ys.ravel()
        var = np.zeros((x.size, 3), np.float32)
        if self.preview_samples > 0:
            L, li, lc = self.scene.radiance(x, y)
            tau = self.scene.guides(x, y)[2]
            sd = PREVIEW_SD / np.sqrt(self.preview_samples)
            # Another deviate than the exact pixels': the preview's own samples.
            dev = np.array([np.random.default_rng(int(py) * 65536 + int(px) + (1 << 40)).standard_normal()
                            for px, py in zip(x, y)], np.float32)[:, None]
            li = li + sd * dev
            L = li * tau + lc
            var = np.full((x.size, 3), sd * sd, np.float32) * tau * tau
        else:
            L, li, lc = self.scene.radiance(x & ~1, y & ~1)
        out.write(b"samples %d\n" % x.size)
        out.write(np.hstack([L] + ([li, lc] if split else []) + ([var] if want_variance else [])).astype("<f4").tobytes())

    def serve(self, inp, out):
        """Answers requests until 'quit' or end of input; returns the exit status."""
        hello = self.read_line(inp)
        if hello is None or not hello.startswith("dcm-pipe "):
            sys.stderr.write("analytic_provider: expected the dcm-pipe handshake, got %r\n" % hello)
            return 2
        out.write(self.handshake_line().encode("ascii"))
        out.flush()
        while True:
            line = self.read_line(inp)
            if line is None or line == "quit":
                return 0
            tokens = line.split(" ")
            try:
                if tokens[0] == "guides" and len(tokens) >= 5:
                    self.answer_guides(tokens, out)
                elif tokens[0] == "eval" and len(tokens) >= 2:
                    self.answer_eval(tokens, inp, out)
                elif tokens[0] == "preview" and len(tokens) >= 5 and (self.round_latency > 0 or
                                                                       self.preview_samples > 0):
                    self.answer_preview(tokens, out)
                else:
                    raise ProtocolError("unknown request %r" % line[:60])
            except (ProtocolError, ValueError) as e:
                out.write(("error %s\n" % e).encode("ascii", "replace"))
                out.flush()
                return 2
            out.flush()


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--width", type=int, default=192)
    ap.add_argument("--height", type=int, default=144)
    ap.add_argument("--truth", help="write the full image (float32 RGB, row-major, raw) to this file and exit")
    ap.add_argument("--noise", type=float, default=0.0,
                    help="Gaussian noise of this sd on L_i, announced with its variance (a Monte Carlo renderer); "
                         "--truth stays noise-free")
    ap.add_argument("--normals", action="store_true", help="announce and serve normal guides")
    ap.add_argument("--round-latency", type=float, default=0.0,
                    help="announce this latency per round (seconds) and serve a half-resolution preview")
    ap.add_argument("--preview-samples", type=int, default=0,
                    help="serve a noisy full-resolution preview of this many samples per pixel (noise of sd %g "
                         "over their square root on L_i, with its variance) and announce preview_samples=" % PREVIEW_SD)
    ap.add_argument("--count-file", help="at the end, write the number of evaluated pixels to this file")
    args = ap.parse_args(argv)
    scene = AnalyticScene(args.width, args.height)
    if args.truth:
        ys, xs = np.mgrid[0:scene.height, 0:scene.width]
        L, _, _ = scene.radiance(xs.ravel(), ys.ravel())
        L.astype("<f4").tofile(args.truth)
        return 0
    provider = Provider(scene, noise=args.noise, normals=args.normals, round_latency=args.round_latency,
                        preview_samples=args.preview_samples)
    status = provider.serve(sys.stdin.buffer, sys.stdout.buffer)
    sys.stderr.write("analytic_provider: evaluated %d pixels in %d batches\n" % (provider.evaluated, provider.batches))
    if args.count_file:
        with open(args.count_file, "w") as f:
            f.write("%d\n" % provider.evaluated)
    return status


if __name__ == "__main__":
    sys.exit(main())

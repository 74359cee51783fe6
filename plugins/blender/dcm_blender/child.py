"""The dcm-pipe child (plugins/pipe/PROTOCOL.md) inside Blender:

    blender -b SCENE.blend --python plugins/blender/child_main.py -- --protocol-fd 3 [ARGS] 3>&1 1>&2

Blender and Cycles print to stdout, Blender even before it runs any script
(its version, "Read blend: ..."). So the protocol goes to its own descriptor:
the shell gives the child's stdout to fd 3 and points fd 1 at stderr (or at
/dev/null: `dcm blender` without -v; the child's notes go to stderr). Without
--protocol-fd the child takes a private copy of fd 1 and points fd 1 at
stderr, which keeps everything after start-up clean."""
import argparse
import os
import shutil
import sys
import tempfile
import time
import urllib.parse

import numpy as np

from . import scene

CAPS = "object_id,shader_id,texture,normal,split,preview,extra,exact_samples"


def parse_args(argv):
    ap = argparse.ArgumentParser(prog="dcm_blender child")
    ap.add_argument("--samples", type=int, default=0, help="Cycles samples of the exact pixels (0: the file's)")
    ap.add_argument("--preview-samples", type=int, default=0,
                    help="samples of the guides and preview render (0: a sixteenth of --samples, at least 16)")
    ap.add_argument("--frame", type=int, default=None, help="frame to render (default: the file's current)")
    ap.add_argument("--view-layer", default="", help="view layer to render (default: the first that renders)")
    ap.add_argument("--threads", type=int, default=0, help="render threads (0: Blender's choice)")
    ap.add_argument("--variance-halves", action="store_true",
                    help="render exact pixels as two halves of the samples with two seeds; report their variance")
    ap.add_argument("--call-seconds", type=float, default=0.03,
                    help="fixed time of a render call in the running Blender, its render cropped to its "
                         "border (sets how many borders pay off)")
    ap.add_argument("--max-calls", type=int, default=64, help="render calls per round at most")
    ap.add_argument("--border-tile", type=int, default=0,
                    help="tests: render every round within borders over tiles of this size")
    ap.add_argument("--mask-scale", type=int, default=4, help="mask texels per pixel and side")
    ap.add_argument("--masked-min-samples", type=int, default=0,
                    help="samples after which a masked pixel may stop in a round of exact pixels "
                         "(0: 8, which stops at 16; the samples: never)")
    ap.add_argument("--adaptive-threshold", type=float, default=1e-8,
                    help="tests: Cycles' noise threshold in rounds of exact pixels without the keep-alive (exact "
                         "pixels that stop before every sample are rendered again)")
    ap.add_argument("--keep-alive", choices=("auto", "on", "off"), default="auto",
                    help="the keep-alive emission in rounds of exact pixels: where the preview expects pixels "
                         "to stop early (auto), always (on: tests), never (off)")
    ap.add_argument("--workdir", default="",
                    help="scratch folder for masks and renders, made and removed by dcm (default: one of its own)")
    ap.add_argument("--verbose", action="store_true", help="the time of each render call on stderr")
    ap.add_argument("--protocol-fd", type=int, default=-1, help="descriptor of the protocol's output")
    ap.add_argument("--verify-restore", action="store_true",
                    help="fail when the scene after the run differs from the scene before it (tests)")
    ap.add_argument("--keep-renders", default="", help="save every render's passes (npz) in this folder")
    return ap.parse_args(argv)


class Protocol:
    def __init__(self, out_fd):
        self.inp = sys.stdin.buffer
        self.out = os.fdopen(out_fd, "wb")

    def line(self):
        s = self.inp.readline(4097)
        if not s:
            return None
        return s.decode("ascii", "replace").rstrip("\r\n")

    def read(self, n):
        b = self.inp.read(n)
        if len(b) != n:
            raise EOFError("dcm closed the pipe in the middle of a request")
        return b

    def send(self, line, payload=b""):
        self.out.write(line.encode("ascii") + b"\n")
        if payload:
            self.out.write(payload)
        self.out.flush()


def _records(what, L, Li, Lc, var=None, texcov=None):
    parts = [L]
    if "split" in what:
        parts += [Li, Lc]
    if "variance" in what:
        if var is None:
            raise ValueError("eval: variance asked for, and not announced")
        parts.append(var)
    if "texcov" in what:
        if texcov is None:
            raise ValueError("texcov asked for, and not announced")
        parts.append(texcov)
    return np.concatenate(parts, axis=1).astype("<f4").tobytes()


def serve(proto, session):
    while True:
        line = proto.line()
        if line is None or line == "quit":
            return
        t = line.split(" ")
        if t[0] == "guides" and len(t) == 6:
            x0, y0, x1, y1 = (int(v) for v in t[1:5])
            g = session.guides()
            n = (x1 - x0) * (y1 - y0)
            payload = b""
            for kind in ("object_id", "shader_id", "texture", "normal"):
                if kind in t[5].split(","):
                    a = g[kind][y0:y1, x0:x1]
                    payload += a.astype("<u4" if kind.endswith("_id") else "<f4").tobytes()
            proto.send("guides %d" % n, payload)
        elif t[0] == "eval" and len(t) == 3:
            n = int(t[1])
            xy = np.frombuffer(proto.read(8 * n), "<i4").reshape(n, 2)
            xs, ys = xy[:, 0].astype(np.int64), xy[:, 1].astype(np.int64)
            if n and (xs.min() < 0 or ys.min() < 0 or xs.max() >= session.width or ys.max() >= session.height):
                raise ValueError("eval: a pixel outside the %dx%d image" % (session.width, session.height))
            what = t[2].split(",")
            none = np.zeros(0, np.int64), np.zeros(0, np.int64), *(np.zeros((0, 3), np.float32),) * 4
            L, Li, Lc, var, extra = session.evaluate(xs, ys, "variance" in what) if n else (*none[2:], none)
            proto.send("samples %d" % n, _records(what, L, Li, Lc, var))
            # Capability `extra`: the pixels the round rendered exactly besides.
            ex, ey, eL, eLi, eLc, evar = extra
            proto.send("extra %d" % len(ex), np.stack([ex, ey], axis=1).astype("<i4").tobytes()
                       + _records(what, eL, eLi, eLc, evar))
        elif t[0] == "exact_samples" and len(t) == 2:
            session.set_exact_samples(int(t[1]))
            proto.send("exact_samples %d" % session.samples)
        elif t[0] == "preview" and len(t) == 6:
            x0, y0, x1, y1 = (int(v) for v in t[1:5])
            g = session.guides()
            sl = (slice(y0, y1), slice(x0, x1))
            n = (x1 - x0) * (y1 - y0)
            # A preview of one sample has no halves: its variance unknown (NaN, which dcm takes as none).
            flat = [g[k][sl].reshape(n, 3) if k in g else np.full((n, 3), np.nan, np.float32)
                    for k in ("L", "Li", "Lc", "var", "texcov")]
            proto.send("samples %d" % n, _records(t[5].split(","), *flat))
        else:
            raise ValueError("unknown request '%s'" % line[:60])


def main(argv):
    # The protocol's own copy of stdout; Blender's prints go to stderr from now on.
    args = parse_args(argv)
    sys.stdout.flush()
    if args.protocol_fd >= 0:
        out_fd = args.protocol_fd  # fd 1 is what the shell made of it (stderr, or /dev/null)
    else:
        out_fd = os.dup(1)
        os.dup2(2, 1)
    proto = Protocol(out_fd)
    t0 = time.monotonic()
    hello = proto.line()
    if hello is None:
        return 0
    if not hello.startswith("dcm-pipe "):
        proto.send("error expected 'dcm-pipe 1', got '%s'" % hello[:60])
        return 1
    own_workdir = not args.workdir
    workdir = tempfile.mkdtemp(prefix="dcm-blender-") if own_workdir else args.workdir
    session = scene.Session(args, workdir)
    before = session.fingerprint() if args.verify_restore else None
    status = 0
    try:
        session.setup()
        for note in session.notes:
            print("dcm-blender: " + note, file=sys.stderr, flush=True)
        # The guides and preview render first: its time tells what a round costs.
        session.guides()
        latency, per_sample = session.round_cost()
        # view_layer (percent-encoded: names have spaces) and guides_seconds are for `dcm blender`;
        # the preview comes with the guides render, which every schedule pays.
        proto.send("dcm-pipe 1 width=%d height=%d caps=%s name=blender-cycles round_latency=%.4g sample_cost=%.4g "
                   "preview_cost=0 view_layer=%s guides_seconds=%.3f samples=%d preview_samples=%d seeds=%s%s"
                   % (session.width, session.height, CAPS + (",variance,texture_covariance" if session.halves else ""), latency, per_sample,
                      urllib.parse.quote(session.layer.name, safe=""), session.render_seconds[0][1],
                      session.samples, session.preview_samples,
                      ",".join(str(s) for s in session.seeds),
                      "" if session.noise_psnr is None else " noise_psnr=%.2f" % session.noise_psnr))
        serve(proto, session)
    except Exception as e:  # told to dcm, which stops with the message
        msg = " ".join(("%s: %s" % (type(e).__name__, e) if not isinstance(e, scene.SceneError)
                        else str(e)).split())
        try:
            proto.send("error " + msg[:3900])
        except OSError:
            pass
        status = 1
    finally:
        session.restore()
        if own_workdir:
            shutil.rmtree(workdir, ignore_errors=True)
    if before is not None and session.fingerprint() != before:
        import difflib
        diff = difflib.unified_diff(before.splitlines(), session.fingerprint().splitlines(), lineterm="")
        print("dcm-blender: the scene was not restored:\n" + "\n".join(diff), file=sys.stderr)
        status = 3
    if args.verbose:
        for label, s, sync, render in session.render_seconds:
            print("dcm-blender: render %s %.2f s (Cycles: sync %.2f s, render %.2f s)" % (label, s, sync, render),
                  file=sys.stderr)
        print("dcm-blender: %d renders kept their exact pixels sampling (the keep-alive on %d of %d materials, "
              "the others may emit); %d exact pixels stopped early and were rendered again; %d pixels rendered "
              "exactly besides those asked for (their pixel filter's reach inside the mask)"
              % (session.kept_alive_renders, len(session.kept_alive), session.masked_materials,
                 session.rendered_again, session.extra_pixels), file=sys.stderr)
        print("dcm-blender: %.2f s in the child" % (time.monotonic() - t0), file=sys.stderr, flush=True)
    return status

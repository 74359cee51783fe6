#!/usr/bin/python3
"""Merges POV-Ray's full pass renders of examples/povray/scene.pov into one EXR
for `dcm reconstruct` (the dense check set QP of docs/QUALITY.md; made by
scripts/povray_passes.sh). The `merge` of the former examples/povray/povtool.py.

  povray_merge.py [--matte-shaders LIST] OUT.exr ID.exr SHADER.exr TAU.exr NORMAL.exr LI.exr BEAUTY.exr

The inputs are the renders of Declare=Pass=1, 2, 3, 5, 4 and 0. OUT.exr (float)
holds dcm's generic channel names: id, shader, tau.R/G/B, N.X/Y/Z (N from the
slope values v of pass 5 as -cos(pi * v)), Li.R/G/B and R, G, B (L). It checks
the split L = L_i*tau + L_c: L_c = L - L_i*tau (the highlights and reflections)
never below zero beyond half-float rounding, and zero on the matte shaders
(no specular, no reflection: LIST, comma-separated shader IDs, default
scene.pov's 2,3,4,5,9,11; an empty LIST skips that part), and prints the
figures. OUT.exr is written to a temporary name in its folder and renamed.
"""
import os
import signal
import sys
import tempfile

import numpy as np
import OpenImageIO as oiio

# Shaders of scene.pov without specular highlight and reflection.
MATTE_SHADERS = [2, 3, 4, 5, 9, 11]


def fail(msg):
    sys.exit(f"povray_merge: {msg}")


def read(path):
    buf = oiio.ImageBuf(path)
    if buf.has_error:
        fail(f"cannot read {path}: {buf.geterror()}")
    spec = buf.spec()
    px = buf.get_pixels(oiio.FLOAT)
    if px is None:
        fail(f"cannot read {path}: {buf.geterror()}")
    ch = {n: px[:, :, i] for i, n in enumerate(spec.channelnames)}
    if not {"R", "G", "B"} <= ch.keys():
        fail(f"{path} has no R, G, B channels (channels: {', '.join(spec.channelnames)})")
    return ch, spec.width, spec.height


def rgb(ch, base=""):
    return np.stack([ch[base + c] for c in "RGB"], axis=-1)


def write(path, planes, names, fmt="float"):
    """An EXR, written to a temporary name in the same folder and renamed."""
    h, w = planes[0].shape
    data = np.stack(planes, axis=-1).astype(np.float32)
    spec = oiio.ImageSpec(w, h, len(names), fmt)
    spec.channelnames = tuple(names)
    spec.attribute("compression", "zip")
    folder, base = os.path.split(os.path.abspath(path))
    fd, tmp = tempfile.mkstemp(prefix=f".{base}.", suffix=".tmp.exr", dir=folder)
    os.close(fd)
    try:
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)  # mkstemp's 0600 -> what open() would give
        out = oiio.ImageOutput.create(tmp)
        if out is None or not out.open(tmp, spec) or not out.write_image(data) or not out.close():
            fail(f"cannot write {path}: {oiio.geterror()}")
        os.replace(tmp, path)
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)


def merge(out, id_path, shader_path, tau_path, normal_path, li_path, beauty_path, matte_shaders):
    ids, w, h = read(id_path)
    inputs = {}
    for what, path in (("shader", shader_path), ("tau", tau_path), ("normal", normal_path),
                       ("Li", li_path), ("beauty", beauty_path)):
        ch, pw, ph = read(path)
        if (pw, ph) != (w, h):
            fail(f"{path} is {pw}x{ph}, {id_path} is {w}x{h}")
        inputs[what] = ch
    shader, tau, slope, li, beauty = (inputs[k] for k in ("shader", "tau", "normal", "Li", "beauty"))
    for name, ch in (("object ID", ids), ("shader ID", shader)):
        v = ch["R"]
        if not (np.array_equal(v, np.round(v)) and np.array_equal(v, ch["G"]) and np.array_equal(v, ch["B"])):
            fail(f"the {name} pass does not hold one integer per pixel")
    planes = [ids["R"], shader["R"]] + [tau[c] for c in "RGB"]
    planes += [-np.cos(np.pi * np.clip(slope[c], 0.0, 1.0)) for c in "RGB"]
    names = ["id", "shader", "tau.R", "tau.G", "tau.B", "N.X", "N.Y", "N.Z"]
    planes += [li[c] for c in "RGB"] + [beauty[c] for c in "RGB"]
    names += ["Li.R", "Li.G", "Li.B", "R", "G", "B"]
    # The split: L_c = L - L_i*tau must be the highlights and reflections
    # only: never below zero (beyond half-float rounding) and zero on
    # shaders without highlights and reflection.
    t, L, Li = rgb(tau), rgb(beauty), rgb(li)
    Lc = L - Li * t
    # half float: relative rounding 2^-11 of each stored value
    tol = (np.abs(L) + np.abs(Li * t)) * 2.0 ** -10 + 1e-6
    neg = Lc < -tol
    print(f"split: L_c = L - L_i*tau: min {Lc.min():.5f}, max {Lc.max():.4f}; "
          f"{int(neg.any(axis=-1).sum())} pixels below zero beyond half-float rounding")
    bad = bool(neg.any())
    if matte_shaders:
        matte = np.isin(shader["R"], np.array(matte_shaders))
        if not matte.any():
            fail(f"no pixel has a matte shader {matte_shaders} (--matte-shaders)")
        rel = np.abs(Lc[matte]) / (np.abs(L[matte]) + 1e-3)
        print(f"split: on matte shaders {matte_shaders} |L_c| <= {np.abs(Lc[matte]).max():.2e} "
              f"(relative {rel.max():.2e}; half float rounds at {2.0 ** -11:.1e})")
        # L, L_i and tau each carry a half-float rounding of 2^-11 relative:
        # |L_c| / L stays below 3 * 2^-11 = 1.5e-3 where the split is exact;
        # 2^-9 = 2.0e-3 allows that and nothing more.
        if rel.max() > 2.0 ** -9 and not bad:
            fail(f"the split L = L_i*tau + L_c does not hold: L_c is not zero on the matte shaders "
                 f"{matte_shaders} (for another scene than scene.pov give its own with --matte-shaders)")
    if bad:
        fail("the split L = L_i*tau + L_c does not hold: L_c below zero")
    write(out, planes, names)


def main(argv):
    matte = MATTE_SHADERS
    if argv and argv[0].startswith("--matte-shaders"):
        if "=" in argv[0]:
            text, argv = argv[0].split("=", 1)[1], argv[1:]
        elif len(argv) > 1:
            text, argv = argv[1], argv[2:]
        else:
            sys.exit(__doc__)
        try:
            matte = [int(s) for s in text.split(",") if s.strip()]
        except ValueError:
            fail(f"--matte-shaders: not a comma-separated list of integers: {text!r}")
    if len(argv) != 7 or any(a.startswith("-") for a in argv):
        sys.exit(__doc__)
    # A signal leaves no temporary: SystemExit runs write()'s cleanup.
    for s in (signal.SIGTERM, signal.SIGHUP):
        signal.signal(s, lambda n, _f: sys.exit(128 + n))
    merge(*argv, matte)


if __name__ == "__main__":
    try:
        main(sys.argv[1:])
    except KeyboardInterrupt:
        sys.exit(130)

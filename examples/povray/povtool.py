#!/usr/bin/python3
"""Helpers of examples/povray/run.sh (Debian's python3 with numpy and OpenImageIO).

  povtool.py merge OUT.exr ID.exr SHADER.exr TAU.exr NORMAL.exr [LI.exr BEAUTY.exr]
      One multichannel EXR with dcm's generic channel names from POV-Ray's
      pass renders: id, shader, tau.R/G/B, N.X/Y/Z (the guides; N from the
      slope values v of pass 5 as -cos(pi * v)) and, with the last two,
      Li.R/G/B and R, G, B. With L_i and L it checks the split
      L = L_i*tau + L_c (L_c = the highlights and reflections, never negative,
      zero on surfaces without them) and prints the figures.
  povtool.py scatter LIST.txt LI.exr BEAUTY.exr SAMPLES.exr
      The sparse renders of a `dcm plan` list (face i = pixel i of the list,
      at output pixel (i mod W, i div W + 1), W = min(N, frame width): see
      sparse_size) added to the samples EXR of the full frame (created if
      absent): Li.R/G/B, R, G, B (dcm derives L_c = L - L_i*tau, as in dense
      mode) and mask = 1 where rendered. One file with all samples so far, so
      that each `dcm plan` reads one samples file.
  povtool.py check SAMPLES.exr FULL.exr
      The rendered pixels against the full render (the dense-mode input):
      prints "pixels N maxdiff X differing M beyond_1e-3 K".
  povtool.py compare A.exr B.exr
      RGB of two images: prints "maxdiff X differing N rms R".
"""
import os
import sys

import numpy as np
import OpenImageIO as oiio


def read(path):
    buf = oiio.ImageBuf(path)
    if buf.has_error:
        sys.exit(f"povtool: cannot read {path}: {buf.geterror()}")
    spec = buf.spec()
    px = buf.get_pixels(oiio.FLOAT)
    if px is None:
        sys.exit(f"povtool: cannot read {path}: {buf.geterror()}")
    return {n: px[:, :, i] for i, n in enumerate(spec.channelnames)}, spec.width, spec.height


def rgb(ch, base=""):
    return np.stack([ch[base + c] for c in "RGB"], axis=-1)


def write(path, planes, names, fmt="float"):
    """An EXR (float or half), written to a temporary name and renamed."""
    h, w = planes[0].shape
    data = np.stack(planes, axis=-1).astype(np.float32)
    spec = oiio.ImageSpec(w, h, len(names), fmt)
    spec.channelnames = tuple(names)
    spec.attribute("compression", "zip")
    tmp = path + ".tmp.exr"
    out = oiio.ImageOutput.create(tmp)
    if out is None or not out.open(tmp, spec) or not out.write_image(data) or not out.close():
        sys.exit(f"povtool: cannot write {path}: {oiio.geterror()}")
    os.replace(tmp, path)


def read_list(path):
    xs, ys, header = [], [], None
    for line in open(path):
        if line.startswith("#"):
            if "dcm plan:" in line:
                header = line
            continue
        if line.strip():
            x, y = line.split()
            xs.append(int(x))
            ys.append(int(y))
    if header is None:
        sys.exit(f"povtool: {path} is not a `dcm plan` list (no header)")
    size = header.split(" pixels of ")[1].split()[0]
    fw, fh = map(int, size.split("x"))
    channels = header.rsplit("channels: ", 1)[1].strip().split(",")
    return np.array(xs, np.int64), np.array(ys, np.int64), fw, fh, channels


def sparse_size(n, full_w):
    """The image for n mesh_camera faces: width w, one row per w faces plus one.

    POV-Ray 3.7 shifts the pixel y by -0.5 (to the pixel centre) before it
    truncates it to a face row, so output row r traces face row r - 1 and row 0
    repeats face row 0: face k is output pixel (k mod w, k div w + 1). Render
    rows 2.. only (+SR2, 1-based) and read the faces from there."""
    w = min(n, full_w)
    return w, (n + w - 1) // w + 1


def cmd_merge(args):
    out, id_path, shader_path, tau_path, normal_path = args[:5]
    ids, w, h = read(id_path)
    shader, _, _ = read(shader_path)
    tau, _, _ = read(tau_path)
    slope, _, _ = read(normal_path)
    for name, ch in (("object ID", ids), ("shader ID", shader)):
        v = ch["R"]
        if not (np.array_equal(v, np.round(v)) and np.array_equal(v, ch["G"]) and np.array_equal(v, ch["B"])):
            sys.exit(f"povtool: the {name} pass does not hold one integer per pixel")
    planes = [ids["R"], shader["R"]] + [tau[c] for c in "RGB"]
    planes += [-np.cos(np.pi * np.clip(slope[c], 0.0, 1.0)) for c in "RGB"]
    names = ["id", "shader", "tau.R", "tau.G", "tau.B", "N.X", "N.Y", "N.Z"]
    if len(args) > 5:
        li, _, _ = read(args[5])
        beauty, _, _ = read(args[6])
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
        matte = np.isin(shader["R"], np.array(MATTE_SHADERS))
        rel = np.abs(Lc[matte]) / (np.abs(L[matte]) + 1e-3)
        print(f"split: on matte shaders {MATTE_SHADERS} |L_c| <= {np.abs(Lc[matte]).max():.2e} "
              f"(relative {rel.max():.2e}; half float rounds at {2.0 ** -11:.1e})")
        # L, L_i and tau each carry a half-float rounding of 2^-11 relative:
        # |L_c| / L stays below 3 * 2^-11 = 1.5e-3 where the split is exact;
        # 2^-9 = 2.0e-3 allows that and nothing more.
        if neg.any() or rel.max() > 2.0 ** -9:
            sys.exit("povtool: the split L = L_i*tau + L_c does not hold")
    write(out, planes, names)


# Shaders of scene.pov without specular highlight and reflection.
MATTE_SHADERS = [2, 3, 4, 5, 9, 11]


SAMPLE_CHANNELS = ["Li.R", "Li.G", "Li.B", "R", "G", "B"]


def cmd_scatter(args):
    xs, ys, fw, fh, channels = read_list(args[0])
    li, sw, sh = read(args[1])
    beauty, sw2, sh2 = read(args[2])
    acc_path = args[3]
    n = len(xs)
    if (sw, sh) != sparse_size(n, fw) or (sw2, sh2) != (sw, sh):
        sys.exit(f"povtool: sparse renders are {sw}x{sh}, {sw2}x{sh2}; expected {sparse_size(n, fw)}")
    wanted = {c for c in channels if c != "mask"}
    if not wanted <= {"Li.R", "Li.G", "Li.B", "Lc.R", "Lc.G", "Lc.B", "R", "G", "B"}:
        sys.exit(f"povtool: the plan asks for channels this example does not render: {sorted(wanted)}")
    if os.path.exists(acc_path):
        acc, w, h = read(acc_path)
        if (w, h) != (fw, fh):
            sys.exit(f"povtool: {acc_path} is {w}x{h}, the list is for {fw}x{fh}")
        planes = [acc[c].copy() for c in SAMPLE_CHANNELS + ["mask"]]
    else:
        planes = [np.zeros((fh, fw), np.float32) for _ in range(len(SAMPLE_CHANNELS) + 1)]
    if (planes[-1][ys, xs] > 0).any():
        sys.exit("povtool: the list asks for pixels rendered in an earlier round")
    k = np.arange(n)
    fy, fx = k // sw + 1, k % sw  # face k -> output pixel (k mod width, k div width + 1)
    for p, name in zip(planes, SAMPLE_CHANNELS):
        src = li if name.startswith("Li.") else beauty
        p[ys, xs] = src[name[-1]][fy, fx]
    planes[-1][ys, xs] = 1.0
    # POV-Ray's EXRs are half float: half keeps the samples exactly.
    write(acc_path, planes, SAMPLE_CHANNELS + ["mask"], "half")


def cmd_check(args):
    s, _, _ = read(args[0])
    full, _, _ = read(args[1])
    m = s["mask"] > 0
    d = np.zeros(int(m.sum()))
    for name in SAMPLE_CHANNELS:
        d = np.maximum(d, np.abs(s[name][m] - full[name][m]))
    print(f"pixels {int(m.sum())} maxdiff {d.max():.3g} differing {int((d > 0).sum())} "
          f"beyond_1e-3 {int((d > 1e-3).sum())}")


def cmd_compare(args):
    a, _, _ = read(args[0])
    b, _, _ = read(args[1])
    d = np.abs(rgb(a) - rgb(b))
    print(f"maxdiff {d.max():.3g} differing {int((d > 0).any(axis=-1).sum())} "
          f"rms {float(np.sqrt(np.mean(d * d))):.3g}")


if __name__ == "__main__":
    cmds = {"merge": cmd_merge, "scatter": cmd_scatter, "check": cmd_check, "compare": cmd_compare}
    if len(sys.argv) < 2 or sys.argv[1] not in cmds:
        sys.exit(__doc__)
    cmds[sys.argv[1]](sys.argv[2:])

#!/usr/bin/python3
"""Commit-sized error figure for docs/: the error heat maps of `dcm bench`
(dcm, joint bilateral, bilinear at dcm's budget) side by side, each reduced
2x by max pooling (a one-pixel error stays visible) and stored with a
32-colour palette.

    /usr/bin/python3 tools/bench/error_strip.py OUT_DIR SCENE DEST.png
"""
import os
import sys
import tempfile

from PIL import Image, ImageDraw


def main(argv):
    if len(argv) != 4:
        print(__doc__, file=sys.stderr)
        return 2
    out_dir, scene, dest = argv[1:]
    tiles = []
    for what in ("dcm", "jbu", "bilinear"):
        im = Image.open(os.path.join(out_dir, "%s_error_%s.png" % (scene, what))).convert("RGB")
        w, h = im.size
        # Max pooling: take the brightest of each 2x2 block.
        src = Image.open(os.path.join(out_dir, "%s_error_%s.png" % (scene, what))).convert("RGB")
        px = src.load()
        small = Image.new("RGB", (max(1, w // 2), max(1, h // 2)))
        sp = small.load()
        for y in range(small.size[1]):
            for x in range(small.size[0]):
                best = (0, 0, 0)
                for dy in (0, 1):
                    for dx in (0, 1):
                        c = px[min(w - 1, 2 * x + dx), min(h - 1, 2 * y + dy)]
                        if sum(c) > sum(best):
                            best = c
                sp[x, y] = best
        ImageDraw.Draw(small).text((4, 4), what, fill=(255, 255, 255))
        tiles.append(small)
    W = sum(t.size[0] for t in tiles) + 4 * (len(tiles) - 1)
    H = max(t.size[1] for t in tiles)
    strip = Image.new("RGB", (W, H), (255, 255, 255))
    x = 0
    for t in tiles:
        strip.paste(t, (x, 0))
        x += t.size[0] + 4
    strip = strip.quantize(colors=32)
    fd, tmp = tempfile.mkstemp(suffix=".png", dir=os.path.dirname(os.path.abspath(dest)))
    os.close(fd)
    try:
        strip.save(tmp, optimize=True)
        os.chmod(tmp, 0o644)
        os.replace(tmp, dest)
    finally:
        if os.path.exists(tmp):
            os.remove(tmp)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))

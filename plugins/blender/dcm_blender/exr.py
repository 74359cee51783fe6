"""Reads the uncompressed scanline multilayer EXRs that the child makes Blender
write (codec NONE, 32-bit float): a header walk and one numpy view per
channel. Blender 3.4's Python has no EXR reader that returns every pass."""
import struct

import numpy as np

_MAGIC = 20000630
_TYPE_SIZE = {0: 4, 1: 2, 2: 4}  # uint, half, float
_TYPE_DTYPE = {0: "<u4", 1: "<f2", 2: "<f4"}


def _cstring(data, pos):
    end = data.index(b"\0", pos)
    return data[pos:end].decode("latin-1"), end + 1


def read(path):
    """Returns (width, height, {channel name: float32 array [height, width]},
    {string attribute: value}), rows top-down. Raises ValueError naming the file on anything else than an
    uncompressed single-part scanline EXR."""
    with open(path, "rb") as f:
        data = f.read()
    if len(data) < 8 or struct.unpack_from("<i", data, 0)[0] != _MAGIC:
        raise ValueError("%s: not an OpenEXR file" % path)
    flags = struct.unpack_from("<I", data, 4)[0]
    if flags & 0x1a00:  # tiled, deep or multi-part
        raise ValueError("%s: not a single-part scanline EXR" % path)
    pos = 8
    channels, window, compression, strings = [], None, None, {}
    while True:
        name, pos = _cstring(data, pos)
        if not name:
            break
        kind, pos = _cstring(data, pos)
        size = struct.unpack_from("<i", data, pos)[0]
        pos += 4
        value = data[pos:pos + size]
        pos += size
        if name == "channels":
            p = 0
            while value[p] != 0:
                ch, p = _cstring(value, p)
                ptype, _linear, xs, ys = struct.unpack_from("<iB3xii", value, p)
                p += 16
                if xs != 1 or ys != 1:
                    raise ValueError("%s: channel %s is subsampled" % (path, ch))
                channels.append((ch, ptype))
        elif name == "dataWindow":
            window = struct.unpack_from("<iiii", value, 0)
        elif kind == "string":
            strings[name] = value.decode("utf-8", "replace")
        elif name == "compression":
            compression = value[0]
    if window is None or compression != 0:
        raise ValueError("%s: expected an uncompressed EXR with a data window" % path)
    x0, y0, x1, y1 = window
    w, h = x1 - x0 + 1, y1 - y0 + 1
    offsets = np.frombuffer(data, "<u8", h, pos)
    line = sum(_TYPE_SIZE[t] for _, t in channels) * w
    planes = {name: np.empty((h, w), np.float32) for name, _ in channels}
    for off in offsets:
        y, size = struct.unpack_from("<ii", data, int(off))
        if size != line or not y0 <= y <= y1:
            raise ValueError("%s: unexpected scanline block" % path)
        p = int(off) + 8
        for name, t in channels:
            planes[name][y - y0] = np.frombuffer(data, _TYPE_DTYPE[t], w, p)
            p += _TYPE_SIZE[t] * w
    return w, h, planes, strings

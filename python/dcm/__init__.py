"""dcm: reconstruct a render from a few percent of exact pixels (Directional
Coherence Maps, Guo 1998 and Scheel et al. 2001).

    dcm.reconstruct_exr(inputs, preset="blender", **options)
        what `dcm reconstruct` does, on a renderer's EXR AOVs;
    dcm.reconstruct(width, height, guides={...}, evaluate=fn, **options)
        a renderer written in Python: fn(xy) evaluates the pixels the engine asks for.

Both return a Result (.image, .sample_map, .stats). Options take the names of the
C API (dcm/dcm.h): method, contrast_threshold, elementary_block, texture_split, ...
Errors raise dcm.Error (files, channels, the engine), ValueError or TypeError
(arguments), with dcm's message. docs/PYTHON.md has examples.
"""
from ._dcm import REASON_NAMES, Error, Result, __version__, reconstruct, reconstruct_exr

__all__ = ["REASON_NAMES", "Error", "Result", "__version__", "reconstruct", "reconstruct_exr"]

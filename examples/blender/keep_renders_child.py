# dcm blender's child with every render's passes kept (npz, one per render
# call: NN_guides.npz for the preview's halves, NN_evalK.npz for the rounds):
#
#   DCM_BLENDER_CHILD=examples/blender/keep_renders_child.py KEEP_DIR=DIR \
#     dcm blender SCENE.blend -o OUT.exr --sample-map MAP.png
#
# For analysis (preview_floor.py); the result is the same as without.
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "plugins", "blender"))
from dcm_blender import child  # noqa: E402

argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
code = child.main(argv + ["--keep-renders", os.environ["KEEP_DIR"]])
sys.stderr.flush()
os._exit(code)

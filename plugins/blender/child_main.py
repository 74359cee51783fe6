# Entry of the dcm-pipe child inside Blender (what `dcm blender` runs):
#   blender -b SCENE.blend --python child_main.py -- [ARGS of dcm_blender.child]
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from dcm_blender import child  # noqa: E402

argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
code = child.main(argv)
sys.stderr.flush()
os._exit(code)  # Blender would go on with its own command line and print "Blender quit" to stdout

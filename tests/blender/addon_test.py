"""Runs addon_in_blender.py inside Blender (exit 77 without Blender) with a
private user folder, so that the user's add-ons stay untouched, and a scratch
folder that is removed afterwards.

    /usr/bin/python3 addon_test.py BLENDER ZIP DCM"""
import os
import shutil
import subprocess
import sys
import tempfile

blender, zip_path, dcm = sys.argv[1:4]
script = os.path.join(os.path.dirname(os.path.abspath(__file__)), "addon_in_blender.py")
if not shutil.which(blender):
    print("blender not found: skipped")
    sys.exit(77)
work = tempfile.mkdtemp(prefix="dcm-addon-test-")
# The add-on's scratch folders go here, so that the test sees they are removed.
env = dict(os.environ, TMPDIR=os.path.join(work, "tmp"), BLENDER_USER_CONFIG=os.path.join(work, "config"),
           BLENDER_USER_SCRIPTS=os.path.join(work, "scripts"), BLENDER_USER_DATAFILES=os.path.join(work, "data"))
os.mkdir(env["TMPDIR"])
try:
    r = subprocess.run([blender, "-b", "--factory-startup", "--python-exit-code", "1", "--python", script,
                        "--", zip_path, dcm, work], timeout=220, env=env)
    sys.exit(r.returncode)
finally:
    shutil.rmtree(work, ignore_errors=True)

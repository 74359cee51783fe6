"""The add-on zip the build makes, in a Blender with a private user folder:
it installs, enables, registers "Render with DCM" in the Render menu and the
DCM panel, and the `dcm blender` command its operator runs renders the open
file's saved copy; disabling removes its settings.

    /usr/bin/python3 addon_test.py DCM BLENDER SOURCE_DIR ZIP"""
import os
import shutil
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import blender_support as bs  # noqa: E402


def main():
    dcm, blender, src, zip_path = sys.argv[1:5]
    if not shutil.which(blender):
        print("blender not found: skipped")
        return 77
    tmp = tempfile.mkdtemp(prefix="dcm-blender-addon-test-")
    try:
        blend = bs.make_scene(blender, src, tmp)
        # The user's own configuration and add-ons stay untouched.
        env = dict(os.environ, BLENDER_USER_CONFIG=os.path.join(tmp, "config"),
                   BLENDER_USER_SCRIPTS=os.path.join(tmp, "scripts"))
        p = subprocess.run([blender, "-b", blend, "--python", os.path.join(src, "tests/blender/addon_check.py"),
                            "--", zip_path, dcm, tmp], env=env, capture_output=True, text=True, timeout=110)
        if p.returncode != 0 or "addon ok" not in p.stdout:
            print(p.stdout[-3000:], p.stderr[-3000:])
            return 1
        img, spec = bs.read_exr(os.path.join(tmp, "addon.exr"))
        assert img.shape[:2] == (48, 64) and "ViewLayer.Combined.A" in spec.channelnames, spec.channelnames
        print("ok")
        return 0
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


if __name__ == "__main__":
    sys.exit(main())

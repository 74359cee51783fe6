"""The add-on's runner without Blender: the dcm command line it builds, the
progress lines it reads, and a cancel that stops the whole process group."""
import os
import sys
import time

sys.path.insert(0, os.path.join(sys.argv[1], "plugins", "blender", "dcm_blender"))
import runner  # noqa: E402


def check(cond, what):
    if not cond:
        print("FAILED:", what)
        sys.exit(1)
    print("ok:", what)


cmd = runner.command_line("/x/dcm", "/s/a b.blend", "/o/out.exr", blender="/usr/bin/blender", samples=64,
                          preview_samples=8, method="paper", threshold=0.1, schedule="preview", max_rounds=2,
                          view_layer="ViewLayer", frame=7, extra="--threads 2 --crease-angle 45")
check(cmd[:5] == ["/x/dcm", "blender", "/s/a b.blend", "-o", "/o/out.exr"], "scene and output first: %s" % cmd)
for pair in (["--samples", "64"], ["--preview-samples", "8"], ["--method", "paper"], ["--threshold", "0.1"], ["--schedule", "preview"], ["--max-rounds", "2"],
             ["--view-layer", "ViewLayer"], ["--frames", "7"], ["--threads", "2"], ["--crease-angle", "45"]):
    i = cmd.index(pair[0]) if pair[0] in cmd else -1
    check(i >= 0 and cmd[i:i + 2] == pair, "flag %s" % pair)
check("--full" not in cmd and "--method" not in runner.command_line("d", "s", "o"), "defaults add no flags")
check("--samples" not in runner.command_line("d", "s", "o"), "samples 0: the scene's")
t = runner.command_line("d", "s", "o", target_psnr=40)
check(t[t.index("--target-psnr") + 1] == "40.0" and "--threshold" not in t, "a target instead of a threshold: %s" % t)
check("--preview-correction" not in runner.command_line("d", "s", "o") and
      runner.command_line("d", "s", "o", preview_correction=False)[-2:] == ["--preview-correction", "0"],
      "the preview correction: dcm's default, or off")
check("--preview-filter" not in runner.command_line("d", "s", "o") and
      runner.command_line("d", "s", "o", preview_filter=False)[-2:] == ["--preview-filter", "0"],
      "the preview filter: dcm's default, or off")
check("--fixed-samples" not in runner.command_line("d", "s", "o") and
      "--fixed-samples" in runner.command_line("d", "s", "o", fixed_samples=True),
      "the exact pixels' samples: dcm's choice, or every sample")
check(runner.parse_progress("rounds  42% (3.5 s)") == ("rounds", 0.42), "a progress line")
check(runner.parse_progress("\r\x1b[Kengine 100% (0.1 s)") == ("engine", 1.0), "a terminal progress line")
check(runner.parse_progress("dcm blender: error: x") is None, "an error line is no progress")

# A cancel ends the process and its children (dcm's Blender runs in its session).
run = runner.Run(["/bin/sh", "-c", "sleep 60 & sleep 60; wait"])
time.sleep(0.3)
start = time.time()
run.cancel()
check(run.poll() is not None and time.time() - start < 5, "cancel ends the run at once")
alive = True
for _ in range(50):  # the orphaned sleep dies of the same SIGTERM, a moment later
    try:
        os.killpg(run.proc.pid, 0)
        time.sleep(0.05)
    except ProcessLookupError:
        alive = False
        break
check(not alive, "no process of its group is left")
run = runner.Run(["/bin/sh", "-c", "echo 'render 50% (1.0 s)' >&2; echo 'dcm: error: step x' >&2; exit 3"])
check(run.wait() == 3 and "step x" in run.error_text() and run.fraction == 0.5, "exit code, message, progress")
print("runner_test: all checks passed")

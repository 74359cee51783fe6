#!/usr/bin/python3
"""The analytic provider of examples/provider-python, made hostile for the
tests of tests/robustness/hostile_output_test.cpp:

    hostile_provider.py MODE PID_FILE [--width W] [--height H]

It writes its own process id to PID_FILE (one line, then in mode grandchild
a second line with the pid of its grandchild), then serves the scene.

MODE:
    ok          no fault
    huge        answers every sample with L = -3e38 (a finite float32)
    grandchild  sleeps 0.3 s before each batch of samples (time to send dcm
                a signal mid-run), and starts a `sleep 600` grandchild that
                stays in the provider's process group (a renderer's helper)
"""
import os
import subprocess
import sys
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "examples",
                                "provider-python"))
import analytic_provider as ap  # noqa: E402
import numpy as np  # noqa: E402


class Hostile(ap.Provider):
    def __init__(self, scene, mode):
        super().__init__(scene)
        self.mode = mode

    def answer_eval(self, tokens, inp, out):
        if self.mode == "grandchild":
            time.sleep(0.3)
        if self.mode != "huge":
            return super().answer_eval(tokens, inp, out)
        n = int(tokens[1])
        split = len(tokens) > 2 and "split" in tokens[2].split(",")
        self.read_exact(inp, 8 * n)
        per = 9 if split else 3
        out.write(b"samples %d\n" % n)
        out.write(np.full((n, per), -3e38, np.float32).astype("<f4").tobytes())


def main():
    mode, pid_file = sys.argv[1], sys.argv[2]
    import argparse
    p = argparse.ArgumentParser()
    p.add_argument("--width", type=int, default=64)
    p.add_argument("--height", type=int, default=48)
    args = p.parse_args(sys.argv[3:])
    pids = [os.getpid()]
    if mode == "grandchild":
        pids.append(subprocess.Popen(["sleep", "600"], stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL).pid)
    with open(pid_file + ".tmp", "w") as f:
        f.write("".join("%d\n" % q for q in pids))
    os.rename(pid_file + ".tmp", pid_file)
    provider = Hostile(ap.AnalyticScene(args.width, args.height), mode)
    return provider.serve(sys.stdin.buffer, sys.stdout.buffer)


if __name__ == "__main__":
    sys.exit(main())

#!/usr/bin/python3
"""The analytic provider of examples/provider-python with one fault, to test
how dcm handles a misbehaving child:

    faulty_provider.py MODE [analytic_provider options]

MODE (the fault happens at the first request of its kind):
    ok                  no fault
    crash-on-eval       killed by SIGSEGV instead of answering
    exit-on-eval        exits with status 3 without answering
    garbage-on-eval     answers with binary garbage
    garbage-handshake   answers the handshake with a line of text that is not one
    wrong-count         answers 'samples N-1' with N-1 records
    short-payload       answers 'samples N' with half the bytes, then exits 0
    hang-on-eval        never answers (sleeps)
    error-on-guides     answers 'error ...' to the guide request
    bad-version         announces protocol version 99
    long-line           sends 10000 bytes without a newline
    exit-after-quit     exits with status 5 after 'quit'
"""
import os
import signal
import sys
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "examples",
                                "provider-python"))
import analytic_provider as ap  # noqa: E402


class Faulty(ap.Provider):
    def __init__(self, scene, mode):
        super().__init__(scene)
        self.mode = mode

    def handshake_line(self):
        if self.mode == "garbage-handshake":
            return "HELLO I am a renderer\n"
        if self.mode == "bad-version":
            return "dcm-pipe 99 width=%d height=%d\n" % (self.scene.width, self.scene.height)
        if self.mode == "long-line":
            return "x" * 10000
        return super().handshake_line()

    def answer_guides(self, tokens, out):
        if self.mode == "error-on-guides":
            out.write(b"error scene file 'missing.scn' not found\n")
            return
        super().answer_guides(tokens, out)

    def answer_eval(self, tokens, inp, out):
        n = int(tokens[1])
        if self.mode == "crash-on-eval":
            sys.stdout.flush()
            os.kill(os.getpid(), signal.SIGSEGV)
        if self.mode == "exit-on-eval":
            os._exit(3)
        if self.mode == "garbage-on-eval":
            out.write(b"\x00\xff\x13garbage \x80\x81\n")
            return
        if self.mode == "hang-on-eval":
            time.sleep(120)
        if self.mode in ("wrong-count", "short-payload"):
            self.read_exact(inp, 8 * n)
            split = len(tokens) > 2 and "split" in tokens[2]
            per = 9 if split else 3
            if self.mode == "wrong-count":
                out.write(b"samples %d\n" % (n - 1))
                out.write(b"\0" * (4 * per * (n - 1)))
            else:
                out.write(b"samples %d\n" % n)
                out.write(b"\0" * (4 * per * n // 2))
                out.flush()
                os._exit(0)
            return
        super().answer_eval(tokens, inp, out)


def main():
    mode = sys.argv[1]
    import argparse
    p = argparse.ArgumentParser()
    p.add_argument("--width", type=int, default=64)
    p.add_argument("--height", type=int, default=48)
    args = p.parse_args(sys.argv[2:])
    provider = Faulty(ap.AnalyticScene(args.width, args.height), mode)
    status = provider.serve(sys.stdin.buffer, sys.stdout.buffer)
    if mode == "exit-after-quit":
        return 5
    return status


if __name__ == "__main__":
    sys.exit(main())

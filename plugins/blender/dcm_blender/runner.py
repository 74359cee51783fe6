"""Runs `dcm blender` for the add-on: the command line from the settings, the
process in its own session (so that a cancel stops Blender's render child
too), its progress read from stderr. No bpy here: the tests drive it alone."""
import os
import re
import shlex
import signal
import subprocess
import threading

# dcm's progress lines: "<stage> <percent>% (<seconds> s)" (tools/common/progress.cpp).
_PROGRESS = re.compile(r"^(?P<stage>.*?)\s+(?P<percent>\d{1,3})% \((?P<seconds>[0-9.]+) s\)\s*$")


def command_line(dcm, scene_file, output, *, blender=None, stats=None, samples=0, preview_samples=0,
                 method="dcm", full=False, threshold=None, target_psnr=None, schedule="auto", max_rounds=3,
                 preview_correction=True, preview_filter=True, fixed_samples=False, view_layer=None, frame=None,
                 sample_map=None, extra=""):
    """The `dcm blender` command for one render of `scene_file` into `output`."""
    cmd = [dcm, "blender", scene_file, "-o", output]
    if blender:
        cmd += ["--blender", blender]
    if stats:
        cmd += ["--stats", stats]
    if sample_map:
        cmd += ["--sample-map", sample_map]
    if samples:
        cmd += ["--samples", str(int(samples))]
    if preview_samples:
        cmd += ["--preview-samples", str(int(preview_samples))]
    if method != "dcm":
        cmd += ["--method", method]
    if full:
        cmd += ["--full"]
    if threshold is not None:
        cmd += ["--threshold", repr(float(threshold))]
    if target_psnr is not None:
        cmd += ["--target-psnr", repr(float(target_psnr))]
    cmd += ["--schedule", schedule, "--max-rounds", str(int(max_rounds))]
    if not preview_correction:
        cmd += ["--preview-correction", "0"]
    if not preview_filter:
        cmd += ["--preview-filter", "0"]
    if fixed_samples:
        cmd += ["--fixed-samples"]
    if view_layer:
        cmd += ["--view-layer", view_layer]
    if frame is not None:
        cmd += ["--frames", str(int(frame))]
    cmd += shlex.split(extra or "")
    return cmd


def parse_progress(line):
    """(stage, fraction) of a dcm progress line, or None."""
    m = _PROGRESS.match(line.strip("\r\n").split("\r")[-1].replace("\x1b[K", ""))
    if not m:
        return None
    return m.group("stage").strip(), min(int(m.group("percent")), 100) / 100.0


class Run:
    """One `dcm blender` process: started at once, polled, cancelled."""

    def __init__(self, cmd, env=None):
        self.cmd = cmd
        self.lines = []
        self.stage, self.fraction = "starting", 0.0
        self._lock = threading.Lock()
        self.proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, env=env,
                                     start_new_session=True)
        self._readers = [threading.Thread(target=self._read, args=(s,), daemon=True)
                         for s in (self.proc.stdout, self.proc.stderr)]
        for t in self._readers:
            t.start()

    def _read(self, stream):
        # Progress on a terminal ends in "\r"; from a pipe each update is a line.
        for raw in iter(stream.readline, b""):
            text = raw.decode("utf-8", "replace")
            for part in text.replace("\r", "\n").splitlines():
                if not part.strip():
                    continue
                with self._lock:
                    p = parse_progress(part)
                    if p:
                        self.stage, self.fraction = p
                    else:
                        self.lines.append(part.replace("\x1b[K", ""))

    def poll(self):
        """The exit code, or None while it runs."""
        return self.proc.poll()

    def wait(self):
        code = self.proc.wait()
        for t in self._readers:
            t.join(timeout=5)
        return code

    def cancel(self):
        """SIGTERM to dcm's session: dcm removes its temporaries and its Blender child."""
        if self.proc.poll() is None:
            try:
                os.killpg(self.proc.pid, signal.SIGTERM)
            except ProcessLookupError:
                pass
        try:
            self.proc.wait(timeout=10)
        except subprocess.TimeoutExpired:
            os.killpg(self.proc.pid, signal.SIGKILL)
            self.proc.wait()

    def error_text(self):
        """The lines dcm printed that are not progress (its error names the step)."""
        with self._lock:
            return "\n".join(self.lines[-8:])

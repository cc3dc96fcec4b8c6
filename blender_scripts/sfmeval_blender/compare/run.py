"""A pipeline run: ``sfmeval-runner run`` as a subprocess in a session of its own, read line by
line without blocking, and a cancel that ends the runner and the tools it started (the runner
puts every tool in a process group of its own, so the whole tree's groups are signalled)."""

import json
import os
import queue
import signal
import subprocess
import threading
import time


def list_pipelines(runner, timeout=120):
    """``sfmeval-runner pipelines --json``: [{"name", "installed", "detail"}]."""
    proc = subprocess.run([runner, "pipelines", "--json"], capture_output=True, text=True,
                          timeout=timeout)
    if proc.returncode != 0:
        raise RuntimeError("%s pipelines --json failed: %s" % (runner, proc.stderr.strip()[-500:]))
    try:
        return json.loads(proc.stdout)
    except ValueError as exc:
        raise RuntimeError("%s pipelines --json printed no JSON (an older runner? rebuild it): %s"
                           % (runner, exc))


def run_command(runner, dataset, out, pipeline, timeout, intrinsics):
    """The argv of one run: results land in ``out/<dataset name>/<pipeline>/``."""
    return [runner, "run", "--datasets", dataset, "--out", out, "--pipelines", pipeline,
            "--timeout", str(timeout), "--intrinsics", intrinsics]


def run_folder(dataset, out, pipeline):
    """Where the runner writes the run of `pipeline` on `dataset` (see native_runner/README.md)."""
    return os.path.join(out, os.path.basename(os.path.normpath(dataset)), pipeline)


def run_status(folder):
    """(status, reason) of a finished run from its run.json (sfmeval.run/1)."""
    path = os.path.join(folder, "run.json")
    try:
        with open(path) as f:
            rec = json.load(f)
    except (OSError, ValueError) as exc:
        return "failed", "no readable run.json in %s: %s" % (folder, exc)
    return rec.get("status", "failed"), rec.get("reason") or ""


def _descendant_groups(pid):
    """Process groups of `pid`'s descendants (Linux /proc), so tools in groups of their own end
    too."""
    children = {}
    for entry in os.listdir("/proc"):
        if not entry.isdigit():
            continue
        try:
            with open("/proc/%s/stat" % entry) as f:
                stat = f.read()
        except OSError:
            continue
        fields = stat[stat.rfind(")") + 2:].split()
        children.setdefault(int(fields[1]), []).append((int(entry), int(fields[2])))
    groups, todo = set(), [pid]
    while todo:
        for child, pgid in children.get(todo.pop(), []):
            groups.add(pgid)
            todo.append(child)
    return groups


class Job:
    """One subprocess; `poll()` returns new output lines and the exit code (None while running)."""

    def __init__(self, argv, cwd=None):
        self.argv = argv
        self.start = time.monotonic()
        self.end = None
        self.proc = subprocess.Popen(argv, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                                     stdin=subprocess.DEVNULL, text=True, errors="replace",
                                     start_new_session=True, cwd=cwd)
        self._lines = queue.Queue()
        self._reader = threading.Thread(target=self._read, daemon=True)
        self._reader.start()

    def _read(self):
        for line in self.proc.stdout:
            self._lines.put(line.rstrip("\n"))
        self.proc.stdout.close()

    def elapsed(self):
        return (self.end or time.monotonic()) - self.start

    def poll(self):
        rc = self.proc.poll()
        if rc is not None:
            self._reader.join(timeout=5)
            if self.end is None:
                self.end = time.monotonic()
        lines = []
        while True:
            try:
                lines.append(self._lines.get_nowait())
            except queue.Empty:
                break
        return lines, rc

    def cancel(self, grace=3.0):
        """SIGTERM to the runner's group and its tools' groups, SIGKILL after `grace` seconds."""
        if self.proc.poll() is not None:
            return
        groups = _descendant_groups(self.proc.pid) - {self.proc.pid}
        for sig in (signal.SIGTERM, signal.SIGKILL):
            # The runner's own group first: signalled after a tool, it could see the tool die
            # and record the run as failed (run.json) before its own signal arrived.
            for g in [self.proc.pid, *sorted(groups)]:
                try:
                    os.killpg(g, sig)
                except (ProcessLookupError, PermissionError):
                    pass
            try:
                self.proc.wait(timeout=grace)
                break
            except subprocess.TimeoutExpired:
                groups |= _descendant_groups(self.proc.pid)
        self.proc.wait()

"""A one-node Slurm cluster on this machine for the tests: Debian's slurm-wlm (22.05) and munge,
started from nothing in a temporary folder and stopped by the PIDs it wrote.

- munged: its own key (1024 random bytes), socket, PID, log and seed files in the folder, so
  it neither needs nor touches /etc/munge or a munged already running;
- slurmctld + slurmd: one node (this host, its CPUs), `ProctrackType=proctrack/linuxproc`,
  `TaskPlugin=task/none`, state, spool, logs and PID files in the folder, on two free ports,
  authenticating through that munged (`AuthInfo=socket=...`);
- the client commands (sbatch, squeue, scancel) find it through `SLURM_CONF`.

`start(folder)` returns a `Cluster`; `Cluster.stop()` cancels what is left in its queue and
ends the three daemons by their PIDs (SIGTERM, then SIGKILL after 10 s). A missing program is
a pytest skip naming it (scripts/test.sh counts a skip as a failure under CI=true).
"""

import os
import shutil
import signal
import socket
import subprocess
import time

import pytest

PROGRAMS = ["munged", "munge", "unmunge", "slurmctld", "slurmd", "sbatch", "squeue", "scancel", "sinfo"]


def require_programs():
    missing = [p for p in PROGRAMS if shutil.which(p) is None
               and not os.path.exists("/usr/sbin/" + p)]
    if missing:
        pytest.skip("Slurm/munge not installed (%s): apt-get install slurm-wlm munge "
                    "(requirements/apt-slurm.txt)" % ", ".join(missing))


def which(p):
    return shutil.which(p) or "/usr/sbin/" + p


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def read_pid(path):
    try:
        with open(path) as f:
            return int(f.read().split()[0])
    except (OSError, ValueError, IndexError):
        return None


def stop_pid(pid, timeout=10.0):
    if pid is None:
        return
    try:
        os.kill(pid, signal.SIGTERM)
    except ProcessLookupError:
        return
    deadline = time.time() + timeout
    while time.time() < deadline:
        try:
            os.kill(pid, 0)
        except ProcessLookupError:
            return
        time.sleep(0.1)
    try:
        os.kill(pid, signal.SIGKILL)
    except ProcessLookupError:
        pass


class Cluster:
    def __init__(self, root):
        self.root = root
        self.conf = os.path.join(root, "slurm.conf")
        self.env = dict(os.environ, SLURM_CONF=self.conf)

    def cmd(self, *args, check=True, timeout=60):
        proc = subprocess.run([which(args[0])] + [str(a) for a in args[1:]], env=self.env,
                              stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                              timeout=timeout)
        if check:
            assert proc.returncode == 0, "%s: %s%s" % (args, proc.stdout, proc.stderr)
        return proc

    def jobs(self):
        """{"JOBID_TASK" or "JOBID": state} of the queue."""
        out = self.cmd("squeue", "-h", "-r", "-o", "%i %T").stdout
        return dict(line.split() for line in out.splitlines() if line.strip())

    def wait_idle(self, timeout):
        """Waits until the queue is empty; returns the seconds waited."""
        t0 = time.time()
        while time.time() - t0 < timeout:
            if not self.jobs():
                return time.time() - t0
            time.sleep(0.5)
        raise AssertionError("the Slurm queue is not empty after %.0f s: %s\n%s"
                             % (timeout, self.jobs(), self.log_tail()))

    def log_tail(self):
        out = []
        for n in ("slurmctld.log", "slurmd.log"):
            p = os.path.join(self.root, n)
            if os.path.exists(p):
                with open(p, errors="replace") as f:
                    out.append("--- %s\n%s" % (n, "".join(f.readlines()[-15:])))
        return "\n".join(out)

    def stop(self):
        if os.path.exists(os.path.join(self.root, "slurmctld.pid")):
            subprocess.run([which("scancel"), "--full", "-u", str(os.getuid())], env=self.env,
                           stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, timeout=30)
            deadline = time.time() + 20
            while time.time() < deadline:
                try:
                    if not self.jobs():
                        break
                except (AssertionError, subprocess.SubprocessError):
                    break
                time.sleep(0.5)
        for name in ("slurmd.pid", "slurmctld.pid", os.path.join("munge", "munged.pid")):
            stop_pid(read_pid(os.path.join(self.root, name)))


def start(root, memory_mb=8000):
    """Starts munged, slurmctld and slurmd with everything under `root`; waits until the node
    is idle. Stops whatever it started if that fails."""
    require_programs()
    host = socket.gethostname().split(".")[0]
    cpus = os.cpu_count() or 1
    munge_dir = os.path.join(root, "munge")
    os.makedirs(munge_dir, mode=0o755)
    os.chmod(root, 0o755)
    key = os.path.join(munge_dir, "munge.key")
    with open(key, "wb") as f:
        f.write(os.urandom(1024))
    os.chmod(key, 0o400)
    sock = os.path.join(munge_dir, "munge.socket")
    cluster = Cluster(root)
    for d in ("spool", "state"):
        os.makedirs(os.path.join(root, d))
    conf = {
        "ClusterName": "sfmevaltest", "SlurmctldHost": host,
        "SlurmctldPort": free_port(), "SlurmdPort": free_port(),
        "AuthType": "auth/munge", "CredType": "cred/munge", "AuthInfo": "socket=" + sock,
        "ProctrackType": "proctrack/linuxproc", "TaskPlugin": "task/none",
        "SchedulerType": "sched/backfill", "SelectType": "select/cons_tres",
        "SelectTypeParameters": "CR_Core", "ReturnToService": 2, "SlurmUser": "root",
        "SlurmdUser": "root", "MpiDefault": "none",
        "SlurmctldPidFile": os.path.join(root, "slurmctld.pid"),
        "SlurmdPidFile": os.path.join(root, "slurmd.pid"),
        "SlurmdSpoolDir": os.path.join(root, "spool"),
        "StateSaveLocation": os.path.join(root, "state"),
        "SlurmctldLogFile": os.path.join(root, "slurmctld.log"),
        "SlurmdLogFile": os.path.join(root, "slurmd.log"),
    }
    with open(cluster.conf, "w") as f:
        for k, v in conf.items():
            f.write("%s=%s\n" % (k, v))
        f.write("NodeName=%s CPUs=%d RealMemory=%d State=UNKNOWN\n" % (host, cpus, memory_mb))
        f.write("PartitionName=debug Nodes=%s Default=YES MaxTime=INFINITE State=UP\n" % host)
    try:
        subprocess.run([which("munged"), "--force", "--socket=" + sock, "--key-file=" + key,
                        "--pid-file=" + os.path.join(munge_dir, "munged.pid"),
                        "--log-file=" + os.path.join(munge_dir, "munged.log"),
                        "--seed-file=" + os.path.join(munge_dir, "munged.seed")],
                       check=True, timeout=30)
        cred = subprocess.run([which("munge"), "-S", sock, "-n"], stdout=subprocess.PIPE,
                              check=True, timeout=30).stdout
        check = subprocess.run([which("unmunge"), "-S", sock], input=cred,
                               stdout=subprocess.PIPE, timeout=30)
        assert b"Success" in check.stdout, check.stdout
        cluster.cmd("slurmctld", "-f", cluster.conf)
        cluster.cmd("slurmd", "-f", cluster.conf)
        deadline = time.time() + 60
        while True:
            state = cluster.cmd("sinfo", "-h", "-o", "%t", check=False).stdout.strip()
            if state == "idle":
                break
            assert time.time() < deadline, "node not idle after 60 s (%r)\n%s" % (
                state, cluster.log_tail())
            time.sleep(0.5)
    except BaseException:
        cluster.stop()
        raise
    return cluster

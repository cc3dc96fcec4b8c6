"""Slurm defects of `--executor slurm`, each on the real one-node Slurm cluster that
slurm_testlib starts (slurmctld + slurmd + munged in a temporary folder):

- a submission that fails part-way (an `--sbatch` wrapper that fails on its second call)
  records the job it had queued, so `--resume` (and the same command) refuse while it is
  queued instead of submitting its tasks again; once it has left the queue the same command
  submits what is missing;
- a first submission that failed (the wrapper fails on its first call) is retried by the same
  command, without --resume;
- a request above what the partition's nodes have (CPUs, memory) is refused before anything
  is submitted, naming the stage and the nodes' size;
- a task whose runner is killed with SIGKILL (as the kernel's OOM killer does) has its tool's
  process group ended by the task's script, and its cell says so with Slurm's job state and
  exit signal.

No rendering and no SfM tool: `run` batches on a folder with one placeholder image, with a
custom pipeline that sleeps (`--hold` in the wrapper keeps the jobs pending where they need
not run). Measured here (2 vCPUs, loaded): ~20 s for the four tests, half of it the cluster's
start and the SIGKILL test's collect."""

import os
import signal
import stat
import time

import pytest

import slurm_testlib
from runner_testlib import load, run_cli

HANG = ["--pipelines", "hang", "--custom", "hang=sleep 300; echo {out}"]
SMALL = ["--stage", "run:cpus=1,mem=100M,time=10", "--stage", "collect:cpus=1,mem=500M"]


@pytest.fixture(scope="module")
def cluster(tmp_path_factory):
    c = slurm_testlib.start(str(tmp_path_factory.mktemp("slurm-cluster")))
    yield c
    c.stop()


def dataset(root, name):
    d = root / name
    (d / "images").mkdir(parents=True)
    (d / "images" / "0000.png").write_bytes(b"\x89PNG placeholder")
    return d


def wrapper(tmp_path, fail_on, hold=True):
    """An sbatch that fails on its `fail_on`-th call (counted in a file beside it) and passes
    every other call to the real sbatch (with --hold: the jobs stay pending)."""
    w = tmp_path / "bin" / "sbatch"
    w.parent.mkdir(exist_ok=True)
    w.write_text(
        "#!/bin/bash\n"
        "n=$(( $(cat %(c)s 2>/dev/null || echo 0) + 1 )); echo $n > %(c)s\n"
        "if [ $n -eq %(f)d ]; then echo 'sbatch: error: Batch job submission failed: "
        "Socket timed out on send/recv operation' >&2; exit 1; fi\n"
        "exec %(sbatch)s %(hold)s \"$@\"\n"
        % {"c": tmp_path / "bin" / "calls", "f": fail_on, "sbatch": slurm_testlib.which("sbatch"),
           "hold": "--hold" if hold else ""})
    w.chmod(w.stat().st_mode | stat.S_IXUSR)
    return str(w)


def queue_of(cluster):
    """The array job ids in the queue (`%F`: an array's tasks under the array's id)."""
    out = cluster.cmd("squeue", "-h", "-o", "%F").stdout
    return sorted(set(l.strip() for l in out.splitlines() if l.strip()))


def cancel_all(cluster):
    cluster.cmd("scancel", "-u", str(os.getuid()))
    cluster.wait_idle(60)


def test_a_submission_failing_part_way_records_what_it_queued(runner_bin, cluster, tmp_path):
    d1, d2 = dataset(tmp_path, "d1"), dataset(tmp_path, "d2")
    out = tmp_path / "out"
    env = {"SLURM_CONF": cluster.conf}
    cmd = ["run", "--datasets", d1, d2, *HANG, "--out", out, "--executor", "slurm", *SMALL,
           "--sbatch", wrapper(tmp_path, fail_on=2)]
    p = run_cli(runner_bin, *cmd, env=env, check=False)
    assert p.returncode == 1 and "already queued and recorded" in p.stderr, p.stderr
    recs = load(out / "slurm" / "jobs.json")
    assert len(recs) == 1 and recs[0]["complete"] is False
    assert [(s["label"], s["tasks"]) for s in recs[0]["stages"]] == [("run_0", [0])]
    job = recs[0]["stages"][0]["job"]
    assert queue_of(cluster) == [job]
    # --resume, or the same command, while that job is queued: refused, nothing submitted
    for extra in (["--resume"], []):
        again = run_cli(runner_bin, *cmd, *extra, env=env, check=False)
        assert again.returncode == 1 and "jobs %s of this batch" % job in again.stderr \
            and "still in the queue" in again.stderr, again.stderr
        assert load(out / "slurm" / "jobs.json") == recs
        assert queue_of(cluster) == [job]
    # once it has left the queue (here: cancelled), the same command submits what is missing
    cancel_all(cluster)
    p = run_cli(runner_bin, *cmd, env=env)
    assert "submitted run 2/2, collect 1/1" in p.stderr, p.stderr
    recs = load(out / "slurm" / "jobs.json")
    assert len(recs) == 2 and recs[1]["complete"] is True
    assert [(s["label"], s["tasks"]) for s in recs[1]["stages"]] == \
        [("run_0", [0]), ("run_1", [1]), ("collect", [0])]
    assert queue_of(cluster) == sorted(s["job"] for s in recs[1]["stages"])
    # a started batch is only resumed
    again = run_cli(runner_bin, *cmd, env=env, check=False)
    assert again.returncode == 1 and "holds a Slurm batch already" in again.stderr
    cancel_all(cluster)


def test_a_failed_first_submission_is_retried_by_the_same_command(runner_bin, cluster,
                                                                   tmp_path):
    d1 = dataset(tmp_path, "d1")
    out = tmp_path / "out"
    env = {"SLURM_CONF": cluster.conf}
    cmd = ["run", "--datasets", d1, *HANG, "--out", out, "--executor", "slurm", *SMALL,
           "--sbatch", wrapper(tmp_path, fail_on=1)]
    p = run_cli(runner_bin, *cmd, env=env, check=False)
    assert p.returncode == 1 and "nothing of this submission was queued: run the same " \
        "command again" in p.stderr, p.stderr
    assert (out / "slurm" / "plan.json").is_file() and queue_of(cluster) == []
    p = run_cli(runner_bin, *cmd, env=env)
    assert "submitted run 1/1, collect 1/1" in p.stderr, p.stderr
    recs = load(out / "slurm" / "jobs.json")
    assert [(r["complete"], len(r["stages"])) for r in recs] == [(False, 0), (True, 2)]
    # a dry run plans without starting the batch: the same command plans again
    dry = tmp_path / "dry"
    for _ in range(2):
        run_cli(runner_bin, "run", "--datasets", d1, *HANG, "--out", dry, "--executor",
                "slurm", *SMALL, "--dry-run", env=env)
    cancel_all(cluster)


def test_a_request_above_the_partitions_nodes_is_refused(runner_bin, cluster, tmp_path):
    d1 = dataset(tmp_path, "d1")
    env = {"SLURM_CONF": cluster.conf}
    cpus = os.cpu_count() or 1
    base = ["run", "--datasets", d1, *HANG, "--executor", "slurm"]
    for i, (stages, msg) in enumerate([
            (["--stage", "run:cpus=%d,mem=100M" % (cpus + 1), "--stage", "collect:mem=500M"],
             "stage run asks for %d CPUs and 100M of memory per task, more than any node of "
             "the default partition has (at most %d CPUs, 8000M)" % (cpus + 1, cpus)),
            (["--stage", "run:cpus=1,mem=100M"],  # collect's default 16G > 8000M
             "stage collect asks for 2 CPUs and 16G"),
            (SMALL + ["--partition", "gpu"], "sinfo lists no node in partition gpu "
             "(partitions: debug)"),
    ]):
        out = tmp_path / ("out%d" % i)
        p = run_cli(runner_bin, *base, "--out", out, *stages, env=env, check=False)
        assert p.returncode == 1 and msg in p.stderr, p.stderr
        assert not (out / "slurm" / "jobs.json").exists() and queue_of(cluster) == []
    # what fits is submitted
    p = run_cli(runner_bin, *base, "--out", tmp_path / "fits", *SMALL, "--stage",
                "run:cpus=%d,mem=8000M" % cpus, "--sbatch", wrapper(tmp_path, fail_on=0),
                env=env)
    assert "submitted run 1/1" in p.stderr
    cancel_all(cluster)


def processes():
    """{pid: (pgid, cmdline)} of this machine."""
    out = {}
    for n in os.listdir("/proc"):
        if not n.isdigit():
            continue
        try:
            with open("/proc/%s/stat" % n) as f:
                pgid = int(f.read().rsplit(")", 1)[1].split()[2])
            with open("/proc/%s/cmdline" % n, "rb") as f:
                cmd = f.read().split(b"\0")
        except (OSError, IndexError, ValueError):
            continue
        out[int(n)] = (pgid, [c.decode(errors="replace") for c in cmd if c])
    return out


def test_a_task_killed_with_sigkill_ends_its_tools_and_says_why(runner_bin, cluster, tmp_path):
    d1 = dataset(tmp_path, "d1")
    out = tmp_path / "out"
    env = {"SLURM_CONF": cluster.conf}
    run_cli(runner_bin, "run", "--datasets", d1, *HANG, "--out", out, "--executor", "slurm",
            *SMALL, env=env)
    pgids = out / "slurm" / "logs" / "run-0.pgids"
    plan = str(out / "slurm" / "plan.json")
    deadline = time.time() + 120
    while True:
        procs = processes()
        groups = [int(g) for g in pgids.read_text().split()] if pgids.is_file() else []
        tool = [p for p, (g, c) in procs.items() if g in groups and c[:1] == ["sleep"]]
        runner = [p for p, (g, c) in procs.items() if "slurm-task" in c and plan in c]
        if tool and len(runner) == 1:
            break
        assert time.time() < deadline, (cluster.jobs(), cluster.log_tail())
        time.sleep(0.1)
    os.kill(runner[0], signal.SIGKILL)
    cluster.wait_idle(120)
    # the tool's whole process group is gone
    left = [p for p, (g, _) in processes().items() if g in groups]
    assert left == [], left
    log = (out / "slurm" / "logs" / "run-0.out").read_text()
    assert "# sfmeval-runner: run task 0: its runner was killed by signal 9 (SIGKILL); ended " \
        "its tools' process group(s) %d (2 process(es))" % groups[0] in log, log
    rec = load(out / "runs" / "d1" / "hang" / "run.json")
    job = load(out / "slurm" / "jobs.json")[0]["stages"][0]["job"]
    assert rec["status"] == "failed"
    # the end reason as Slurm recorded it (state, exit signal) and the script's line
    assert rec["reason"].startswith(
        "Slurm run task 0: killed by signal 9 (SIGKILL: the kernel's out-of-memory killer, or a "
        "kill outside Slurm; Slurm job %s_0: JobState=FAILED ExitCode=0:9); ended its tools' "
        "process group(s) %d (2 process(es)); see " % (job, groups[0])), rec["reason"]
    cell = (out / "table" / "table1.md").read_text()
    assert "| failed: Slurm run task 0: killed by signal 9 (SIGKILL" in cell, cell
    doc = load(out / "batch.json")
    assert [(t["task"], t["status"]) for t in doc["tasks_without_result"]] == [(0, "failed")]
    assert doc["executor"] == "slurm"

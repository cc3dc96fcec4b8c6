"""`sfmeval-runner table1|sweep --executor slurm` on a real one-node Slurm cluster (slurmctld + slurmd +
munged started by slurm_testlib in a temporary folder, stopped by their PIDs at the end).

The job: `table1 --quick` on one preset (statue) with two pipelines (openmvg, pycolmap) at
320x180, 24 views, 4 spp, 100k completeness samples: rendered in 2 shards + finalize, one run
task per pipeline, collect. It is run once locally and once through Slurm; the pycolmap run task
is cancelled (scancel) while it runs, the table is written with that cell marked, and
`--resume` submits only that task (and the collect), after which the table equals the local one
byte for byte. Then `run --executor slurm` of the same grid on that dataset with a 1-minute
time limit: the pycolmap task is stopped until Slurm kills it (TIMEOUT), the table marks the
cell, `--resume` with a longer limit completes it to a local `run` + `report`'s table. Then a
`noise=0,8` sweep (small preset at the same size, openmvg) locally and through Slurm: the same
sweep.csv and charts but for the run times. Measured on 2 vCPUs (loaded): table1 ~12 s
locally, ~25 s through Slurm with its resume; the run test ~80 s (60-90 s of it waiting for
Slurm's time limit, which it checks every 30 s); the sweep test 40-60 s."""

import csv
import json
import os
import time

import pytest

import slurm_testlib
from runner_testlib import load, run_cli

PRESET = "statue"
NAME = "statue-quick"
# One thread each: with all cores, pycolmap's model can depend on the load (seen under load 9:
# 31 points in one run, 34 in the next), and the tests compare runs made at different times.
PIPES = "openmvg:threads=1;pycolmap:threads=1"
SETS = ["camera.resolution=[320, 180]", "render.samples=4",
        "views.orbits=[{elevation_deg=20.0, count=12}, "
        "{elevation_deg=45.0, count=12, azimuth_offset_deg=15.0}]"]
SLURM = ["--executor", "slurm", "--render-shards", "2",
         "--stage", "render:cpus=1,mem=1G", "--stage", "finalize:cpus=1,mem=1G",
         "--stage", "run:cpus=1,mem=2G", "--stage", "collect:cpus=1,mem=2G"]


def table1_args(out, *extra):
    args = ["table1", "--quick", "--presets", PRESET, "--pipelines", PIPES,
            "--samples", "100000", "--out", str(out)]
    for s in SETS:
        args += ["--set", s]
    return args + list(extra)


def files(root):
    out = {}
    for d, _, names in os.walk(root):
        for n in names:
            with open(os.path.join(d, n), "rb") as f:
                out[os.path.relpath(os.path.join(d, n), root)] = f.read()
    return out


def md_cells(path):
    """{(dataset, pipeline): cell} of table1.md."""
    lines = [l for l in open(path).read().splitlines() if l.startswith("|")]
    rows = [[c.strip() for c in l.strip().strip("|").split("|")] for l in lines]
    header = rows[0]
    return {(r[0], header[i]): r[i] for r in rows[2:] for i in range(1, len(header))}


def measures(report):
    """The numbers of a report that the table is made of, and the rest of its measurements."""
    return {k: report[k] for k in ("accuracy", "completeness", "thresholds", "alignment")}


@pytest.fixture(scope="module")
def tools():
    pytest.importorskip("bpy")
    pytest.importorskip("pycolmap")
    pytest.importorskip("openmvg_rs")


@pytest.fixture(scope="module")
def cluster(tmp_path_factory):
    c = slurm_testlib.start(str(tmp_path_factory.mktemp("slurm-cluster")))
    yield c
    c.stop()


@pytest.fixture(scope="module")
def local(runner_bin, tools, tmp_path_factory):
    out = tmp_path_factory.mktemp("local") / "t1"
    t0 = time.time()
    run_cli(runner_bin, *table1_args(out))
    print("local table1: %.1f s" % (time.time() - t0))
    return out


def test_dry_run_writes_the_scripts_and_submits_nothing(runner_bin, cluster, tmp_path):
    out = tmp_path / "dry"
    env = {"SLURM_CONF": cluster.conf}
    p = run_cli(runner_bin, *table1_args(out, *SLURM, "--dry-run", "--partition", "debug",
                                         "--account", "lab", "--stage",
                                         "run:cpus=2,mem=3G,time=00:20:00"), env=env)
    assert "--dry-run: scripts in" in p.stderr and "run 2/2" in p.stderr
    slurm = out / "slurm"
    assert cluster.jobs() == {} and not (slurm / "jobs.json").exists()
    render = (slurm / "render.sbatch").read_text()
    run = (slurm / "run.sbatch").read_text()
    for line in ["#SBATCH --cpus-per-task=1", "#SBATCH --mem=1G",
                 "#SBATCH --partition=debug", "#SBATCH --account=lab",
                 "#SBATCH --output=%s/logs/render-%%a.out" % slurm]:
        assert line in render.splitlines(), (line, render)
    for line in ["#SBATCH --cpus-per-task=2", "#SBATCH --mem=3G",
                 "#SBATCH --time=00:20:00", "#SBATCH --partition=debug"]:
        assert line in run.splitlines(), (line, run)
    assert "slurm-task --plan %s/plan.json --stage run --index \"$SLURM_ARRAY_TASK_ID\"" \
        % slurm in run
    collect = (slurm / "collect.sbatch").read_text()
    assert "#SBATCH --array" not in collect and "--stage collect --index 0" in collect
    submit = (slurm / "submit.sh").read_text().splitlines()
    sb = [l for l in submit if "sbatch --parsable" in l]
    assert [l.split("=")[0] for l in sb] == ["render_0", "finalize_0", "run_0", "collect"]
    assert "--parsable --array=0-1 %s/render.sbatch" % slurm in sb[0]
    assert "--array=0 --dependency=afterok:$render_0 --kill-on-invalid-dep=yes" in sb[1]
    assert "--array=0-1 --dependency=afterok:$finalize_0 --kill-on-invalid-dep=yes" in sb[2]
    assert "--dependency=afterany:$render_0:$finalize_0:$run_0" in sb[3]
    assert "--array" not in sb[3]
    assert slurm_testlib.subprocess.run(["bash", "-n", str(slurm / "submit.sh")]).returncode == 0
    plan = load(slurm / "plan.json")
    assert plan["cells"] == [{"dataset": NAME, "pipeline": "openmvg"},
                             {"dataset": NAME, "pipeline": "pycolmap"}]
    assert plan["render_shards"] == 2 and plan["datasets"][0]["name"] == NAME
    # a dry run does not start the batch: the same command plans it again; other work is
    # refused on --resume
    again = run_cli(runner_bin, *table1_args(out, *SLURM, "--dry-run"), env=env)
    assert "--dry-run: scripts in" in again.stderr
    three_shards = [a if a != "2" else "3" for a in SLURM]
    other = run_cli(runner_bin, *table1_args(out, *three_shards, "--resume", "--dry-run"),
                    env=env, check=False)
    assert other.returncode == 1 and "planned with other" in other.stderr, other.stderr
    fresh = run_cli(runner_bin, *table1_args(tmp_path / "new", *SLURM, "--resume"), env=env,
                    check=False)
    assert fresh.returncode == 1 and "holds no Slurm batch" in fresh.stderr
    local = run_cli(runner_bin, *table1_args(tmp_path / "l", "--dry-run"), check=False)
    assert local.returncode == 1 and "go with --executor slurm" in local.stderr
    bad = run_cli(runner_bin, *table1_args(tmp_path / "b", *SLURM, "--stage", "run:gpus=1"),
                  env=env, check=False)
    assert bad.returncode == 1 and "unknown key 'gpus'" in bad.stderr
    assert cluster.jobs() == {}


def wait_running_then_cancel(cluster, job, task_dir, pipeline, *scancel, timeout=240):
    """`scancel [SCANCEL...] JOB` while it runs its tool (its partial run folder exists)."""
    deadline = time.time() + timeout
    while time.time() < deadline:
        state = cluster.jobs().get(job)
        busy = task_dir.is_dir() and any(n.startswith(".%s.partial" % pipeline)
                                         for n in os.listdir(task_dir))
        if state == "RUNNING" and busy:
            cluster.cmd("scancel", *scancel, job)
            return
        assert not (task_dir / pipeline / "run.json").exists(), \
            "the task finished before it could be cancelled"
        time.sleep(0.05)
    raise AssertionError("task %s never ran: %s\n%s" % (job, cluster.jobs(), cluster.log_tail()))


def test_slurm_gives_the_local_table_and_resume_completes_it(runner_bin, tools, cluster, local,
                                                             tmp_path):
    out = tmp_path / "slurm"
    env = {"SLURM_CONF": cluster.conf}
    t0 = time.time()
    run_cli(runner_bin, *table1_args(out, *SLURM), env=env)
    subs = load(out / "slurm" / "jobs.json")
    assert len(subs) == 1
    stages = {s["stage"]: s for s in subs[0]["stages"]}
    assert [s["label"] for s in subs[0]["stages"]] == ["render_0", "finalize_0", "run_0",
                                                       "collect"]
    assert stages["render"]["tasks"] == [0, 1] and stages["run"]["tasks"] == [0, 1]
    # resuming while the batch is still queued would run tasks twice at once
    early = run_cli(runner_bin, *table1_args(out, *SLURM, "--resume"), env=env, check=False)
    assert early.returncode == 1 and "still in the queue" in early.stderr, early.stderr
    assert len(load(out / "slurm" / "jobs.json")) == 1
    plan = load(out / "slurm" / "plan.json")
    k = [c["pipeline"] for c in plan["cells"]].index("pycolmap")
    job = "%s_%d" % (stages["run"]["job"], k)
    task_dir = out / "slurm" / "runs" / ("task-%d" % k) / NAME
    wait_running_then_cancel(cluster, job, task_dir, "pycolmap")
    cluster.wait_idle(240)
    first = time.time() - t0

    # The table is written, the cancelled cell marked with Slurm's reason.
    cells = md_cells(out / "table" / "table1.md")
    local_cells = md_cells(local / "table" / "table1.md")
    assert cells[(NAME, "pycolmap")].startswith("failed: Slurm run task %d: cancelled" % k), cells
    assert cells[(NAME, "openmvg")] == local_cells[(NAME, "openmvg")]
    assert not local_cells[(NAME, "pycolmap")].startswith("failed")
    rec = load(out / "runs" / NAME / "pycolmap" / "run.json")
    assert rec["status"] == "failed" and "CANCELLED" in rec["reason"], rec["reason"]
    doc = load(out / "table1.json")
    assert doc["executor"] == "slurm" and doc["runs_executed"] == {"ok": 1}
    assert [(t["task"], t["pipeline"]) for t in doc["tasks_without_result"]] == [(k, "pycolmap")]
    # The dataset rendered in two shards + finalize is the local one-shot render, byte for byte
    # (timing.json holds the measured times and where each part ran).
    a, b = files(local / "datasets" / NAME), files(out / "datasets" / NAME)
    assert sorted(a) == sorted(b) and len([f for f in a if f.startswith("images/")]) == 24
    assert [f for f in a if a[f] != b[f]] == ["timing.json"]
    assert [p["views"] for p in load(out / "datasets" / NAME / "timing.json")["parts"]] == \
        ["shard 0 2", "shard 1 2"]

    # --resume submits only what is missing: the cancelled run and the collect.
    done = out / "slurm" / "runs" / ("task-%d" % (1 - k)) / NAME / "openmvg" / "run.json"
    before = done.read_bytes()
    t1 = time.time()
    p = run_cli(runner_bin, *table1_args(out, *SLURM, "--resume"), env=env)
    assert "submitted run 1/2, collect 1/1" in p.stderr, p.stderr
    subs = load(out / "slurm" / "jobs.json")
    assert [(s["stage"], s["tasks"]) for s in subs[1]["stages"]] == [("run", [k]),
                                                                      ("collect", [0])]
    cluster.wait_idle(240)
    resumed = time.time() - t1
    assert done.read_bytes() == before  # not redone
    for f in ["table1.md", "table1.csv"]:
        assert (out / "table" / f).read_text() == (local / "table" / f).read_text(), f
    for pipe in ["openmvg", "pycolmap"]:
        rel = os.path.join("table", "reports", NAME, pipe + ".json")
        assert measures(load(out / rel)) == measures(load(local / rel)), pipe
    doc = load(out / "table1.json")
    assert doc["tasks_without_result"] == [] and doc["runs_executed"] == {"ok": 2}
    # One summary type from both executors: the same keys, the same values but for where it
    # ran and the measured times.
    mine = load(local / "table1.json")
    assert (doc["executor"], mine["executor"]) == ("slurm", "local")
    assert sorted(doc) == sorted(mine) and sorted(doc["timing"]) == sorted(mine["timing"])
    for k in doc:
        if k not in ("executor", "timing"):
            assert doc[k] == mine[k], (k, doc[k], mine[k])
    for k in ("render_seconds", "render_seconds_per_view"):
        assert sorted(doc["timing"][k]) == sorted(mine["timing"][k]) == [NAME], k
        assert doc["timing"][k][NAME] > 0 and mine["timing"][k][NAME] > 0, k

    # Nothing missing: a third call only collects again.
    p = run_cli(runner_bin, *table1_args(out, *SLURM, "--resume"), env=env)
    assert "submitted collect 1/1" in p.stderr, p.stderr
    cluster.wait_idle(120)
    assert (out / "table" / "table1.md").read_text() == (local / "table" / "table1.md").read_text()
    print("slurm: first submission %.1f s, resume %.1f s" % (first, resumed))
    print(json.dumps(load(out / "table1.json")["timing"]))


RUN_SLURM = ["--executor", "slurm", "--stage", "collect:cpus=1,mem=2G"]


def test_run_through_slurm_equals_local_run_and_a_timed_out_task_resumes(runner_bin, tools,
                                                                        cluster, local,
                                                                        tmp_path):
    """`run --executor slurm` on the dataset the local table1 rendered: one array of run tasks
    (no render) and the collect. Slurm's time limit (1 minute, the least it takes) kills the
    pycolmap task, which the test stops (SIGSTOP, a tool that hangs): the table is written with
    that cell marked `timeout` and Slurm's message; `--resume` with a longer limit redoes that
    task only, and the table then equals a local `run` + `report` of the same grid."""
    dataset = local / "datasets" / NAME
    grid = ["--datasets", str(dataset), "--pipelines", PIPES]
    env = {"SLURM_CONF": cluster.conf}
    dry = tmp_path / "dry"
    run_cli(runner_bin, "run", *grid, "--out", dry, *RUN_SLURM, "--dry-run", env=env)
    sb = [l for l in (dry / "slurm" / "submit.sh").read_text().splitlines()
          if "sbatch --parsable" in l]
    assert [l.split("=")[0] for l in sb] == ["run_0", "collect"], sb
    assert "--parsable --array=0-1 %s/run.sbatch" % (dry / "slurm") in sb[0]
    assert "--dependency=afterany:$run_0 " in sb[1]
    plan = load(dry / "slurm" / "plan.json")
    assert plan["render_shards"] == 0 and plan["datasets"][0]["dir"] == str(dataset)
    assert sorted(f for f in os.listdir(dry / "slurm") if f.endswith(".sbatch")) == \
        ["collect.sbatch", "run.sbatch"] and not (dry / "datasets").exists()
    bad = run_cli(runner_bin, "run", *grid, "--out", tmp_path / "b", "--samples", "9",
                  check=False)
    assert bad.returncode == 1 and "go with --executor slurm" in bad.stderr, bad.stderr

    out = tmp_path / "slurm"
    t0 = time.time()
    run_cli(runner_bin, "run", *grid, "--out", out, "--samples", "100000", *RUN_SLURM,
            "--stage", "run:cpus=1,mem=2G,time=1", env=env)
    stages = load(out / "slurm" / "jobs.json")[0]["stages"]
    assert [(s["label"], s["tasks"]) for s in stages] == [("run_0", [0, 1]), ("collect", [0])]
    k = [c["pipeline"] for c in load(out / "slurm" / "plan.json")["cells"]].index("pycolmap")
    task_dir = out / "slurm" / "runs" / ("task-%d" % k) / NAME
    wait_running_then_cancel(cluster, "%s_%d" % (stages[0]["job"], k), task_dir, "pycolmap",
                             "--signal=STOP", "--full")
    # the local run of the same grid meanwhile (the stopped task takes no CPU)
    mine = tmp_path / "local"
    run_cli(runner_bin, "run", *grid, "--out", mine)
    run_cli(runner_bin, "report", mine, "--out", mine / "table", "--samples", "100000")
    cluster.wait_idle(240)
    first = time.time() - t0

    cells = md_cells(out / "table" / "table1.md")
    local_cells = md_cells(mine / "table" / "table1.md")
    assert cells[(NAME, "pycolmap")].startswith(
        "timeout: Slurm run task %d: Slurm time limit" % k), cells
    assert cells[(NAME, "openmvg")] == local_cells[(NAME, "openmvg")]
    rec = load(out / "runs" / NAME / "pycolmap" / "run.json")
    assert rec["status"] == "timeout" and "DUE TO TIME LIMIT" in rec["reason"], rec["reason"]
    with open(os.path.join(cluster.root, "slurmctld.log"), errors="replace") as f:
        assert "Time limit exhausted for JobId=" in f.read()
    doc = load(out / "batch.json")
    assert doc["runs_executed"] == {"ok": 1} and doc["datasets"] == [str(dataset)]
    assert [(t["task"], t["status"]) for t in doc["tasks_without_result"]] == [(k, "timeout")]

    t1 = time.time()
    p = run_cli(runner_bin, "run", *grid, "--out", out, "--samples", "100000", *RUN_SLURM,
                "--stage", "run:cpus=1,mem=2G,time=10", "--resume", env=env)
    assert "submitted run 1/2, collect 1/1" in p.stderr, p.stderr
    assert "#SBATCH --time=10" in (out / "slurm" / "run.sbatch").read_text().splitlines()
    cluster.wait_idle(240)
    resumed = time.time() - t1
    for f in ["table1.md", "table1.csv"]:
        assert (out / "table" / f).read_text() == (mine / "table" / f).read_text(), f
    for pipe in ["openmvg", "pycolmap"]:
        rel = os.path.join("reports", NAME, pipe + ".json")
        assert measures(load(out / "table" / rel)) == measures(load(mine / "table" / rel)), pipe
    assert load(out / "batch.json")["tasks_without_result"] == []
    print("slurm run: first submission (with the timeout) %.1f s, resume %.1f s"
          % (first, resumed))


SWEEP = ["sweep", "--factor", "noise=0,8", "--dataset-preset", "small",
         "--set", "render.samples=4", "--set", "camera.resolution=[320, 180]",
         "--set", "views.orbits=[{elevation_deg=20.0, count=12}, "
                  "{elevation_deg=45.0, count=12, azimuth_offset_deg=15.0}]",
         "--pipelines", "openmvg", "--samples", "100000"]


def test_a_sweep_through_slurm_equals_the_local_sweep(runner_bin, tools, cluster, tmp_path):
    """`sweep --executor slurm`: one dataset per value (2 render parts each), its runs, and a
    collect that writes the local sweep's CSV and charts."""
    local = tmp_path / "local"
    run_cli(runner_bin, *SWEEP, "--out", local)
    out = tmp_path / "slurm"
    p = run_cli(runner_bin, *SWEEP, "--out", out, *SLURM, env={"SLURM_CONF": cluster.conf})
    assert "submitted render 4/4, finalize 2/2, run 2/2, collect 1/1" in p.stderr, p.stderr
    labels = [s["label"] for s in load(out / "slurm" / "jobs.json")[0]["stages"]]
    assert labels == ["render_0", "finalize_0", "run_0", "render_1", "finalize_1", "run_1",
                      "collect"]
    cluster.wait_idle(240)
    # every column but the measured run time (run.wall_seconds), which two runs never share
    def table(path):
        with open(path, newline="") as f:
            return [{k: v for k, v in r.items() if k != "run.wall_seconds"}
                    for r in csv.DictReader(f)]
    rows = table(out / "sweep.csv")
    assert rows == table(local / "sweep.csv")
    assert [(r["dataset"], r["pipeline"]) for r in rows] == [("noise-0", "openmvg"),
                                                             ("noise-8", "openmvg")]
    assert rows[0]["status"] == "ok" and float(rows[0]["report.accuracy.mean"]) > 0
    charts = sorted(os.listdir(local / "charts"))
    assert "report_accuracy_mean.svg" in charts and sorted(os.listdir(out / "charts")) == charts
    for c in charts:
        if c != "run_wall_seconds.svg":
            assert (out / "charts" / c).read_text() == (local / "charts" / c).read_text(), c
    doc = load(out / "sweep.json")
    assert [v["status"] for v in doc["variants"]] == ["rendered", "rendered"]
    assert doc["executor"] == "slurm" and doc["tasks_without_result"] == []
    # the same summary as the local sweep's but for where it ran and the times
    mine = load(local / "sweep.json")
    assert sorted(doc) == sorted(mine) and sorted(doc["timing"]) == sorted(mine["timing"])
    assert mine["executor"] == "local"
    for k in doc:
        if k not in ("executor", "timing", "command", "variants"):
            assert doc[k] == mine[k], k
    assert [{k: v for k, v in x.items() if k != "seconds"} for x in doc["variants"]] == \
        [{k: v for k, v in x.items() if k != "seconds"} for x in mine["variants"]]
    for v in ["noise-0", "noise-8"]:
        a, b = files(local / "datasets" / v), files(out / "datasets" / v)
        assert [f for f in a if a[f] != b.get(f)] == ["timing.json"], v

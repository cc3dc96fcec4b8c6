"""The timing loop of the protocol benchmarks (bench/dtu.py, bench/eth3d.py): a command run
several times in its own process under GNU time, the median wall and CPU (user + system) times,
the largest peak memory and the last run's parsed result. CPU time is the fairer number on a
loaded machine, where a process waits for the cores. (bench/tanksandtemples.py has its own
alternating loop, `measure_pair`; it can switch to this module.)"""
import statistics
import subprocess
import tempfile
import time

from compare import GNU_TIME


def run_timed(cmd, env=None):
    """Runs cmd once; returns (wall s, CPU s, peak MiB, exit code, stdout, stderr)."""
    with tempfile.NamedTemporaryFile("r") as tf:
        t0 = time.perf_counter()
        p = subprocess.run([GNU_TIME, "-f", "%U %S %M", "-o", tf.name, *map(str, cmd)],
                           capture_output=True, env=env)
        wall = time.perf_counter() - t0
        fields = tf.read().split()
    try:
        user, system, peak_kb = float(fields[-3]), float(fields[-2]), int(fields[-1])
        cpu, peak = user + system, peak_kb / 1024.0
    except (IndexError, ValueError):
        cpu, peak = float("nan"), float("nan")
    return wall, cpu, peak, p.returncode, p.stdout.decode(errors="replace"), p.stderr.decode(errors="replace")


def measure_cpu(cmd, rounds, result, env=None):
    """Runs `cmd` `rounds` times; returns (median wall s, median CPU s, max peak MiB,
    result(last stdout)). Exits with the command's output when a run fails."""
    walls, cpus, peaks, out = [], [], [], ""
    for _ in range(rounds):
        wall, cpu, peak, rc, out, err = run_timed(cmd, env=env)
        if rc != 0:
            raise SystemExit(f"bench: {' '.join(map(str, cmd[:3]))} failed: {(out + err)[-800:]}")
        walls.append(wall)
        cpus.append(cpu)
        peaks.append(peak)
    return statistics.median(walls), statistics.median(cpus), max(peaks), result(out)


def measure(cmd, rounds, result, env=None):
    """`measure_cpu` without the CPU time: (median wall s, max peak MiB, result(last stdout))."""
    wall, _, peak, res = measure_cpu(cmd, rounds, result, env=env)
    return wall, peak, res

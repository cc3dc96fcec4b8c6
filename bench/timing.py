"""The timing loop of the protocol benchmarks (bench/dtu.py, bench/eth3d.py): a command run
several times in its own process under GNU time, the median wall time, the largest peak memory and
the last run's parsed result. (bench/tanksandtemples.py has its own alternating loop with CPU
time, `measure_pair`; it can switch to this module.)"""
import statistics

from compare import run_with_peak


def measure(cmd, rounds, result, env=None):
    """Runs `cmd` `rounds` times; returns (median wall s, max peak MiB, result(last stdout)).
    Exits with the command's output when a run fails."""
    walls, peaks, out = [], [], ""
    for _ in range(rounds):
        wall, peak, rc, out, err = run_with_peak(cmd, env=env)
        if rc != 0:
            raise SystemExit(f"bench: {' '.join(map(str, cmd[:3]))} failed: {(out + err)[-800:]}")
        walls.append(wall)
        peaks.append(peak)
    return statistics.median(walls), max(peaks), result(out)

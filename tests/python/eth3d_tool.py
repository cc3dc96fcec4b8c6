"""Runs ETH3D's official multi-view evaluation tool (tests/third_party/eth3d_multi_view_evaluation,
built by scripts/build-eth3d-tool.sh into .tools/eth3d/) and parses what it prints."""
import os
import subprocess
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
TOOL_DIR = ROOT / ".tools" / "eth3d"


def build():
    """Builds the tool once (a no-op when built); returns the 9-digit build's path."""
    subprocess.run([str(ROOT / "scripts" / "build-eth3d-tool.sh")], check=True)
    return TOOL_DIR / "ETH3DMultiViewEvaluation9"


def run(tool, mlp, recon, tolerances, out_dir=None, threads=1):
    """The tool's tolerances, completenesses, accuracies and F1 scores (lists of floats).
    `threads`: OpenMP threads of its completeness loop (its per-point results are written to a
    std::vector<bool> from several threads without a lock, so the clouds are compared from one
    thread)."""
    cmd = [str(tool), "--reconstruction_ply_path", str(recon), "--ground_truth_mlp_path", str(mlp),
           "--tolerances", ",".join(map(str, tolerances))]
    if out_dir is not None:
        cmd += ["--completeness_cloud_output_path", str(Path(out_dir) / "completeness"),
                "--accuracy_cloud_output_path", str(Path(out_dir) / "accuracy")]
    env = dict(os.environ, OMP_NUM_THREADS=str(threads))
    p = subprocess.run(cmd, capture_output=True, text=True, env=env)
    assert p.returncode == 0, p.stderr[-3000:]
    got = {}
    for line in p.stdout.splitlines():
        key, _, values = line.partition(": ")
        if key in ("Tolerances", "Completenesses", "Accuracies", "F1-scores"):
            got[key] = [float(v) for v in values.split()]
    return got

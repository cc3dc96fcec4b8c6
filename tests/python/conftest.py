"""Shared fixtures: the sfmeval binary, a runner that returns parsed reports, schema validation."""
import json
import os
import subprocess
from pathlib import Path

import jsonschema
import pytest

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="session")
def sfmeval_bin() -> str:
    env_bin = os.environ.get("SFMEVAL_BIN")
    if env_bin and Path(env_bin).exists():
        return env_bin
    subprocess.run([str(ROOT / "scripts" / "build-release.sh"), "-q"], cwd=ROOT, check=True)
    return str(ROOT / "target" / "release" / "sfmeval")


@pytest.fixture(scope="session")
def report_schema():
    return json.loads((ROOT / "schemas" / "report.schema.json").read_text())


@pytest.fixture
def run_eval(sfmeval_bin, report_schema, tmp_path):
    """Runs `sfmeval eval` and returns (report dict, per-point CSV rows as numpy arrays)."""
    import numpy as np

    def run(gt, recon, *extra, expect_ok=True):
        report = tmp_path / "report.json"
        csv = tmp_path / "points.csv"
        extra = list(map(str, extra))
        # Recon files in these tests are already in the GT frame unless a transform is given.
        align = [] if ("--transform" in extra or "--align" in extra) else ["--align", "none"]
        cmd = [sfmeval_bin, "eval", "--gt", str(gt), "--recon", str(recon), "--quiet", *align,
               "--report", str(report), "--csv", str(csv), *extra]
        p = subprocess.run(cmd, capture_output=True, text=True)
        if not expect_ok:
            return p
        assert p.returncode == 0, p.stderr
        rep = json.loads(report.read_text())
        jsonschema.validate(rep, report_schema)
        data = np.genfromtxt(csv, delimiter=",", names=True, dtype=None, encoding="utf-8")
        return rep, data

    return run

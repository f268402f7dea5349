"""The benchmark script runs (smoke mode only: speed is never a test)."""

import subprocess
import sys
from pathlib import Path

SCRIPT = Path(__file__).parent.parent / "benchmarks" / "run.py"


def test_benchmarks_quick_smoke(tmp_path):
    out = tmp_path / "RESULTS.md"
    run = subprocess.run(
        [sys.executable, str(SCRIPT), "--quick", "--out", str(out)],
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert run.returncode == 0, run.stderr
    text = out.read_text()
    for section in (
        "## Problem",
        "## Reference",
        "## Results",
        "## What failed",
        "## Conclusion",
        "## Versions and command",
    ):
        assert section in text
    assert "× control.initial_response" in text and "ratio (target ≥ 100)" in text

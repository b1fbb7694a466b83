"""benchmarks/stats_scale.py runs end to end on a few synthetic sequences (nothing about its
numbers is asserted but that they are there)."""
import json
import subprocess
import sys
from pathlib import Path

import pytest

SCRIPT = Path(__file__).resolve().parents[2] / "benchmarks" / "stats_scale.py"


@pytest.mark.slow
def test_stats_scale_measures_each_stage_at_both_sizes(tmp_path):
    done = subprocess.run([sys.executable, str(SCRIPT), "--sequences", "40", "--small", "4", "--frames", "3",
                           "--work", str(tmp_path / "work"), "--json", str(tmp_path / "scale.json")],
                          capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stdout[-2000:] + done.stderr[-2000:]
    found = json.loads((tmp_path / "scale.json").read_text())
    assert [(r["stage"], r["sequences"]) for r in found] == [(s, n) for n in (4, 40) for s in ("statistics", "compare",
                                                                                                  "report")]
    assert all(r["seconds"] > 0 and r["peak_mb"] >= r["added_mb"] >= 0 for r in found)
    assert (tmp_path / "work" / "n40" / "report" / "per_sequence.csv").read_text().count("\n") == 1 + 2 * 40
    assert "compare    10x the sequences: " in done.stdout

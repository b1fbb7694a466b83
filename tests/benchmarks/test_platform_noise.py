"""benchmarks/platform_noise.py runs end to end on a few synthetic frames (its workers, a switch,
the table and the JSON), so that a change cannot break it unseen."""
import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

SCRIPT = Path(__file__).resolve().parents[2] / "benchmarks" / "platform_noise.py"


@pytest.mark.slow
def test_platform_noise_smoke(tmp_path):
    env = {**os.environ, "DCFKIT_TEST_DATA": str(tmp_path / "no data")}  # the synthetic sequence
    out = tmp_path / "noise.json"
    run = subprocess.run([sys.executable, str(SCRIPT), "--configs", "kcf,reference/strcf", "--max-frames", "4",
                          "--switches", "baseline,numba_generic,fft_pyfftw", "--json", str(out), "--runs", str(tmp_path / "runs")],
                         env=env, capture_output=True, text=True, timeout=600)
    assert run.returncode == 0, run.stdout[-2000:] + run.stderr[-2000:]
    report = json.loads(out.read_text())
    assert set(report) == {"numba_generic", "fft_pyfftw"}
    rows = report["numba_generic"]
    assert [(r["config"], r["sequence"]) for r in rows] == [("kcf", "synthetic"), ("reference/strcf", "synthetic")]
    assert all(r["max_px"] >= 0 and abs(r["d_auc"]) <= 1 for r in rows)
    assert "== numba_generic: NUMBA_CPU_NAME=generic" in run.stdout and "== fft_pyfftw: pyfftw" in run.stdout
    assert {p.name for p in (tmp_path / "runs").iterdir()} >= {"baseline.npz", "numba_generic.npz", "fft_pyfftw.npz"}
    # numba compiles without fast-math: a generic x86-64 target computes the same boxes
    assert all(r["parts_at"] is None and r["max_px"] == 0 for r in rows)

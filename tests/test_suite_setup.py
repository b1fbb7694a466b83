"""The suite's own setup: pyproject's addopts with and without pytest-xdist."""
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def test_the_suite_runs_in_one_process_without_pytest_xdist(tmp_path):
    """``addopts`` asks xdist for workers; with xdist not loaded (as after ``pip install .``
    without the test extras) a test file still runs, in pytest's own process."""
    test = ROOT / "tests" / "tracker" / "test_blank.py"
    done = subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:xdist", "-p", "no:cacheprovider",
                           "--rootdir", str(ROOT), str(test), "-k", "subset_sees_flat"],
                          cwd=ROOT, capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stdout + done.stderr
    assert "1 passed" in done.stdout and "workers" not in done.stdout

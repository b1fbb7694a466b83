"""dcfkit as a user installs it (not this checkout): shipped configs found, the README's demo runs."""
import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def test_installed_package_finds_its_configs_and_runs_the_demo(pip_install_copy, tmp_path):
    site = pip_install_copy(ROOT)
    assert (site / "dcfkit" / "configs" / "dr2track.yaml").is_file()
    assert (site / "dcfkit" / "configs" / "ablations" / "table3.yaml").is_file()
    assert (site / "dcfkit" / "data" / "uav123_sequences.tsv").is_file()
    assert all((site / "dcfkit" / "analysis" / "report_html" / name).is_file() for name in ("report.js", "report.css"))
    env = {**os.environ, "PYTHONPATH": str(site)}
    where = subprocess.run([sys.executable, "-c", "import dcfkit.config as c; print(c.__file__); "
                            "print(c.load_config('dr2track')['name'])"],
                           cwd=tmp_path, env=env, capture_output=True, text=True, timeout=120)
    assert where.returncode == 0, where.stderr
    module, name = where.stdout.split()
    assert Path(module).is_relative_to(site) and name == "dr2track"
    demo = subprocess.run([sys.executable, "-m", "dcfkit.cli", "demo", "--frames", "8", "--save-video", ""],
                          cwd=tmp_path, env=env, capture_output=True, text=True, timeout=300)
    assert demo.returncode == 0, demo.stderr
    assert "strcf" in demo.stdout and "dr2track" in demo.stdout

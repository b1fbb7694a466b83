"""dcfkit as a user installs it (not this checkout): shipped configs found, the README's demo runs,
and the commit it was built from recorded."""
import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

from dcfkit.store.code_state import code_digest

ROOT = Path(__file__).resolve().parents[1]


def test_installed_package_finds_its_configs_and_runs_the_demo(pip_install_copy, tmp_path):
    git = shutil.which("git") is not None  # then the copy is a clone: `pip install .` of a checkout
    site = pip_install_copy(ROOT, git=git)
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
    if git:  # the source state: recorded at build time, and the installed files' digest
        commit = subprocess.run(["git", "-C", str(site.parent / "source"), "rev-parse", "HEAD"], capture_output=True,
                                text=True, check=True).stdout.strip()
        state = subprocess.run([sys.executable, "-c", "import json; from dcfkit.store.provenance import sources; "
                                "print(json.dumps(sources([])))"], cwd=tmp_path, env=env, capture_output=True,
                               text=True, timeout=120)
        assert state.returncode == 0, state.stderr
        assert json.loads(state.stdout) == {"dcfkit": {"commit": commit, "dirty": False,
                                                       "code": code_digest(ROOT / "dcfkit")}}

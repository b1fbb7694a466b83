"""The example plugin plugins/dcfkit-context-label, as a user gets it.

It is pip-installed (``--target`` a temporary folder, put on PYTHONPATH of a subprocess), found
through its ``dcfkit`` entry point by ``dcfkit components``, used from YAML by ``dcfkit track``,
and hidden by DCFKIT_DISABLE_PLUGINS=1. The tutorial docs/plugins.md quotes its source verbatim.
"""
import json
import os
import re
import subprocess
import sys
from pathlib import Path

import cv2
import pytest

from dcfkit.datasets.synthetic import make_sequence
from dcfkit.registry import DISABLE_ENV

ROOT = Path(__file__).resolve().parents[1]
PLUGIN = ROOT / "plugins" / "dcfkit-context-label"
CONFIG = PLUGIN / "configs" / "strcf_context.yaml"
TUTORIAL = ROOT / "docs" / "plugins.md"
PROVIDER = "context (dcfkit_context_label)"  # entry-point name (module)


@pytest.fixture(scope="module")
def site(pip_install_copy) -> Path:
    """The plugin pip-installed into a fresh folder; its dist-info carries the entry point."""
    target = pip_install_copy(PLUGIN)
    (dist_info,) = target.glob("dcfkit_context_label-*.dist-info")
    assert "[dcfkit]\ncontext = dcfkit_context_label" in (dist_info / "entry_points.txt").read_text()
    return target


def run(site: Path, *args: str, plugins: bool = True) -> subprocess.CompletedProcess:
    """``python -m dcfkit.cli ARGS`` with the installed plugin (and this checkout's dcfkit) importable."""
    env = {k: v for k, v in os.environ.items() if k != DISABLE_ENV}
    env["PYTHONPATH"] = os.pathsep.join([str(site), str(ROOT)] + [p for p in [env.get("PYTHONPATH")] if p])
    if not plugins:
        env[DISABLE_ENV] = "1"
    return subprocess.run([sys.executable, "-m", "dcfkit.cli", *args], env=env, cwd=site.parent,
                          capture_output=True, text=True, timeout=300)


def labels(done: subprocess.CompletedProcess) -> dict:
    assert done.returncode == 0, done.stderr
    return {row["name"]: row for row in json.loads(done.stdout)}


def test_installed_plugin_is_listed_with_its_provider(site):
    rows = labels(run(site, "components", "--kind", "label", "--format", "json"))
    assert {"gaussian", "distractor_repressed", "context_aware"} <= set(rows)
    context = rows["context_aware"]
    assert context["provider"] == PROVIDER and rows["gaussian"]["provider"] == "dcfkit"
    assert context["doc"].startswith("Context-aware label (Mueller et al., CVPR 2017)")
    assert [(f["name"], f["default"]) for f in context["params"]] == [
        ("strength", 0.1), ("distance", 1.0), ("diagonals", False), ("use_response", False)]


def test_tutorial_shows_the_real_components_output(site):
    shown = blocks_after("output of: dcfkit components --kind label")
    assert shown, "docs/plugins.md shows the output of `dcfkit components --kind label`"
    listed = run(site, "components", "--kind", "label").stdout.splitlines()
    for line in shown[0].splitlines():
        assert line in listed, f"docs/plugins.md shows {line!r}; dcfkit components prints:\n" + "\n".join(listed)


def test_yaml_naming_the_plugin_label_tracks(site, tmp_path):
    seq = make_sequence(n_frames=15)
    frames = tmp_path / "frames"
    frames.mkdir()
    for i, image in enumerate(seq.frames):
        assert cv2.imwrite(str(frames / f"{i + 1:06d}.png"), image)
    box = ",".join(f"{v:.2f}" for v in seq.ground_truth[0])
    out = tmp_path / "boxes.txt"
    done = run(site, "track", str(CONFIG), "--frames", str(frames), "--box", box, "--out", str(out))
    assert done.returncode == 0, done.stderr
    assert "strcf_context: 15 frames" in done.stderr
    boxes = [[float(v) for v in line.split(",")] for line in out.read_text().splitlines()]
    assert len(boxes) == 15 and all(len(b) == 4 and b[2] > 0 and b[3] > 0 for b in boxes)

    hidden = run(site, "track", str(CONFIG), "--frames", str(frames), "--box", box, plugins=False)
    assert hidden.returncode == 2
    assert "label.name: unknown label 'context_aware'" in hidden.stderr


def test_disabling_plugins_hides_the_label(site):
    rows = labels(run(site, "components", "--kind", "label", "--format", "json", plugins=False))
    assert "context_aware" not in rows and "gaussian" in rows


# -- the tutorial quotes the plugin ------------------------------------------------------
def blocks_after(marker: str) -> list[str]:
    """Fenced code blocks of docs/plugins.md that directly follow ``<!-- MARKER -->``."""
    pattern = re.compile(r"<!-- " + re.escape(marker) + r" -->\n```[^\n]*\n(.*?)```", re.S)
    return pattern.findall(TUTORIAL.read_text(encoding="utf-8"))


QUOTED = ("pyproject.toml", "dcfkit_context_label/__init__.py", "dcfkit_context_label/label.py",
          "tests/test_context_label.py", "configs/strcf_context.yaml")


@pytest.mark.parametrize("path", QUOTED)
def test_tutorial_code_is_the_plugin_source(path):
    blocks = blocks_after(f"file: plugins/dcfkit-context-label/{path}")
    assert blocks, f"docs/plugins.md quotes no part of {path} (mark a block with <!-- file: ... -->)"
    source = (PLUGIN / path).read_text(encoding="utf-8")
    for block in blocks:
        assert block in source, f"docs/plugins.md: this block is not verbatim in {path}:\n{block}"


def test_every_marked_block_names_a_plugin_file():
    text = TUTORIAL.read_text(encoding="utf-8")
    marked = re.findall(r"<!-- file: plugins/dcfkit-context-label/(\S+) -->", text)
    assert sorted(set(marked)) == sorted(QUOTED)


# A plugin as the 0.5 tutorial taught it, one hook, register(cls), with its imports updated to the
# current module paths (those of 0.5 and 0.6 went in 0.11: docs/changes.md).
LEGACY_PLUGIN = '''
import dataclasses

import numpy as np

from dcfkit.components.labels import Detection, Label
from dcfkit.params import param
from dcfkit.registry import hookimpl


class Raised(Label):
    """The label raised by a constant (a 0.5-style plugin)."""

    name = "legacy_raised"

    @dataclasses.dataclass(frozen=True)
    class Params:
        level: float = param(0.0, "added to the Gaussian", ge=0, le=1)

    def make(self, g: np.ndarray, detection: Detection | None):
        return (g + np.float32(self.params.level)).astype(np.float32), np.zeros((0, 2), int)


@hookimpl
def dcfkit_register_components(registry):
    registry.register(Raised)
'''


@pytest.fixture(scope="module")
def legacy_site(pip_install_copy, tmp_path_factory) -> Path:
    project = tmp_path_factory.mktemp("legacy") / "dcfkit-legacy-raised"
    (project / "legacy_raised").mkdir(parents=True)
    (project / "legacy_raised" / "__init__.py").write_text(LEGACY_PLUGIN)
    (project / "pyproject.toml").write_text(
        '[build-system]\nrequires = ["setuptools>=61"]\nbuild-backend = "setuptools.build_meta"\n\n'
        '[project]\nname = "dcfkit-legacy-raised"\nversion = "0.5.0"\n\n'
        '[project.entry-points.dcfkit]\nraised = "legacy_raised"\n\n'
        '[tool.setuptools]\npackages = ["legacy_raised"]\n')
    return pip_install_copy(project)


@pytest.mark.install
def test_a_plugin_written_for_0_5_loads_with_its_imports_updated(legacy_site, tmp_path):
    rows = labels(run(legacy_site, "components", "--kind", "label", "--format", "json"))
    assert rows["legacy_raised"]["provider"] == "raised (legacy_raised)"
    seq = make_sequence(n_frames=8)
    frames = tmp_path / "frames"
    frames.mkdir()
    for i, image in enumerate(seq.frames):
        assert cv2.imwrite(str(frames / f"{i + 1:06d}.png"), image)
    config = tmp_path / "legacy.yaml"
    config.write_text("base: strcf\nname: legacy\nlabel: {name: legacy_raised, level: 0.1}\n")
    box = ",".join(f"{v:.2f}" for v in seq.ground_truth[0])
    done = run(legacy_site, "track", str(config), "--frames", str(frames), "--box", box, "--out", str(tmp_path / "b.txt"))
    assert done.returncode == 0 and "legacy: 8 frames" in done.stderr, done.stderr

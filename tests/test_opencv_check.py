"""A cv2 whose contrib modules another OpenCV package overwrote (``pip install vot-toolkit``
does it, and ``pip check`` passes): dcfkit says so, with the packages installed and what to run
(the ``clobbered_opencv`` fixture of conftest.py stands in for such an install)."""
from __future__ import annotations

import importlib.metadata
import shlex
import sys
import tomllib
import types
from pathlib import Path

import pytest

from dcfkit import opencv_check
from dcfkit.cli import main

PIP = f"{shlex.quote(sys.executable)} -m pip"  # this interpreter's pip, not whichever is first on PATH
REPAIR = (f'{PIP} uninstall -y opencv-python && {PIP} install --force-reinstall --no-deps '
          '"opencv-contrib-python-headless==4.14.0.94"')


def test_the_contrib_build_has_csrt_in_legacy_or_at_the_top():
    assert opencv_check.has_contrib(types.SimpleNamespace(legacy=types.SimpleNamespace(TrackerCSRT_create=1)))
    assert opencv_check.has_contrib(types.SimpleNamespace(TrackerCSRT_create=1))
    assert not opencv_check.has_contrib(types.SimpleNamespace(legacy=types.SimpleNamespace()))
    assert not opencv_check.has_contrib(types.SimpleNamespace())


def test_the_installed_cv2_of_the_tests_is_the_contrib_build():
    assert opencv_check.contrib_problem() is None


def test_a_clobbered_cv2_is_said_with_the_packages_and_the_repair(clobbered_opencv):
    said = opencv_check.contrib_problem()
    assert said.startswith(f"OpenCV's contrib modules are missing (no cv2.legacy.TrackerCSRT_create in OpenCV "
                           f"5.0.0 at {clobbered_opencv.__file__})")
    assert ("OpenCV packages installed: opencv-contrib-python-headless 4.14.0.94, opencv-python 5.0.0.93. They all "
            "install the same cv2 folder") in said
    assert said.endswith(f"Repair with: {REPAIR}")


@pytest.mark.parametrize("installed, command", [
    ({"opencv-python": "4.10.0.84"},
     f'{PIP} uninstall -y opencv-python && {PIP} install --force-reinstall --no-deps '
     '"opencv-contrib-python-headless>=4.8,<5"'),
    ({"opencv-contrib-python-headless": "4.9.0.80"},
     f'{PIP} install --force-reinstall --no-deps "opencv-contrib-python-headless==4.9.0.80"'),
    ({"opencv-python-headless": "4.9.0.80", "opencv-contrib-python": "4.9.0.80",
      "opencv-contrib-python-headless": "4.9.0.80"},
     f'{PIP} uninstall -y opencv-python-headless opencv-contrib-python && {PIP} install --force-reinstall --no-deps '
     '"opencv-contrib-python-headless==4.9.0.80"'),
])
def test_the_repair_removes_the_others_then_rewrites_the_contrib_build(installed, command):
    assert opencv_check.repair_command(installed) == command


def test_installed_opencv_reads_the_package_metadata(monkeypatch):
    versions = {"opencv-python": "5.0.0.93", "opencv-contrib-python-headless": "4.14.0.94"}

    def version(name):
        if name not in versions:
            raise importlib.metadata.PackageNotFoundError(name)
        return versions[name]

    monkeypatch.setattr(importlib.metadata, "version", version)
    assert opencv_check.installed_opencv() == {"opencv-python": "5.0.0.93",
                                               "opencv-contrib-python-headless": "4.14.0.94"}


def test_the_contrib_requirement_is_the_one_pyproject_declares():
    pyproject = tomllib.loads((Path(__file__).resolve().parents[1] / "pyproject.toml").read_text())
    assert opencv_check.CONTRIB_REQUIREMENT in pyproject["project"]["dependencies"]


def test_the_color_names_table_error_says_how_to_repair(clobbered_opencv):
    from dcfkit.components.features.colornames import _from_opencv
    from dcfkit.errors import ConfigError

    with pytest.raises(ConfigError, match="Color Names table was not found .* OpenCV's contrib modules are missing") \
            as caught:
        _from_opencv()
    assert REPAIR in str(caught.value)


def test_the_opencv_baselines_error_says_how_to_repair(clobbered_opencv):
    from dcfkit.integrations.opencv import OpenCVUnavailable, opencv_tracker

    with pytest.raises(OpenCVUnavailable, match=r"OpenCV tracker CSRT is not in this OpenCV build \(available: "
                                                r"none\); OpenCV's contrib modules are missing") as caught:
        opencv_tracker("CSRT")
    assert REPAIR in str(caught.value)


def test_components_warns_of_a_clobbered_cv2(clobbered_opencv, capsys):
    assert main(["components", "--kind", "feature"]) == 0
    captured = capsys.readouterr()
    assert "colornames" in captured.out
    assert captured.err == f"warning: {opencv_check.contrib_problem()}\n" and REPAIR in captured.err

"""Where results came from: the git state of the code that made them, in every sidecar."""
from __future__ import annotations

import json
import shutil
import subprocess
from pathlib import Path

import cv2
import pytest

import dcfkit
from dcfkit.analysis.report_html.provenance import describe_sources
from dcfkit.config import load_config
from dcfkit.datasets import Sequence
from dcfkit.datasets.synthetic import make_sequence
from dcfkit.store import code_state, provenance
from dcfkit.running.evaluation import run_one_pass
from dcfkit.store.provenance import git_state, package_source

needs_git = pytest.mark.skipif(shutil.which("git") is None, reason="git is not installed")


def git(folder: Path, *args: str) -> str:
    return subprocess.run(["git", "-C", str(folder), *args], check=True, capture_output=True, text=True).stdout.strip()


@needs_git
def test_the_git_state_of_a_work_tree(tmp_path):
    repo = tmp_path / "repo"
    (repo / "pkg").mkdir(parents=True)
    (repo / "pkg" / "__init__.py").write_text("x = 1\n")
    git(repo, "init", "-q")
    git(repo, "-c", "user.name=t", "-c", "user.email=t@t", "add", ".")
    git(repo, "-c", "user.name=t", "-c", "user.email=t@t", "commit", "-qm", "one")
    git_state.cache_clear()
    assert git_state(str(repo)) == {"commit": git(repo, "rev-parse", "HEAD"), "dirty": False}
    (repo / "pkg" / "__init__.py").write_text("x = 2\n")
    (repo / "untracked.txt").write_text("not part of the code\n")
    git_state.cache_clear()
    assert git_state(str(repo))["dirty"] is True
    assert package_source("no-such-distribution", str(repo / "pkg")) == git_state(str(repo))
    assert git_state(str(tmp_path)) is None and package_source("no-such-distribution") is None
    git(repo, "worktree", "add", "-q", str(tmp_path / "other"), "HEAD")  # its .git is a file
    git_state.cache_clear()
    assert git_state(str(tmp_path / "other")) == {"commit": git(repo, "rev-parse", "HEAD"), "dirty": False}


def test_dcfkit_records_the_commit_it_runs_from_or_none(tmp_path):
    top = Path(dcfkit.__file__).resolve().parents[1]
    expected = git_state(str(top))  # a checkout: its commit; an installed copy: pip's record or nothing
    found = provenance.sources([])
    assert set(found) == {"dcfkit"}
    if expected is not None:
        assert found["dcfkit"] == {**expected, "code": code_state.box_code()}
    assert describe_sources(found).startswith("dcfkit ")


def test_every_sidecar_holds_the_source(tmp_path):
    syn = make_sequence(n_frames=4, size=(60, 80), target=(12, 14))
    frames = []
    for i, image in enumerate(syn.frames):
        frames.append(tmp_path / f"{i:04d}.png")
        cv2.imwrite(str(frames[-1]), image)
    seq = Sequence("syn", tuple(frames), syn.ground_truth, {}, "synthetic")
    run_one_pass(load_config("kcf"), [seq], tmp_path / "out", progress=False)
    meta = json.loads((tmp_path / "out" / "kcf" / "syn.json").read_text())
    assert meta["source"] == provenance.sources([])

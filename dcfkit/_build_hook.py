"""A build step for setuptools (``cmdclass`` in pyproject.toml), never imported by dcfkit: a
wheel built from a git checkout (``pip install .``) carries ``dcfkit/_source.json``, the
checkout's commit and whether tracked files had uncommitted changes, which
:func:`dcfkit.store.code_state.built_source` reads. Standard library and setuptools only:
it runs in the build environment, before dcfkit or its dependencies are installed."""
from __future__ import annotations

import json
import os
import subprocess
from pathlib import Path

from setuptools.command.build_py import build_py

CHECKOUT = Path(__file__).resolve().parents[1]


def checkout_state(folder: Path) -> dict | None:
    """``{"commit", "dirty"}`` of the git work tree at ``folder``, or None (no git, not a checkout)."""
    if not (folder / ".git").exists():
        return None
    try:
        runs = [subprocess.run(["git", "-C", str(folder), *args], capture_output=True, text=True, timeout=10)
                for args in (("rev-parse", "HEAD"), ("status", "--porcelain", "--untracked-files=no"))]
    except (OSError, subprocess.SubprocessError):
        return None
    if any(r.returncode != 0 for r in runs):
        return None
    return {"commit": runs[0].stdout.strip(), "dirty": bool(runs[1].stdout.strip())}


class BuildPy(build_py):
    """setuptools' ``build_py``, then ``_source.json`` beside the built package (not for an
    editable install: that runs from the checkout, whose git state is read live)."""

    def run(self):
        super().run()
        state = checkout_state(CHECKOUT)
        if state is None or getattr(self, "editable_mode", False):
            return
        target = Path(self.build_lib) / "dcfkit" / "_source.json"
        os.makedirs(target.parent, exist_ok=True)
        target.write_text(json.dumps(state) + "\n", encoding="utf-8")

"""Is the installed ``cv2`` OpenCV's contrib build, which dcfkit needs?

Two things dcfkit reads exist in the contrib build only: the Color Names table, compiled into
its tracking module (:mod:`dcfkit.components.features.colornames`), and the CSRT, KCF and MOSSE trackers
(:mod:`dcfkit.integrations.opencv`). The four OpenCV packages on PyPI (``opencv-python``,
``opencv-python-headless``, ``opencv-contrib-python`` and dcfkit's
``opencv-contrib-python-headless``) all install the same ``cv2`` folder: the one installed
last overwrites the others' files while pip keeps every one listed as installed, so ``pip
check`` sees nothing wrong (``pip install vot-toolkit`` does this: it requires
``opencv-python``). The contrib modules are then gone, and a ``cv2/legacy`` folder left
behind still imports, empty. :func:`contrib_problem` says so and what to run; :func:`contrib_advice`
is what the features that need the contrib build say when it is missing.
"""
from __future__ import annotations

import importlib.metadata
import shlex
import sys
from types import ModuleType
from typing import Mapping

CONTRIB = "opencv-contrib-python-headless"
CONTRIB_REQUIREMENT = f"{CONTRIB}>=4.8,<5"  # as pyproject.toml's dependencies say (a test checks)
DISTRIBUTIONS = ("opencv-python", "opencv-python-headless", "opencv-contrib-python", CONTRIB)


def has_contrib(cv2: ModuleType) -> bool:
    """Whether ``cv2`` has the contrib tracking module: CSRT, in ``cv2.legacy`` or at the top."""
    legacy = getattr(cv2, "legacy", None)
    return hasattr(legacy, "TrackerCSRT_create") or hasattr(cv2, "TrackerCSRT_create")


def installed_version(name: str) -> str | None:
    """The version of the installed package ``name``, or None."""
    try:
        return importlib.metadata.version(name)
    except importlib.metadata.PackageNotFoundError:
        return None


def installed_opencv() -> dict[str, str]:
    """The OpenCV packages pip has installed: name -> version."""
    return {name: version for name in DISTRIBUTIONS if (version := installed_version(name))}


def repair_command(installed: Mapping[str, str]) -> str:
    """Remove the other OpenCV packages, then rewrite the contrib build's files (at its installed
    version; ``--no-deps`` leaves numpy alone). pip is this interpreter's: the ``pip`` first on
    PATH may be another environment's (vot-toolkit's own, say, which needs its opencv-python)."""
    pip = f"{shlex.quote(sys.executable)} -m pip"
    others = [name for name in installed if name != CONTRIB]
    wanted = f"{CONTRIB}=={installed[CONTRIB]}" if CONTRIB in installed else CONTRIB_REQUIREMENT
    remove = f"{pip} uninstall -y {' '.join(others)} && " if others else ""
    return f'{remove}{pip} install --force-reinstall --no-deps "{wanted}"'


def contrib_problem(cv2: ModuleType | None = None, installed: Mapping[str, str] | None = None) -> str | None:
    """None if ``cv2`` (default: the one Python imports) has OpenCV's contrib modules; else what
    is wrong, the OpenCV packages installed (default: :func:`installed_opencv`) and the command
    that repairs it."""
    if cv2 is None:
        import cv2  # deferred: the check costs nothing until a caller needs OpenCV anyway
    if has_contrib(cv2):
        return None
    installed = installed_opencv() if installed is None else installed
    listed = ", ".join(f"{name} {version}" for name, version in installed.items()) or "none"
    said = (f"OpenCV's contrib modules are missing (no cv2.legacy.TrackerCSRT_create in OpenCV "
            f"{getattr(cv2, '__version__', '?')} at {getattr(cv2, '__file__', '?')}): dcfkit reads the Color Names "
            f"table and the CSRT, KCF and MOSSE baselines from them. OpenCV packages installed: {listed}.")
    if len(installed) > 1:
        said += (" They all install the same cv2 folder, and the one installed last overwrote the contrib build's "
                 "files (pip check does not notice).")
    if installed_version("vot-toolkit"):
        said += " vot-toolkit requires opencv-python: give it an environment of its own (docs/integrations.md)."
    return f"{said} Repair with: {repair_command(installed)}"


def contrib_advice(cv2: ModuleType | None = None) -> str:
    """What to do when a contrib feature is missing from ``cv2``: :func:`contrib_problem`'s
    diagnosis and repair when another OpenCV package overwrote it, else install the contrib build."""
    return contrib_problem(cv2) or f"install {CONTRIB}"


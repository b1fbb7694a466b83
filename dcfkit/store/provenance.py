"""Where a result came from: the run key naming what decides its boxes, and the command,
machine and versions that made it."""
from __future__ import annotations

import contextlib
import contextvars
import dataclasses
import functools
import hashlib
import importlib.metadata
import json
import os
import platform
import re
import shlex
import subprocess
import sys
import urllib.parse
from datetime import datetime, timezone
from pathlib import Path
from typing import Mapping

import numpy as np

from dcfkit import __version__
from dcfkit.config.slots import components
from dcfkit.registry import get_registry
from dcfkit.store.code_state import box_code, built_source
from dcfkit.store.platforms import cpu_model

_COMMAND: contextvars.ContextVar[list | None] = contextvars.ContextVar("dcfkit_command", default=None)


LABEL_KEYS = ("name", "description")  # config keys that never change a box


def dcfkit_version() -> str:
    """``dcfkit.__version__`` (part of every run key)."""
    return __version__


def json_default(obj):
    """``json.dumps`` fallback for numpy values, dataclasses and sets."""
    if isinstance(obj, np.generic):
        return obj.item()
    if isinstance(obj, np.ndarray):
        return obj.tolist()
    if dataclasses.is_dataclass(obj) and not isinstance(obj, type):
        return dataclasses.asdict(obj)
    if isinstance(obj, (set, frozenset)):
        return sorted(obj)
    return str(obj)


def plugin_versions(config: Mapping) -> list[str]:
    """``"package version"`` of each installed plugin whose components ``config`` uses."""
    used = components(config)
    return get_registry().plugin_versions(used) if used else []  # e.g. an OpenCV baseline: no registry


def run_key(config: Mapping, version: str | None = None, rule: str | None = None,
            code: str | None = None) -> str:
    """The identity of a run: 16 hex digits of SHA-256 over the canonical JSON (sorted keys)
    of ``config`` without its ``name`` and ``description`` (they change no box), the dcfkit
    version, the digest of dcfkit's box code (``code``, default
    :func:`~dcfkit.store.code_state.box_code`: an edited tracker gives new results at the
    same version), the versions of the plugins whose components the config uses (a plugin's
    new release gives new results; configs of built-ins only keep their keys), and the
    experiment's ``rule`` when it has one (:attr:`~dcfkit.experiments.base.Experiment.rule`:
    the reset-based experiment's failures restart its runs, so its boxes depend on it)."""
    payload = {"config": {k: v for k, v in config.items() if k not in LABEL_KEYS},
               "dcfkit": version if version is not None else dcfkit_version(),
               "code": code if code is not None else box_code()}
    plugins = plugin_versions(config)
    if plugins:
        payload["plugins"] = plugins
    if rule is not None:
        payload["rule"] = rule
    text = json.dumps(payload, sort_keys=True, separators=(",", ":"), default=json_default)
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def now() -> str:
    return datetime.now(timezone.utc).isoformat(timespec="seconds")


@contextlib.contextmanager
def running_command(argv: list[str]):
    """Within: :func:`invocation` says ``argv`` (the CLI's ``dcfkit ...`` when its ``main`` is
    called with arguments, as tests and scripts do, rather than their own process's)."""
    token = _COMMAND.set(list(argv))
    try:
        yield
    finally:
        _COMMAND.reset(token)


def without_home(text: str) -> str:
    """``text`` with the user's home folder written ``~``: what dcfkit writes to files that are
    shared (sidecars, reports) names no user (docs/evaluation.md, "What is recorded")."""
    home = str(Path.home()).rstrip("/\\")
    return re.sub(re.escape(home) + r"(?![\w.-])", "~", text) if len(home) > 1 else text  # not /home/al of /home/alice


def shared_path(path, base) -> str:
    """``path`` as a file in folder ``base`` names it: relative to ``base`` (``../results/kcf``),
    :func:`without_home` if it cannot be (another drive) or ``base`` is None."""
    if base is not None:
        with contextlib.suppress(ValueError):
            return Path(os.path.relpath(Path(path).resolve(), Path(base).resolve())).as_posix()
    return without_home(str(path))


def invocation() -> dict:
    """How this command was given: ``{"command": argv}``, the home folder written ``~``
    (:func:`without_home`; the working directory and the host are not recorded). The
    process's ``sys.argv`` (with ``python -m PACKAGE`` as the first words when it was run so:
    ``sys.argv[0]`` is then the path of ``__main__.py``, which does not run alone) unless
    :func:`running_command` says otherwise. Result sidecars record the client's."""
    argv = _COMMAND.get()
    if argv is None:
        argv = list(sys.argv)
        spec = getattr(sys.modules.get("__main__"), "__spec__", None)
        if spec is not None and spec.name.endswith(".__main__"):
            argv[:1] = ["python", "-m", spec.name.removesuffix(".__main__")]
        elif argv:
            argv[0] = os.path.basename(argv[0]) or argv[0]
    return {"command": [without_home(a) for a in argv]}


def command_line(record: Mapping) -> str | None:
    """A sidecar's or :func:`invocation`'s command as one shell line, or None if not recorded."""
    argv = record.get("command")
    if not isinstance(argv, list) or not all(isinstance(a, str) for a in argv):
        return None
    return shlex.join(argv)


@functools.lru_cache(maxsize=1)
def machine() -> dict:
    """The machine this process runs on: OS, CPU model, cores, Python version (not its host
    name: sidecars are shared with the results)."""
    return {"system": platform.platform(terse=True), "cpu": cpu_model(),
            "cores": os.cpu_count(), "python": platform.python_version()}


@functools.lru_cache(maxsize=None)
def git_state(folder: str) -> dict | None:
    """``{"commit", "dirty"}`` of the git work tree whose top is ``folder`` (dirty: tracked files
    changed since the commit), or None if it is none or git cannot say."""
    if not os.path.exists(os.path.join(folder, ".git")):  # a folder, or a file in a worktree or submodule
        return None
    try:
        run = [subprocess.run(["git", "-C", folder, *args], capture_output=True, text=True, timeout=10)
               for args in (("rev-parse", "HEAD"), ("status", "--porcelain", "--untracked-files=no"))]
    except (OSError, subprocess.SubprocessError):  # no git, or it hung
        return None
    if any(r.returncode != 0 for r in run):
        return None
    return {"commit": run[0].stdout.strip(), "dirty": bool(run[1].stdout.strip())}


@functools.lru_cache(maxsize=None)
def package_source(distribution: str, package_dir: str | None = None) -> dict | None:
    """Where an installed package's code came from: the git state of the work tree it runs from
    (``package_dir``'s parent holds ``.git``: a checkout, an editable install), else the state
    its build recorded (``pip install .`` of a checkout: :func:`~dcfkit.store.code_state.built_source`),
    else the commit pip recorded for a VCS install or the git state of the folder of an
    editable one (PEP 610 ``direct_url.json``); None when nothing says (a release from an index)."""
    if package_dir is not None and (found := git_state(os.path.dirname(os.path.abspath(package_dir)))):
        return found
    if package_dir is not None and (found := built_source(Path(package_dir))):
        return found
    try:
        direct = json.loads(importlib.metadata.distribution(distribution).read_text("direct_url.json") or "null")
    except (importlib.metadata.PackageNotFoundError, ValueError):
        return None
    if not isinstance(direct, dict):
        return None
    if isinstance(direct.get("vcs_info"), dict) and direct["vcs_info"].get("commit_id"):
        return {"commit": str(direct["vcs_info"]["commit_id"]), "dirty": None}
    url = str(direct.get("url", ""))
    if url.startswith("file://") and isinstance(direct.get("dir_info"), dict) and direct["dir_info"].get("editable"):
        return git_state(urllib.parse.unquote(url.removeprefix("file://")))
    return None


def sources(plugins: list[str]) -> dict:
    """:func:`package_source` of dcfkit, with ``code`` (:func:`~dcfkit.store.code_state.box_code`),
    and of each of ``plugins`` (``"name version"``, as :func:`plugin_versions` lists them), by
    distribution name (results sidecars record it)."""
    found = {"dcfkit": {**(package_source("dcfkit", str(Path(__file__).resolve().parents[1])) or {}),
                        "code": box_code()}}
    for plugin in plugins:
        name = plugin.rsplit(" ", 1)[0]
        found[name] = package_source(name)
    return found

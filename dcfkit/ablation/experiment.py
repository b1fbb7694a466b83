"""An ablation's experiment (:mod:`dcfkit.experiments`): which ones it can run, and where
their runs go."""
from __future__ import annotations

from pathlib import Path
from typing import Any

from dcfkit.errors import ConfigError, shown
from dcfkit.experiments import get_experiment

ABLATION_EXPERIMENTS = ("ope", "tre", "sre")  # scored as one-pass results are (dcfkit.experiments)


def check_experiment(value: Any, where: str) -> str:
    """``value`` as the name of an experiment an ablation can run, or a :class:`ConfigError`."""
    name = value.lower() if isinstance(value, str) else value
    if name not in ABLATION_EXPERIMENTS:
        reset = (" (reset-based runs: dcfkit eval --experiment reset, then dcfkit report --experiment reset)"
                 if name == "reset" else "")
        raise ConfigError(f"{where}: expected one of {', '.join(ABLATION_EXPERIMENTS)}, got {shown(value)}{reset}")
    return name


def runs_dir(job_folder: Path, experiment: str) -> Path:
    """Where a run key's runs of ``experiment`` go: its folder (:func:`dcfkit.ablation.spec.job_dir`),
    and that folder's ``<experiment>/`` but for one pass."""
    sub = get_experiment(experiment).folder
    return job_folder / sub if sub else job_folder

"""An ablation's experiment (:mod:`dcfkit.experiments`): which ones it can run, and how its
outputs name it."""
from __future__ import annotations

from typing import Any

from dcfkit.errors import ConfigError, shown
from dcfkit.analysis.setting import cut_phrase, experiment_line
from dcfkit.experiments import EXPERIMENTS


def ablation_experiments() -> tuple[str, ...]:
    """The experiments an ablation can run: those whose runs OTB's measures score, which its summary reads."""
    return tuple(name for name, e in EXPERIMENTS.items() if e.scoring == "otb")


def check_experiment(value: Any, where: str) -> str:
    """``value`` as the name of an experiment an ablation can run, or a :class:`ConfigError`."""
    name = value.lower() if isinstance(value, str) else value
    if name not in ablation_experiments():
        other = EXPERIMENTS.get(name) if isinstance(name, str) else None
        hint = (f" ({other.name} runs: dcfkit eval --experiment {other.name}, then dcfkit report --experiment "
                f"{other.name})" if other is not None else "")
        raise ConfigError(f"{where}: expected one of {', '.join(ablation_experiments())}, got {shown(value)}{hint}")
    return name


def cut_title(max_frames: int | None) -> str:
    """A smoke run's cut for a title, ``, first 50 frames (--max-frames 50)``; else ``""``."""
    return f", first {max_frames} frames (--max-frames {max_frames})" if max_frames else ""


def scope_title(experiment: str, max_frames: int | None = None) -> str:
    """What an ablation's scores are of, for its titles: the experiment's name in capitals
    (``TRE``) and a smoke run's :func:`cut_title`."""
    return experiment.upper() + cut_title(max_frames)


def scope_line(experiment: str, protocol: str, max_frames: int | None = None) -> str:
    """One line naming the runs an ablation scored: the report's
    :func:`~dcfkit.analysis.setting.experiment_line` with the protocol before a smoke run's cut,
    ``experiment TRE (...), each sequence's runs pooled, protocol otb; a smoke run: ...``."""
    return f"{experiment_line(experiment)}, protocol {protocol}{cut_phrase(max_frames)}"

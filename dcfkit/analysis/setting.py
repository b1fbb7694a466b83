"""What a report's numbers were measured on, in one line every table and file repeats: the
experiment (:mod:`dcfkit.experiments`) and the ``--max-frames`` cut of a smoke run, so that a
TRE table or a smoke run's table never passes for a full one-pass run's."""
from __future__ import annotations

from typing import Iterable

from dcfkit.datasets import Sequence
from dcfkit.experiments import Experiment, get_experiment


def cut_length(sequences: Iterable[Sequence]) -> int | None:
    """The N of ``--max-frames N`` when it cut any of ``sequences`` (:meth:`Sequence.head`
    keeps N frames of a longer sequence and marks it ``cut``), else None."""
    return next((len(s) for s in sequences if s.cut), None)


def experiment_line(experiment: str | Experiment, max_frames: int | None = None) -> str:
    """``experiment TRE (temporal robustness: 20 starts; Wu et al., ...), each sequence's runs
    pooled``, and ``; a smoke run: each sequence cut to its first N frames (--max-frames N)``."""
    exp = get_experiment(experiment)
    line = f"experiment {exp.name.upper()} ({exp.title}; {exp.source})"
    if exp.pooled:
        line += ", each sequence's runs pooled"
    return line + cut_phrase(max_frames)


def cut_phrase(max_frames: int | None) -> str:
    """``; a smoke run: ...`` for a ``--max-frames`` cut, else nothing."""
    if max_frames is None:
        return ""
    return f"; a smoke run: each sequence cut to its first {max_frames} frames (--max-frames {max_frames})"


def experiment_record(experiment: str | Experiment) -> dict:
    """The experiment as plain data (``report.json``, ``reset.json``)."""
    exp = get_experiment(experiment)
    return {"name": exp.name, "title": exp.title, "source": exp.source}

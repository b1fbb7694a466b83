"""Experiments: which runs a tracker makes of each sequence (docs/evaluation.md, "Experiments").

``ope`` runs once from frame 1's ground truth; ``tre`` and ``sre`` (Wu et al., TPAMI 2015) run
from 20 later starts and from 12 perturbed first boxes (:mod:`dcfkit.experiments.otb`);
``reset`` (VOT) runs once, re-initialised after each failure (:mod:`dcfkit.experiments.vot`).
A run is a :class:`~dcfkit.datasets.Sequence` of its own: its frames from the start, its
``start_box``, and a name ``<sequence>_<k>`` (k from 001), so each is stored, resumed and
scored as a one-pass result is. One-pass results stay in ``OUT/<tracker>/``; the others go to
``OUT/<tracker>/<experiment>/``.
"""
from __future__ import annotations

import dataclasses
from typing import Callable, Iterable

from dcfkit.datasets import Sequence
from dcfkit.errors import DcfkitError, shown
from dcfkit.experiments.otb import sre_runs, tre_runs

__all__ = ["EXPERIMENTS", "Experiment", "get_experiment", "runs_by_sequence"]


@dataclasses.dataclass(frozen=True)
class Experiment:
    """``runs(sequence)`` gives the runs of one sequence; ``folder`` is the sub-folder of a
    tracker's results that holds them (``""`` for one-pass results); ``resets`` marks VOT's
    reset-based runs, which re-initialise the tracker after each failure; ``first_box``
    whether the runs need frame 1's ground truth (TRE and reset-based runs start at the first
    valid one)."""

    name: str
    title: str
    source: str
    runs: Callable[[Sequence], list[Sequence]]
    folder: str
    resets: bool = False
    first_box: bool = True


def _one_run(seq: Sequence) -> list[Sequence]:
    return [seq]


EXPERIMENTS: dict[str, Experiment] = {e.name: e for e in (
    Experiment("ope", "one-pass evaluation", "Wu et al., TPAMI 2015", _one_run, ""),
    Experiment("tre", "temporal robustness: 20 starts", "Wu et al., TPAMI 2015; OTB toolkit splitSeqTRE.m",
               tre_runs, "tre", first_box=False),
    Experiment("sre", "spatial robustness: 8 shifts, 4 scales", "Wu et al., TPAMI 2015; OTB toolkit shiftInitBB.m",
               sre_runs, "sre"),
    Experiment("reset", "reset-based: re-initialised 5 frames after each failure",
               "Kristan et al., TPAMI 2016 (VOT2016); vot-toolkit", _one_run, "reset", resets=True, first_box=False),
)}


def get_experiment(experiment: str | Experiment) -> Experiment:
    """The :class:`Experiment` named ``experiment``; an Experiment passes through."""
    if isinstance(experiment, Experiment):
        return experiment
    try:
        return EXPERIMENTS[str(experiment).lower()]
    except KeyError:
        raise DcfkitError(f"unknown experiment {shown(experiment)}; one of: {', '.join(EXPERIMENTS)}") from None


def runs_by_sequence(sequences: Iterable[Sequence], experiment: str | Experiment) -> dict[str, list[Sequence]]:
    """Sequence name -> its runs in ``experiment``."""
    runs = get_experiment(experiment).runs
    return {seq.name: runs(seq) for seq in sequences}

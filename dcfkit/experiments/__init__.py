"""Experiments: which runs a tracker makes of each sequence (docs/evaluation.md, "Experiments").

``ope`` runs once from frame 1's ground truth; ``tre`` and ``sre`` (Wu et al., TPAMI 2015) run
from 20 later starts and from 12 perturbed first boxes (:mod:`dcfkit.experiments.otb`);
``reset`` (VOT) runs once, re-initialised after each failure (:mod:`dcfkit.experiments.vot`).
A run is a :class:`~dcfkit.datasets.Sequence` of its own: its frames from the start, its
``start_box``, and a name ``<sequence>_<k>`` (k from 001), so each is stored, resumed and
scored as a one-pass result is. One-pass results stay in ``OUT/<tracker>/``; the others go to
``OUT/<tracker>/<experiment>/``. A TRE or SRE run that no tracker can start from is left out
(:func:`left_out_runs` says why, and a warning when its sequence's runs are made); its
sequence is scored on the others.
"""
from __future__ import annotations

import warnings
from typing import Iterable

from dcfkit.datasets import DatasetWarning, Sequence
from dcfkit.errors import DcfkitError, shown
from dcfkit.experiments.base import Experiment, run_identity
from dcfkit.experiments.otb import sre_plan, tre_plan
from dcfkit.experiments.starts import Plan
from dcfkit.experiments.reset import ResetExperiment

__all__ = ["EXPERIMENTS", "Experiment", "get_experiment", "left_out_runs", "run_identity", "runs_by_sequence"]


def _one_run(seq: Sequence) -> Plan:
    return Plan([seq], {})


EXPERIMENTS: dict[str, Experiment] = {e.name: e for e in (
    Experiment("ope", "one-pass evaluation", "Wu et al., TPAMI 2015", _one_run, ""),
    Experiment("tre", "temporal robustness: 20 starts", "Wu et al., TPAMI 2015; OTB toolkit splitSeqTRE.m",
               tre_plan, "tre", first_box=False, pooled=True),
    Experiment("sre", "spatial robustness: 8 shifts, 4 scales", "Wu et al., TPAMI 2015; OTB toolkit shiftInitBB.m",
               sre_plan, "sre", pooled=True),
    ResetExperiment("reset", "reset-based: re-initialised 5 frames after each failure",
                    "Kristan et al., TPAMI 2016 (VOT2016); vot-toolkit", _one_run, "reset", first_box=False,
                    scoring="reset"),
)}


def get_experiment(experiment: str | Experiment, protocol: str | None = None) -> Experiment:
    """The :class:`Experiment` named ``experiment`` (an Experiment passes through), bound to the
    rule ``protocol`` names if it is one of the experiment's own (:meth:`Experiment.bind`)."""
    found = experiment if isinstance(experiment, Experiment) else EXPERIMENTS.get(str(experiment).lower())
    if found is None:
        raise DcfkitError(f"unknown experiment {shown(experiment)}; one of: {', '.join(EXPERIMENTS)}")
    return found.bind(protocol) if protocol is not None else found


_SAID: set[str] = set()  # the left-out runs warned of


def runs_by_sequence(sequences: Iterable[Sequence], experiment: str | Experiment) -> dict[str, list[Sequence]]:
    """Sequence name -> its runs in ``experiment``; a :class:`DatasetWarning` for each run left
    out (once per process)."""
    plan = get_experiment(experiment).plan
    found = {}
    for seq in sequences:
        runs, left_out = plan(seq)
        for why in [w for w in left_out.values() if w not in _SAID]:
            _SAID.add(why)  # once per process: a command makes a sequence's runs several times
            warnings.warn(f"{why}; left out, as the toolkit's run would stop at once: sequence {seq.name!r} is "
                          f"scored on its other {len(runs)} runs", DatasetWarning, stacklevel=2)
        found[seq.name] = runs
    return found


def left_out_runs(sequences: Iterable[Sequence], experiment: str | Experiment) -> dict[str, str]:
    """Run name -> why it is left out of ``experiment``: no tracker can start from its first box."""
    plan = get_experiment(experiment).plan
    return {name: why for seq in sequences for name, why in plan(seq).left_out.items()}

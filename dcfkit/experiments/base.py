"""What an experiment is: a strategy that owns the runs it makes of each sequence, how a run is
tracked, what of it enters the run key and the sidecar, and how its runs are scored
(docs/architecture.md, "Where to add"). The runner, scoring, the reports and the command line
call these methods; none of them tests an experiment's name."""
from __future__ import annotations

import dataclasses
from typing import Callable, Mapping

import numpy as np

from dcfkit.datasets import Sequence
from dcfkit.experiments.loop import track
from dcfkit.experiments.starts import Plan

Read = Callable[[int], np.ndarray]  # frame i (0-based) of the run's sequence, decoded
Tick = Callable[[], None]  # called after every tracked frame (progress bars)


def run_identity(run: Sequence) -> tuple:
    """What makes two runs of one sequence one run where their experiments track each run once
    (:attr:`Experiment.tracks_once`: OPE, TRE, SRE): the first frame's file, the number of
    frames and the first box (a run is its sequence from one frame to the end, so these fix its
    frames and ground truth)."""
    return str(run.frames[0]), len(run), tuple(np.asarray(run.init_box, dtype=np.float64).tolist())


@dataclasses.dataclass(frozen=True)
class Experiment:
    """An experiment whose runs are each tracked once from their first box (OPE, TRE, SRE).

    ``plan(sequence)`` gives a sequence's runs and those left out (:class:`Plan`); ``folder`` is
    the sub-folder of a tracker's results that holds them (``""``: the tracker's folder);
    ``first_box``: whether the runs need frame 1's ground truth; ``pooled``: whether a
    sequence's score pools several runs; ``scoring``: which scoring reads its runs (``"otb"``:
    OTB's success and precision, :func:`dcfkit.analysis.scoring.evaluate`; ``"reset"``: VOT's
    accuracy, failures and EAO, :mod:`dcfkit.analysis.reset_report`)."""

    name: str
    title: str
    source: str
    plan: Callable[[Sequence], Plan]
    folder: str
    first_box: bool = True
    pooled: bool = False
    scoring: str = "otb"

    def runs(self, seq: Sequence) -> list[Sequence]:
        return self.plan(seq).runs

    @property
    def rules(self) -> Mapping[str, object]:
        """The ``--protocol`` values that are this experiment's own rules (they change its runs,
        not only their scores); empty: it takes a scoring protocol."""
        return {}

    def bind(self, protocol: str | None) -> "Experiment":
        """This experiment with the rule ``protocol`` names, if it is one of :attr:`rules`."""
        return self

    @property
    def rule(self) -> str | None:
        """The name of the rule bound into the runs (part of the run key), or None."""
        return None

    @property
    def tracks_once(self) -> bool:
        """Whether each run is tracked once from its first box, by no rule of the experiment's
        own, and stored with nothing of the experiment's own: then two such experiments' runs
        with the same frames and first box are one run (OPE's and TRE's first, or SRE's shifts
        that leave the box where it is), made once
        (:meth:`dcfkit.running.plan.RunPlan.made_elsewhere`)."""
        kind = type(self)
        return (self.rule is None and kind.track is Experiment.track and kind.record is Experiment.record
                and kind.stored_elsewise is Experiment.stored_elsewise)

    def track(self, tracker, make_tracker: Callable[[], object], run: Sequence, read: Read,
              tick: Tick | None = None):
        """Track ``run`` with ``tracker`` (``make_tracker()`` makes another), frames read by ``read``;
        returns a :class:`~dcfkit.experiments.loop.Track`."""
        return track(tracker, (read(i) for i in range(len(run))), run.init_box,
                     (lambda *_: tick()) if tick else None)

    def record(self, result) -> dict:
        """What a run's sidecar records of the experiment, besides its boxes."""
        return {}

    def stored_elsewise(self, meta: Mapping | None) -> str | None:
        """Why a stored run (sidecar ``meta``) was made under other rules of this experiment, to be
        recomputed; None if it was not."""
        return None

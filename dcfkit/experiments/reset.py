"""VOT's reset-based experiment as a strategy (:class:`ResetExperiment`; its rules are
:mod:`dcfkit.experiments.vot`'s) and its frame loop: track,
and start a fresh tracker from the ground truth :data:`~dcfkit.experiments.vot.SKIP` frames
after each failure, or from the first frame after that whose ground truth a tracker can start
from (:func:`~dcfkit.experiments.starts.start_problem`), as vot-toolkit moves a start past
the frames it must not start on."""
from __future__ import annotations

import dataclasses
import itertools
from typing import Callable, Mapping

import numpy as np

from dcfkit.datasets import DatasetError, Sequence
from dcfkit.experiments.starts import start_problem
from dcfkit.experiments.base import Experiment, Read, Tick
from dcfkit.experiments.loop import Track, TrackerFailure, steps
from dcfkit.experiments.vot import DEFAULT_RULE, RULES, SKIP, ResetRule, get_rule, next_start


@dataclasses.dataclass
class ResetTrack(Track):
    """A :class:`Track` of a reset-based run: frames not tracked (between a failure and the
    next start) have NaN boxes, times and confidences; ``starts`` and ``failures`` are 0-based
    frame indices; ``moved`` maps a start made later than due (frame 1, or :data:`SKIP`
    frames after a failure) to the frame it was due; ``rule`` names the
    :class:`~dcfkit.experiments.vot.ResetRule` that decided the failures."""

    rule: str = DEFAULT_RULE
    starts: list[int] = dataclasses.field(default_factory=list)
    failures: list[int] = dataclasses.field(default_factory=list)
    moved: dict[int, int] = dataclasses.field(default_factory=dict)

    def record(self) -> dict:
        """The sidecar's ``resets``: the ``rule``, 1-based ``starts`` and ``failures``, as every frame
        number dcfkit shows, and, if a start was made later than due, ``moved``: ``[due, start]`` of each."""
        record = {"rule": self.rule, "starts": [i + 1 for i in self.starts],
                  "failures": [i + 1 for i in self.failures]}
        if self.moved:
            record["moved"] = [[due + 1, start + 1] for start, due in self.moved.items()]
        return record

    @property
    def fps(self) -> float | None:
        tracked = np.isfinite(self.times)
        total = float(self.times[tracked].sum())
        return int(tracked.sum()) / total if total > 0 else None


def track_with_resets(make_tracker: Callable[[], object], seq: Sequence, frame: Callable[[int], np.ndarray],
                      on_frame: Callable[[], None] | None = None, rule: str = DEFAULT_RULE) -> ResetTrack:
    """Run fresh trackers from ``make_tracker()`` through ``seq`` (frames read by ``frame(i)``),
    each from the ground truth, the first at frame 1 and the next :data:`SKIP` frames after
    each failure (a frame whose box does not overlap a valid ground truth by ``rule``'s
    overlap); a start moves on to the next frame whose ground truth is valid and inside the
    image (:func:`next_start`)."""
    n, found = len(seq), get_rule(rule)
    run = ResetTrack(np.full((n, 4), np.nan), np.full(n, np.nan), np.full((n, 3), np.nan), rule=found.name)
    due, size = 0, None  # the image size: unknown until a frame is read
    start = next_start(seq.ground_truth, due)
    while start is not None:
        image = frame(start)
        if size is None:
            size = image.shape[:2]
            if start_problem(seq.ground_truth[start], size) is not None:
                start = next_start(seq.ground_truth, start + 1, size)
                continue
        if start != due:
            run.moved[start] = due
        run.starts.append(start)
        failure = _segment(make_tracker(), seq, frame, start, image, run, on_frame, found)
        if failure is None:
            break
        run.failures.append(failure)
        due = failure + SKIP
        start = next_start(seq.ground_truth, due, size)
    if not run.starts:  # else scored as a run without a failure
        raise DatasetError(f"sequence {seq.name!r}: no frame's ground truth is valid and inside the image, so no "
                           f"reset-based run can start")
    return run


def _segment(tracker, seq: Sequence, frame: Callable[[int], np.ndarray], start: int, first: np.ndarray,
             run: ResetTrack, on_frame: Callable[[], None] | None, rule: ResetRule) -> int | None:
    """Track from ``start`` (its image ``first``, read) into ``run`` until a failure (its 0-based
    frame) or the end (None)."""
    frames = itertools.chain([first], (frame(i) for i in range(start + 1, len(seq))))
    try:
        for step in steps(tracker, frames, seq.ground_truth[start].copy()):
            i = start + step.index
            run.boxes[i], run.times[i], run.confidence[i] = step.box, step.seconds, step.confidence
            if on_frame is not None:
                on_frame()
            bounds = (step.image.shape[1], step.image.shape[0])
            if step.index > 0 and rule.failed(step.box, seq.ground_truth[i], bounds):
                return i
    except TrackerFailure as exc:  # steps numbers the frames from this start
        raise TrackerFailure(start + exc.frame, exc.detail) from exc.__cause__
    return None


def rule_of(meta: Mapping | None) -> str | None:
    """The rule a reset-based run's sidecar records (None: none, as dcfkit <= 0.9.0 wrote them)."""
    resets = (meta or {}).get("resets")
    return resets.get("rule") if isinstance(resets, dict) else None


@dataclasses.dataclass(frozen=True)
class ResetExperiment(Experiment):
    """VOT's reset-based experiment: one run of each sequence, a fresh tracker started from the
    ground truth :data:`SKIP` frames after each failure that ``reset_rule`` decides
    (:mod:`dcfkit.experiments.reset`); the rule is part of the run key and of the sidecar."""

    reset_rule: str = DEFAULT_RULE

    @property
    def rules(self) -> Mapping[str, ResetRule]:
        return RULES

    def bind(self, protocol: str | None) -> "ResetExperiment":
        return dataclasses.replace(self, reset_rule=get_rule(protocol).name)

    @property
    def rule(self) -> str:
        return self.reset_rule

    def track(self, tracker, make_tracker: Callable[[], object], run: Sequence, read: Read, tick: Tick | None = None):
        first = [tracker]  # the tracker made by the caller starts the run; each restart gets a fresh one
        return track_with_resets(lambda: first.pop() if first else make_tracker(), run, read, tick, self.reset_rule)

    def record(self, result) -> dict:
        return {"resets": result.record()}

    def stored_elsewise(self, meta: Mapping | None) -> str | None:
        if not isinstance((meta or {}).get("resets"), dict) or rule_of(meta) == self.reset_rule:
            return None
        return rule_of(meta) or "dcfkit <= 0.9.0's continuous overlap"

"""The frame loop of VOT's reset-based experiment (:mod:`dcfkit.experiments.vot`): track,
and start a fresh tracker from the ground truth :data:`~dcfkit.experiments.vot.SKIP` frames
after each failure."""
from __future__ import annotations

import dataclasses
from typing import Callable

import numpy as np

from dcfkit.datasets import Sequence
from dcfkit.experiments.vot import SKIP, overlap, valid_box
from dcfkit.running.tracking import Track, TrackerFailure, steps


@dataclasses.dataclass
class ResetTrack(Track):
    """A :class:`Track` of a reset-based run: frames not tracked (between a failure and the
    next start) have NaN boxes, times and confidences; ``starts`` and ``failures`` are 0-based
    frame indices."""

    starts: list[int] = dataclasses.field(default_factory=list)
    failures: list[int] = dataclasses.field(default_factory=list)

    @property
    def fps(self) -> float | None:
        tracked = np.isfinite(self.times)
        total = float(self.times[tracked].sum())
        return int(tracked.sum()) / total if total > 0 else None


def next_start(gt: np.ndarray, frame: int) -> int | None:
    """The first frame from ``frame`` (0-based) with a valid ground truth, or None."""
    for i in range(frame, len(gt)):
        if valid_box(gt[i]):
            return i
    return None


def track_with_resets(make_tracker: Callable[[], object], seq: Sequence, frame: Callable[[int], np.ndarray],
                      on_frame: Callable[[], None] | None = None) -> ResetTrack:
    """Run fresh trackers from ``make_tracker()`` through ``seq`` (frames read by ``frame(i)``),
    each from the ground truth, the first at frame 1 and the next :data:`SKIP` frames after
    each failure (a frame whose box does not overlap a valid ground truth)."""
    n = len(seq)
    run = ResetTrack(np.full((n, 4), np.nan), np.full(n, np.nan), np.full((n, 2), np.nan))
    start = next_start(seq.ground_truth, 0)
    while start is not None:
        run.starts.append(start)
        failed = _segment(make_tracker(), seq, frame, start, run, on_frame)
        if failed is None:
            break
        run.failures.append(failed)
        start = next_start(seq.ground_truth, failed + SKIP)
    return run


def _segment(tracker, seq: Sequence, frame: Callable[[int], np.ndarray], start: int, run: ResetTrack,
             on_frame: Callable[[], None] | None) -> int | None:
    """Track from ``start`` into ``run`` until a failure (its 0-based frame) or the end (None)."""
    frames = (frame(i) for i in range(start, len(seq)))
    try:
        for step in steps(tracker, frames, seq.ground_truth[start].copy()):
            i = start + step.index
            run.boxes[i], run.times[i], run.confidence[i] = step.box, step.seconds, step.confidence
            if on_frame is not None:
                on_frame()
            bounds = (step.image.shape[1], step.image.shape[0])
            if step.index > 0 and overlap(step.box, seq.ground_truth[i], bounds) <= 0:
                return i
    except TrackerFailure as exc:  # steps numbers the frames from this start
        raise TrackerFailure(start + exc.frame, exc.detail) from exc.__cause__
    return None

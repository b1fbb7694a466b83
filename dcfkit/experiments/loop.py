"""The one frame loop: initialise on the first frame, update on the rest, time, collect boxes.

Every run path uses :func:`steps`, which yields each frame as it is tracked: ``dcfkit track``
directly (it writes each box as it comes), an experiment's runs through :func:`track`, which
collects them (or, for VOT's restarts, :mod:`dcfkit.experiments.reset`), the demo and the benchmarks. A
tracker is any object with ``init(image, box)`` and ``update(image) -> box``; boxes are
``(x, y, w, h)`` floats, **0-based**. Frame numbers in messages are **1-based**, as in the
benchmarks' file names and annotations.
"""
from __future__ import annotations

import dataclasses
import time
from typing import Callable, Iterable, Iterator

import numpy as np

from dcfkit.errors import DcfkitError, shown

OnFrame = Callable[[int, np.ndarray, np.ndarray, object], None]


@dataclasses.dataclass
class Track:
    """What a run produced: ``boxes`` ``(N, 4)`` 0-based (frame 1: the initial box),
    ``times`` ``(N,)`` tracker seconds per frame (decoding excluded) and ``confidence``
    ``(N, 3)``, each frame's ``(peak, apce, score)`` (:mod:`dcfkit.tracker.confidence`; NaN for frame 1, held
    blank frames and trackers without ``last_confidence``; all NaN if not given)."""

    boxes: np.ndarray
    times: np.ndarray
    confidence: np.ndarray | None = None

    def __post_init__(self):
        if self.confidence is None:
            self.confidence = np.full((len(self.boxes), 3), np.nan)

    @classmethod
    def collected(cls, boxes: list, times: list, confidence: list) -> "Track":
        """A run's per-frame boxes, seconds and confidences, gathered as it went, as a Track."""
        return cls(np.array(boxes, dtype=np.float64).reshape(-1, 4), np.array(times, dtype=np.float64),
                   np.array(confidence, dtype=np.float64).reshape(-1, 3))

    @property
    def fps(self) -> float | None:
        total = float(self.times.sum())
        return len(self.times) / total if total > 0 else None


class TrackerFailure(DcfkitError):
    """The tracker raised or returned something that is not a box, on ``frame`` (1-based)."""

    def __init__(self, frame: int, message: str):
        super().__init__(f"frame {frame}: {message}")
        self.frame = frame
        self.detail = message


def as_box(value, frame: int) -> np.ndarray:
    """``value`` as a float64 ``(4,)`` box, or a :class:`TrackerFailure` saying what it was."""
    try:
        return np.asarray(value, dtype=np.float64).reshape(4)
    except (TypeError, ValueError):
        what = "the initial box is" if frame == 1 else "update() returned"
        raise TrackerFailure(frame, f"{what} {shown(value)}, expected 4 numbers (x, y, w, h)") from None


@dataclasses.dataclass(frozen=True)
class Step:
    """One tracked frame: ``index`` 0-based, the ``image``, its 0-based ``box`` ``(4,)``, the
    tracker's ``seconds`` on it and its ``confidence`` ``(peak, apce, score)``."""

    index: int
    image: np.ndarray
    box: np.ndarray
    seconds: float
    confidence: tuple[float, float, float]


def steps(tracker, frames: Iterable[np.ndarray], init_box) -> Iterator[Step]:
    """Run ``tracker`` through ``frames``, yielding each frame as it is tracked: ``init`` on the
    first with ``init_box``, ``update`` on each later one. Each frame's confidence is read from
    ``tracker.last_confidence`` after the frame's time is taken (:func:`confidence_of`). A
    tracker exception becomes a :class:`TrackerFailure` naming the frame and the call."""
    from dcfkit.tracker.confidence import confidence_of  # deferred: dcfkit.tracker loads the tracker's components

    for index, image in enumerate(frames):  # decoding happens here: not timed
        start = time.perf_counter()
        try:
            if index == 0:
                tracker.init(image, init_box)
                out = init_box
            else:
                out = tracker.update(image)
        except (KeyboardInterrupt, SystemExit):  # Ctrl-C, SIGTERM (Interrupted) and exit() end the run
            raise
        except BaseException as exc:  # a component's own BaseException subclass, too: its frame fails
            call = "init" if index == 0 else "update"
            said = str(exc).removeprefix(f"frame {index + 1}: ")  # the tracker's own errors name the frame
            raise TrackerFailure(index + 1, f"{call} raised {type(exc).__name__}: {said}") from exc
        seconds = time.perf_counter() - start
        confidence = confidence_of(tracker)
        yield Step(index, image, as_box(out, index + 1), seconds, confidence)


def track(tracker, frames: Iterable[np.ndarray], init_box, on_frame: OnFrame | None = None) -> Track:
    """Run ``tracker`` through ``frames`` (:func:`steps`) and collect the boxes, times and
    confidence. ``on_frame(index, image, box, tracker)`` is called after each frame (0-based
    index; progress bars, video writers). A caller that keeps the frames done before an error
    iterates :func:`steps` itself, as ``dcfkit track`` does."""
    boxes, times, confidence = [], [], []
    for step in steps(tracker, frames, init_box):
        boxes.append(step.box)
        times.append(step.seconds)
        confidence.append(step.confidence)
        if on_frame is not None:
            on_frame(step.index, step.image, step.box, tracker)
    return Track.collected(boxes, times, confidence)

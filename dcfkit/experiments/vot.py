"""VOT's reset-based experiment (Kristan et al., TPAMI 2016; the VOT2016 challenge).

The tracker starts from frame 1's ground truth. A frame whose box does not overlap its
ground truth is a **failure**; the tracker is started again, from the ground truth,
:data:`SKIP` frames later (the first frame from there with a valid ground truth), and the
frames between are not tracked. :mod:`dcfkit.analysis.reset_scores` scores these runs:
accuracy leaves out the :data:`BURN_IN` frames from each start.

Whether a box overlaps, and by how much, is a toolkit's rasterisation (:mod:`.raster`): a
:class:`ResetRule` of :data:`RULES` says which overlap decides a failure during the run and
which the accuracy and the EAO average (docs/evaluation.md, "Reset-based experiment").
"""
from __future__ import annotations

import dataclasses
from typing import Callable

import numpy as np

from dcfkit.errors import DcfkitError, shown
from dcfkit.experiments.starts import start_problem
from dcfkit.experiments.raster import NO_BOUNDS, trax2016_overlap, vottoolkit_overlap

__all__ = ["BURN_IN", "DEFAULT_RULE", "RULES", "SKIP", "ResetRule", "get_rule", "next_start", "valid_box"]

SKIP = 5  # frames from a failure to the next start (vot-toolkit's skip_initialize)
BURN_IN = 10  # frames from each start left out of accuracy, the start included
Size = tuple[float, float]  # an image's (width, height)


def valid_box(box) -> bool:
    """Whether ``box`` ``(x, y, w, h)`` is finite with a positive width and height."""
    b = np.asarray(box, dtype=np.float64).reshape(4)
    return bool(np.isfinite(b).all() and b[2] > 0 and b[3] > 0)


def _valid(boxes: np.ndarray) -> np.ndarray:
    return np.isfinite(boxes).all(axis=1) & (boxes[:, 2] > 0) & (boxes[:, 3] > 0)


def _guarded(overlap: Callable[[np.ndarray, np.ndarray, Size | None], np.ndarray]):
    """``overlap`` of the pairs where both boxes are valid; 0 where only the ground truth is
    (no box, or an empty one: a failure), NaN where it is not (a frame without ground truth is
    never a failure: the toolkits' overlap with a missing region is NaN)."""
    def guarded(boxes, gts, size: Size | None) -> np.ndarray:
        boxes = np.asarray(boxes, dtype=np.float64).reshape(-1, 4)
        gts = np.asarray(gts, dtype=np.float64).reshape(-1, 4)
        out = np.where(_valid(gts), 0.0, np.nan)
        both = _valid(gts) & _valid(boxes)
        if both.any():
            out[both] = overlap(boxes[both], gts[both], size)
        return out
    return guarded


@dataclasses.dataclass(frozen=True)
class ResetRule:
    """One toolkit's overlaps of boxes ``(N, 4)`` and ground truth ``(N, 4)`` in an image
    ``size``: ``failure`` decides the run's failures (overlap <= 0, never NaN), ``accuracy``
    and ``eao`` are those the scores average. ``tables``: the published tables it reproduces."""

    name: str
    title: str
    tables: str
    failure: Callable[[np.ndarray, np.ndarray, Size | None], np.ndarray]
    accuracy: Callable[[np.ndarray, np.ndarray, Size | None], np.ndarray]
    eao: Callable[[np.ndarray, np.ndarray, Size | None], np.ndarray]

    def failed(self, box, gt, size: Size | None) -> bool:
        """Whether ``box`` fails on ``gt`` (its ``failure`` overlap is <= 0)."""
        return bool(self.failure(box, gt, size)[0] <= 0)


def _trax(edge: float | None, inclusive: bool):
    """trax 2016's overlap bounded to ``[0, width + edge] x [0, height + edge]`` (None: unbounded)."""
    def overlap(boxes, gts, size):
        bounds = NO_BOUNDS if edge is None or size is None else (0, 0, size[0] + edge, size[1] + edge)
        return trax2016_overlap(boxes, gts, bounds, inclusive)
    return overlap


def _vottoolkit(boxes, gts, size):
    if size is None:
        raise ValueError("vot-toolkit's overlap is bounded by the image: its size is needed")
    return vottoolkit_overlap(boxes, gts, size)


RULES: dict[str, ResetRule] = {r.name: r for r in (
    # the trax client tests failures on rectangle regions in [0, W] x [0, H]; the MATLAB analysis
    # builds its own polygons, unbounded for the accuracy ranking (create_sequence_selectors.m passes
    # no sequence), in [0, W - 1] x [0, H - 1] for the EAO (estimate_accuracy.m with the sequence)
    ResetRule("vot2016", "VOT2016 MATLAB toolkit, trax 2016 region overlap",
              "the VOT2016 challenge's accuracy, robustness and EAO tables (Kristan et al., ECCV-W 2016)",
              _guarded(_trax(0.0, True)), _guarded(_trax(None, False)), _guarded(_trax(-1.0, False))),
    ResetRule("vot-toolkit", "vot-toolkit 0.9 (Python), rounded boxes in the image",
              "tables made with vot-toolkit 0.9's supervised experiment and analyses",
              _guarded(_vottoolkit), _guarded(_vottoolkit), _guarded(_vottoolkit)),
)}
DEFAULT_RULE = "vot2016"


def get_rule(name: str | None) -> ResetRule:
    """The :class:`ResetRule` named ``name`` (None: :data:`DEFAULT_RULE`)."""
    try:
        return RULES[DEFAULT_RULE if name is None else name]
    except KeyError:
        raise DcfkitError(f"unknown reset-based protocol {shown(name)}; one of: {', '.join(RULES)}") from None


def next_start(gt: np.ndarray, frame: int, image_size: tuple[int, int] | None = None) -> int | None:
    """The first frame from ``frame`` (0-based) with a valid ground truth that, when the
    ``(height, width)`` is given, a tracker can start from (:func:`start_problem`), or None."""
    for i in range(frame, len(gt)):
        if valid_box(gt[i]) and (image_size is None or start_problem(gt[i], image_size) is None):
            return i
    return None

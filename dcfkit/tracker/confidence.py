"""Per-frame confidence of a detection, read from its response map R (no box changes).

``peak`` is max R on the grid (its scale is the filter's: comparable along one run only);
``apce`` is the average peak-to-correlation energy of Wang et al. (CVPR 2017),
``|R_max - R_min|² / mean((R - R_min)²)`` over the map: high for one sharp peak, low for
several peaks or spread energy (docs/evaluation.md says why APCE, not the PSR); ``score`` is
how sure the tracker is that the target is present, the one number long-term measures
threshold: its reliability component's score (:mod:`dcfkit.components.reliability`, 1 at its
threshold), else the peak. Frames without a response (frame 1, frames held as blank) have
:data:`NO_CONFIDENCE`; a flat map has APCE 0.
"""
from __future__ import annotations

import dataclasses
import math

import numpy as np

from dcfkit.numerics.response import apce


@dataclasses.dataclass(frozen=True)
class Confidence:
    """``peak`` (max of the response map), ``apce`` (:func:`apce`) and the presence ``score`` of
    one frame; NaN when the frame has no response (frame 1, a held blank frame)."""

    peak: float
    apce: float
    score: float

    @classmethod
    def of(cls, response: np.ndarray | None, score: float | None = None) -> Confidence:
        """The confidence of a response map (any layout: centred or not) with a reliability
        ``score`` (None: the peak), or :data:`NO_CONFIDENCE` for no map."""
        if response is None:
            return NO_CONFIDENCE
        r = np.asarray(response, dtype=np.float64)
        peak = float(r.max())
        return cls(peak, apce(r), peak if score is None else float(score))

    def as_tuple(self) -> tuple[float, float, float]:
        return (self.peak, self.apce, self.score)


NO_CONFIDENCE = Confidence(math.nan, math.nan, math.nan)


def confidence_of(tracker) -> tuple[float, float, float]:
    """``(peak, apce, score)`` of ``tracker``'s last frame: its ``last_confidence`` if it has one
    (any object with ``peak`` and ``apce``; without ``score``, the peak is the score), else NaN:
    e.g. an OpenCV baseline, or a tracker whose ``last_confidence`` cannot be read (a
    diagnostic never fails a run)."""
    try:
        c = getattr(tracker, "last_confidence", None)
        if c is None:
            return NO_CONFIDENCE.as_tuple()
        peak = float(c.peak)
        return (peak, float(c.apce), float(getattr(c, "score", peak)))
    except Exception:  # noqa: BLE001 - read-only diagnostic
        return NO_CONFIDENCE.as_tuple()

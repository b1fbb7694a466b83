"""Per-frame confidence of a detection, read from its response map (read-only: no box changes).

:class:`Confidence` holds two numbers of the response map R of the chosen search scale:

``peak``
    max R, the grid maximum (not the sub-pixel value the tracker moves to). Its scale is
    the filter's: comparable along one run, not between configs.
``apce``
    the average peak-to-correlation energy of Wang et al. (CVPR 2017, "Large Margin Object
    Tracking with Circulant Feature Maps")::

        APCE = |R_max - R_min|² / mean((R - R_min)²)

    over the whole map. A single sharp peak on a flat floor gives a high value; a map with
    several peaks or spread energy (occlusion, a wrong frame, drift) a low one.

Why APCE rather than the peak-to-sidelobe ratio (PSR, MOSSE): the PSR needs a window around
the peak left out of the sidelobe (11 x 11 *pixels* in MOSSE), which has no natural size in
cells across configs whose cell sizes and map sizes differ; APCE has no parameter. Both are
invariant to ``a * R + b`` (a > 0), so APCE compares across configs where the peak does not.

Frames without a response have :data:`NO_CONFIDENCE` (both NaN): frame 1 (``init``: there is
nothing to detect yet) and frames held as blank (``tracker.held_frames``). A flat map (every
value equal) has APCE 0: it has no peak.
"""
from __future__ import annotations

import dataclasses
import math

import numpy as np


@dataclasses.dataclass(frozen=True)
class Confidence:
    """``peak`` (max of the response map) and ``apce`` (:func:`apce`) of one frame; NaN when the
    frame has no response (frame 1, a held blank frame)."""

    peak: float
    apce: float

    @classmethod
    def of(cls, response: np.ndarray | None) -> Confidence:
        """The confidence of a response map (any layout: centred or not), or
        :data:`NO_CONFIDENCE` for None."""
        if response is None:
            return NO_CONFIDENCE
        r = np.asarray(response, dtype=np.float64)
        return cls(float(r.max()), apce(r))

    def as_tuple(self) -> tuple[float, float]:
        return (self.peak, self.apce)


NO_CONFIDENCE = Confidence(math.nan, math.nan)


def apce(response: np.ndarray) -> float:
    """Wang et al.'s APCE: ``|max - min|² / mean((R - min)²)``; 0 for a flat map."""
    r = np.asarray(response, dtype=np.float64)
    low = r.min()
    energy = float(np.mean((r - low) ** 2))
    return float((r.max() - low) ** 2 / energy) if energy > 0 else 0.0


def confidence_of(tracker) -> tuple[float, float]:
    """``(peak, apce)`` of ``tracker``'s last frame: its ``last_confidence`` if it has one
    (any object with ``peak`` and ``apce``), else NaN: e.g. an OpenCV baseline, or a tracker
    whose ``last_confidence`` cannot be read (a diagnostic never fails a run)."""
    try:
        c = getattr(tracker, "last_confidence", None)
        return NO_CONFIDENCE.as_tuple() if c is None else (float(c.peak), float(c.apce))
    except Exception:  # noqa: BLE001 - read-only diagnostic
        return NO_CONFIDENCE.as_tuple()

"""VOT's reset-based experiment (Kristan et al., TPAMI 2016; the VOT2016 challenge).

The tracker starts from frame 1's ground truth. A frame whose box does not overlap its
ground truth is a **failure**; the tracker is started again, from the ground truth,
:data:`SKIP` frames later (the first frame from there with a valid ground truth), and the
frames between are not tracked. :mod:`dcfkit.analysis.reset_scores` scores these runs:
accuracy leaves out the :data:`BURN_IN` frames from each start.
"""
from __future__ import annotations

import numpy as np

__all__ = ["BURN_IN", "SKIP", "failed", "overlap", "valid_box"]

SKIP = 5  # frames from a failure to the next start (vot-toolkit's skip_initialize)
BURN_IN = 10  # frames from each start left out of accuracy, the start included


def valid_box(box) -> bool:
    """Whether ``box`` ``(x, y, w, h)`` is finite with a positive width and height."""
    b = np.asarray(box, dtype=np.float64).reshape(4)
    return bool(np.isfinite(b).all() and b[2] > 0 and b[3] > 0)


def _clipped(box, bounds: tuple[float, float] | None) -> tuple[float, float, float, float]:
    """``(left, top, right, bottom)`` of ``box``, inside ``[0, width] x [0, height]`` if given."""
    x, y, w, h = (float(v) for v in box)
    if bounds is None:
        return x, y, x + w, y + h
    width, height = bounds
    return min(max(x, 0.0), width), min(max(y, 0.0), height), min(max(x + w, 0.0), width), \
        min(max(y + h, 0.0), height)


def overlap(box, gt, bounds: tuple[float, float] | None = None) -> float:
    """Intersection over union of two boxes ``[x, x + w) x [y, y + h)``, each first cut to the
    image ``bounds`` ``(width, height)`` when given, as vot-toolkit does; 0 when ``box`` is not
    :func:`valid_box`, NaN when ``gt`` is not (such a frame is never a failure, as in the
    VOT2016 toolkit, whose overlap of a missing region is NaN)."""
    if not valid_box(gt):
        return float("nan")
    if not valid_box(box):
        return 0.0
    (al, at, ar, ab), (bl, bt, br, bb) = _clipped(box, bounds), _clipped(gt, bounds)
    inter = max(0.0, min(ar, br) - max(al, bl)) * max(0.0, min(ab, bb) - max(at, bt))
    union = (ar - al) * (ab - at) + (br - bl) * (bb - bt) - inter
    return float(inter / union) if union > 0 else 0.0


def failed(box, gt, bounds: tuple[float, float] | None = None) -> bool:
    """VOT's failure: ``box`` does not overlap ``gt`` (:func:`overlap` <= 0; never on a frame
    without ground truth). The rule the runs apply and the reset report replays."""
    return overlap(box, gt, bounds) <= 0

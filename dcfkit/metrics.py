"""One-pass evaluation (OPE) metrics in the conventions of the OTB / UAV123 toolkits.

All boxes are ``(N, 4) float64`` arrays of ``(x, y, w, h)``, 0-based (only differences
matter, so 1-based boxes give the same scores).

Conventions (each one matches the OTB toolkit unless said otherwise):

* **Centre** of a box: ``(x + w/2, y + h/2)``. The toolkit uses ``x + (w-1)/2``; the
  ``-1/2`` cancels in the difference, so centre errors are identical.
* **IoU**: boxes are continuous regions ``[x, x + w) x [y, y + h)``; intersection width is
  ``max(0, min(x1 + w1, x2 + w2) - max(x1, x2))``. This equals the toolkit's
  ``calcRectInt``, whose ``-1`` on the right edge and ``+1`` on the width cancel.
* **Precision curve**: fraction of scored frames with centre error ``<= t`` for
  ``t = 0, 1, ..., 50`` px; the **precision score** is the value at 20 px.
* **Success curve**: fraction of scored frames with IoU ``> t`` (strictly greater, as the
  toolkit) for the 21 thresholds ``t = 0, 0.05, ..., 1``; so the point at ``t = 1`` is
  always 0 and a perfect tracker has AUC 20/21. **AUC** is the mean of the success curve.
* **Normalized precision** (LaSOT / TrackingNet): the centre error divided by the ground
  truth's ``(w, h)`` per axis, thresholds ``0, 0.01, ..., 0.5``; the score is the value at
  0.2 (as pysot and pytracking report it).
* **Scored frames**: frames whose ground truth is finite with ``w > 0`` and ``h > 0``.
  The first frame (where the tracker is initialised with the ground truth) is scored by
  default, as in the OTB toolkit; ``include_first=False`` drops it.
* **Failed predictions**: a prediction containing NaN/inf, or a missing one (a result
  shorter than the ground truth), has centre error ``inf`` and IoU 0 — it fails every
  threshold. (The OTB toolkit instead copies the previous box; we count it as a failure.)
  A prediction with ``w <= 0`` or ``h <= 0`` has IoU 0; its centre error is computed.
* **Averages over sequences**: by default each sequence weighs equally (mean of the
  per-sequence curves, as the OTB / UAV123 toolkits); ``weighting="frame"`` pools all
  frames instead. Sequences without scored frames are left out.
"""
from __future__ import annotations

from typing import Iterable, Mapping

import numpy as np

__all__ = [
    "NORM_PRECISION_AT",
    "NORM_PRECISION_THRESHOLDS",
    "PRECISION_AT",
    "PRECISION_THRESHOLDS",
    "SUCCESS_THRESHOLDS",
    "as_boxes",
    "average",
    "centre_error",
    "iou",
    "normalized_centre_error",
    "precision_curve",
    "score_sequence",
    "scored_frames",
    "success_curve",
]

PRECISION_THRESHOLDS = np.arange(0, 51, dtype=np.float64)  # pixels
SUCCESS_THRESHOLDS = np.linspace(0.0, 1.0, 21)
NORM_PRECISION_THRESHOLDS = np.linspace(0.0, 0.5, 51)
PRECISION_AT = 20.0
NORM_PRECISION_AT = 0.2


def as_boxes(boxes, n: int | None = None) -> np.ndarray:
    """``boxes`` as ``(N, 4) float64``; with ``n``, padded with NaN rows (missing predictions)."""
    b = np.asarray(boxes, dtype=np.float64)
    if b.size == 0:
        b = b.reshape(0, 4)
    if b.ndim != 2 or b.shape[1] != 4:
        raise ValueError(f"expected boxes of shape (N, 4), got {b.shape}")
    if n is not None:
        if len(b) > n:
            raise ValueError(f"{len(b)} predicted boxes for a sequence of {n} frames")
        if len(b) < n:
            b = np.vstack([b, np.full((n - len(b), 4), np.nan)])
    return b


def _failed(pred: np.ndarray) -> np.ndarray:
    return ~np.isfinite(pred).all(axis=1)


def scored_frames(gt, include_first: bool = True) -> np.ndarray:
    """``(N,) bool``: frames whose ground truth is finite with positive width and height."""
    gt = as_boxes(gt)
    with np.errstate(invalid="ignore"):
        mask = np.isfinite(gt).all(axis=1) & (gt[:, 2] > 0) & (gt[:, 3] > 0)
    if not include_first and len(mask):
        mask[0] = False
    return mask


def centre_error(pred, gt) -> np.ndarray:
    """``(N,) float64`` Euclidean distance between box centres, in pixels (``inf`` if pred failed)."""
    gt = as_boxes(gt)
    pred = as_boxes(pred, len(gt))
    d = (pred[:, :2] + pred[:, 2:] / 2) - (gt[:, :2] + gt[:, 2:] / 2)
    err = np.hypot(d[:, 0], d[:, 1])
    err[_failed(pred)] = np.inf
    return err


def normalized_centre_error(pred, gt) -> np.ndarray:
    """``(N,) float64`` centre error with each axis divided by the ground truth's w and h."""
    gt = as_boxes(gt)
    pred = as_boxes(pred, len(gt))
    d = (pred[:, :2] + pred[:, 2:] / 2) - (gt[:, :2] + gt[:, 2:] / 2)
    with np.errstate(divide="ignore", invalid="ignore"):
        err = np.hypot(d[:, 0] / gt[:, 2], d[:, 1] / gt[:, 3])
    err[_failed(pred)] = np.inf
    return err


def iou(pred, gt) -> np.ndarray:
    """``(N,) float64`` intersection over union of continuous boxes (0 if pred failed or is empty)."""
    gt = as_boxes(gt)
    pred = as_boxes(pred, len(gt))
    with np.errstate(invalid="ignore"):
        iw = np.minimum(pred[:, 0] + pred[:, 2], gt[:, 0] + gt[:, 2]) - np.maximum(pred[:, 0], gt[:, 0])
        ih = np.minimum(pred[:, 1] + pred[:, 3], gt[:, 1] + gt[:, 3]) - np.maximum(pred[:, 1], gt[:, 1])
        inter = np.clip(iw, 0, None) * np.clip(ih, 0, None)
        union = pred[:, 2] * pred[:, 3] + gt[:, 2] * gt[:, 3] - inter
        out = np.where(union > 0, inter / np.where(union > 0, union, 1.0), 0.0)
        empty = (pred[:, 2] <= 0) | (pred[:, 3] <= 0)
    out[_failed(pred) | empty] = 0.0
    out[~np.isfinite(gt).all(axis=1)] = np.nan
    return out


def precision_curve(errors, thresholds=PRECISION_THRESHOLDS) -> np.ndarray:
    """Fraction of ``errors`` with ``error <= t`` for each threshold (NaN if no frames)."""
    errors = np.asarray(errors, dtype=np.float64).ravel()
    if errors.size == 0:
        return np.full(len(thresholds), np.nan)
    return (errors[:, None] <= np.asarray(thresholds)[None, :]).mean(axis=0)


def success_curve(overlaps, thresholds=SUCCESS_THRESHOLDS) -> np.ndarray:
    """Fraction of ``overlaps`` with ``IoU > t`` (strict) for each threshold (NaN if no frames)."""
    overlaps = np.asarray(overlaps, dtype=np.float64).ravel()
    if overlaps.size == 0:
        return np.full(len(thresholds), np.nan)
    return (overlaps[:, None] > np.asarray(thresholds)[None, :]).mean(axis=0)


def score_sequence(pred, gt, include_first: bool = True) -> dict:
    """Scores of one sequence, a plain dict.

    Keys: ``frames`` (number of scored frames), ``precision_curve`` (51,),
    ``success_curve`` (21,), ``norm_precision_curve`` (51,), and the scalars ``precision``
    (at 20 px), ``auc`` (mean of the success curve) and ``norm_precision`` (at 0.2).
    Scalars are NaN when no frame is scored.
    """
    gt = as_boxes(gt)
    pred = as_boxes(pred, len(gt))
    mask = scored_frames(gt, include_first)
    err = centre_error(pred, gt)[mask]
    ov = iou(pred, gt)[mask]
    nerr = normalized_centre_error(pred, gt)[mask]
    return _summarise(
        frames=int(mask.sum()),
        precision_curve=precision_curve(err),
        success_curve=success_curve(ov),
        norm_precision_curve=precision_curve(nerr, NORM_PRECISION_THRESHOLDS),
    )


def _summarise(frames, precision_curve, success_curve, norm_precision_curve) -> dict:
    i20 = int(np.searchsorted(PRECISION_THRESHOLDS, PRECISION_AT))
    i02 = int(np.argmin(np.abs(NORM_PRECISION_THRESHOLDS - NORM_PRECISION_AT)))
    return {
        "frames": frames,
        "precision_curve": precision_curve,
        "success_curve": success_curve,
        "norm_precision_curve": norm_precision_curve,
        "precision": float(precision_curve[i20]),
        "auc": float(np.mean(success_curve)),
        "norm_precision": float(norm_precision_curve[i02]),
    }


def average(scores: Iterable[Mapping], weighting: str = "sequence") -> dict:
    """Average per-sequence :func:`score_sequence` dicts into one of the same form.

    ``weighting="sequence"`` (default, OTB/UAV123 toolkits): each sequence weighs equally.
    ``weighting="frame"``: each scored frame weighs equally (pooled frames).
    Sequences with no scored frame are left out; ``frames`` is the total scored frames.
    """
    if weighting not in ("sequence", "frame"):
        raise ValueError(f"weighting must be 'sequence' or 'frame', got {weighting!r}")
    scores = [s for s in scores if s["frames"] > 0]
    keys = ("precision_curve", "success_curve", "norm_precision_curve")
    if not scores:
        sizes = (len(PRECISION_THRESHOLDS), len(SUCCESS_THRESHOLDS), len(NORM_PRECISION_THRESHOLDS))
        return _summarise(0, *(np.full(n, np.nan) for n in sizes))
    w = np.array([s["frames"] if weighting == "frame" else 1 for s in scores], dtype=np.float64)
    curves = [np.average(np.stack([s[k] for s in scores]), axis=0, weights=w) for k in keys]
    return _summarise(int(sum(s["frames"] for s in scores)), *curves)

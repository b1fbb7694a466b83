"""One-pass evaluation (OPE) scores under a named scoring protocol.

Which frames count and what a frame scores are a toolkit's rules, one
:class:`~dcfkit.protocols.Protocol` each (:mod:`dcfkit.protocols`); this module turns a
protocol's per-frame values into curves and scores, and averages sequences.

Boxes are ``(N, 4) float64`` ``(x, y, w, h)``, **0-based** as dcfkit keeps them in memory;
:func:`score_sequence` adds 1 to x and y before applying a protocol, because some rules
test coordinates (the OTB toolkit's ``x > 0``), not only differences.

* **Precision curve**: fraction of the counted frames with centre error ``<= t``; the
  **precision score** is its value at 20 px.
* **Success curve**: fraction of the counted frames with overlap ``> t`` (strictly
  greater), so the point at ``t = 1`` is 0 and a perfect tracker's **AUC** (the mean of
  the success curve) is 20/21 with 21 thresholds.
* **Normalized precision**: the same with the centre offset divided by the ground truth's
  size; the score is the value at 0.2.
* A prediction row that the result lacks (a truncated or missing result) fails every
  threshold in every protocol.

:func:`centre_error`, :func:`normalized_centre_error` and :func:`iou` are plain geometry of
two box series (centre ``x + w/2``, boxes ``[x, x + w)``), with no protocol's rules.
"""
from __future__ import annotations

import dataclasses
from typing import Iterable, Mapping

import numpy as np

from dcfkit.errors import shown
from dcfkit.protocols import DEFAULT, Protocol, get_protocol

__all__ = [
    "as_boxes",
    "average",
    "centre_error",
    "iou",
    "normalized_centre_error",
    "pool_runs",
    "precision_curve",
    "score_sequence",
    "success_curve",
]

_CURVES = ("precision_curve", "success_curve", "norm_precision_curve")


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


def precision_curve(errors, thresholds) -> np.ndarray:
    """Fraction of ``errors`` with ``error <= t`` for each threshold (NaN if no frames)."""
    errors = np.asarray(errors, dtype=np.float64).ravel()
    if errors.size == 0:
        return np.full(len(thresholds), np.nan)
    return (errors[:, None] <= np.asarray(thresholds)[None, :]).mean(axis=0)


def success_curve(overlaps, thresholds) -> np.ndarray:
    """Fraction of ``overlaps`` with ``overlap > t`` (strict) for each threshold (NaN if no frames)."""
    overlaps = np.asarray(overlaps, dtype=np.float64).ravel()
    if overlaps.size == 0:
        return np.full(len(thresholds), np.nan)
    return (overlaps[:, None] > np.asarray(thresholds)[None, :]).mean(axis=0)


def score_sequence(pred, gt, include_first: bool = True, protocol: str | Protocol = DEFAULT) -> dict:
    """Scores of one sequence under ``protocol`` (a name or :class:`Protocol`), a plain dict.

    ``pred`` and ``gt`` are 0-based; ``pred`` may be shorter than ``gt`` (its missing rows
    fail every threshold). ``include_first=False`` takes frame 1 out of the denominator.
    Keys: ``protocol`` (the name), ``frames`` (frames in the denominator), ``given`` (rows
    the result has), ``precision_curve``, ``success_curve``, ``norm_precision_curve`` and
    the scalars ``precision``, ``auc``, ``norm_precision`` (and ``ao``, ``sr50``, ``sr75``
    for a protocol with overlap scores). Scalars are NaN when no frame is counted.
    """
    proto = get_protocol(protocol)
    gt = as_boxes(gt)
    given = len(as_boxes(pred))
    pred = as_boxes(pred, len(gt))
    one = np.array([1.0, 1.0, 0.0, 0.0])
    with np.errstate(over="ignore"):  # a box of 1e300 has an infinite error, as in the toolkits, said by no warning
        f = proto.frames(pred + one, gt + one)
    overlap, error, norm_error = f.overlap.copy(), f.error.copy(), f.norm_error.copy()
    overlap[given:], error[given:], norm_error[given:] = 0.0, np.inf, np.inf
    counted = f.counted.copy()
    if not include_first:
        counted[:1] = False
    overlap = overlap[counted]
    extra = {}
    if proto.overlap_scores:
        extra = {"ao": float(overlap.mean()) if overlap.size else np.nan,
                 "sr50": float((overlap > 0.5).mean()) if overlap.size else np.nan,
                 "sr75": float((overlap > 0.75).mean()) if overlap.size else np.nan}
    return _summarise(proto, int(counted.sum()), given,
                      precision_curve(error[counted], proto.precision_thresholds),
                      success_curve(overlap, proto.success_thresholds),
                      precision_curve(norm_error[counted], proto.norm_precision_thresholds), **extra)


def _summarise(proto: Protocol, frames: int, given: int, precision_curve, success_curve,
               norm_precision_curve, **overlap_scores) -> dict:
    return {
        "protocol": proto.name,
        "frames": frames,
        "given": given,
        "precision_curve": precision_curve,
        "success_curve": success_curve,
        "norm_precision_curve": norm_precision_curve,
        "precision": float(precision_curve[proto.precision_index]),
        "auc": float(np.mean(success_curve)),
        "norm_precision": float(norm_precision_curve[proto.norm_precision_index]),
        **{k: float(v) for k, v in overlap_scores.items()},
    }


def average(scores: Iterable[Mapping], weighting: str | None = None,
            protocol: str | Protocol = DEFAULT) -> dict:
    """Average per-sequence :func:`score_sequence` dicts (all of ``protocol``) into one of
    the same form.

    ``weighting`` ``"sequence"``: each sequence weighs equally; ``"frame"``: each counted
    frame does (frames pooled); ``None``: the protocol's own (``got10k`` pools frames, the
    others weigh sequences). Sequences with no counted frame are left out, and under
    ``otb`` a sequence whose curve is all zero is left out of that curve's mean (as the
    toolkit's ``plotDrawSave``), unless its result was missing altogether (``given`` 0: a
    missing result stays a total failure). ``frames`` is the total of counted frames.
    """
    proto = get_protocol(protocol)
    weighting = weighting or proto.weighting
    if weighting not in ("sequence", "frame"):
        raise ValueError(f"weighting must be 'sequence' or 'frame', got {shown(weighting)}")
    scores = [s for s in scores if s["frames"] > 0]
    other = {s.get("protocol") for s in scores} - {proto.name}
    if other:
        raise ValueError(f"averaging {proto.name!r} scores with scores of protocol {', '.join(map(str, other))}")
    w = np.array([s["frames"] if weighting == "frame" else 1 for s in scores], dtype=np.float64)
    sizes = {"precision_curve": len(proto.precision_thresholds), "success_curve": len(proto.success_thresholds),
             "norm_precision_curve": len(proto.norm_precision_thresholds)}
    means = {}
    for key in _CURVES + proto.overlap_keys:
        values = [np.atleast_1d(np.asarray(s[key], dtype=np.float64)) for s in scores]
        keep = [i for i, v in enumerate(values) if not (proto.drop_zero_curves and key in _CURVES
                                                        and scores[i].get("given", 1) > 0
                                                        and v.sum() <= np.finfo(float).eps)]
        if keep:
            means[key] = np.average(np.stack([values[i] for i in keep]), axis=0, weights=w[keep])
        else:
            means[key] = np.full(sizes.get(key, 1), np.nan)
    overlap_scores = {k: means[k][0] for k in proto.overlap_keys}
    return _summarise(proto, int(sum(s["frames"] for s in scores)), int(sum(s.get("given", 0) for s in scores)),
                      means["precision_curve"], means["success_curve"], means["norm_precision_curve"],
                      **overlap_scores)



def pool_runs(scores: Iterable[Mapping], protocol: str | Protocol = DEFAULT) -> dict:
    """The scores of a sequence's runs (TRE, SRE) as one: their frames pooled, as the OTB
    toolkit's ``perfPlot.m`` sums the successes of all runs and divides by all their frames
    (no run is left out for an all-zero curve; :func:`average` may leave the sequence out)."""
    proto = get_protocol(protocol)
    return average(scores, "frame", dataclasses.replace(proto, drop_zero_curves=False))

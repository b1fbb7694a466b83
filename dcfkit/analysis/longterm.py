"""Long-term tracking precision, recall and F-score (VOT2018-LT onwards).

Definitions of Lukežič et al., "Now you see me: evaluating performance in long-term visual
tracking" (arXiv:1804.07056, 2018), as the Python vot-toolkit computes them
(``vot/analysis/longterm.py``: ``determine_thresholds``, ``compute_tpr_curves``,
``PrecisionRecallCurve``, ``PrecisionRecall``; read at commit 56f0053 of
github.com/votchallenge/toolkit). A frame's prediction is *present* at threshold τ when its
confidence is ``>= τ``; a NaN confidence is never present (the toolkit's ``NaN >= τ`` is false).

* Pr(τ): mean overlap of the frames present at τ, 0 where the ground truth is absent; 1 when no
  frame is present (the toolkit's rule; the paper leaves it undefined).
* Re(τ): the sum of those overlaps over the number of frames whose ground truth is present.
* Overlaps are the toolkit's (rounded boxes bounded by the image, :func:`frame_overlaps`); frame 1
  is in Re's denominator and never present (:func:`predicted_scores`); a NaN box is never present
  (the paper's empty prediction; the toolkit would count an empty region of confidence >= τ).
* Curves are per sequence, then averaged over sequences with equal weight; F(τ) = 2 Pr Re /
  (Pr + Re) of the averaged curves (0 where Pr + Re = 0: the toolkit divides by zero), and the
  score is the maximum of F with the Pr, Re and τ there (the first maximum, i.e. the highest τ,
  as the toolkit's ``list.index(max)``).
* Thresholds from one tracker's confidences pooled over all sequences (``thresholds``).

Arrays in, numbers out: which frames a result predicts and what its confidence file holds is
the report's business (:mod:`dcfkit.analysis.longterm_report`).
"""
from __future__ import annotations

from typing import Iterable

import numpy as np

from dcfkit.analysis.metrics import as_boxes, iou
from dcfkit.experiments.raster import vottoolkit_overlap

__all__ = ["RESOLUTION", "f_score", "frame_overlaps", "long_term_scores", "predicted_scores", "sequence_curves",
           "thresholds"]

RESOLUTION = 100  # the toolkit's _Thresholds.resolution: 98 pooled confidences between +inf and -inf


def thresholds(scores, resolution: int = RESOLUTION) -> np.ndarray:
    """``(K,) float64`` thresholds, highest first, of the toolkit's ``determine_thresholds``.

    ``scores`` pooled over sequences, NaN dropped and sorted highest first (n of them); when n >
    ``resolution - 2``, the ones at indices ``round(linspace(d, n - d, resolution - 2))`` with ``d =
    floor(n / (resolution - 2))`` (numpy's round: half to even), else all of them; then ``+inf``
    first (nothing present) and ``-inf`` last (every scored frame present).
    """
    s = np.asarray(scores, dtype=np.float64).ravel()
    s = -np.sort(-s[~np.isnan(s)])
    inner = resolution - 2
    if len(s) > inner:
        delta = len(s) // inner
        s = s[np.round(np.linspace(delta, len(s) - delta, num=inner)).astype(int)]
    return np.concatenate([[np.inf], s, [-np.inf]])


def frame_overlaps(pred, gt, size: tuple[int, int] | None = None) -> tuple[np.ndarray, np.ndarray]:
    """``(overlap, gt_present)``, each ``(N,)``, of 0-based ``(N, 4)`` ``pred`` and ``gt`` (``pred``
    may be shorter); the overlap is 0 where the ground truth is absent (a row not all finite) or the
    prediction is missing. With the image ``size`` ``(width, height)``, vot-toolkit 0.9's overlap of
    boxes rounded to pixels and bounded by the image (:func:`dcfkit.experiments.raster.vottoolkit_overlap`,
    the toolkit's ``bounded=True``); without, the continuous IoU (:func:`dcfkit.analysis.metrics.iou`).
    """
    gt = as_boxes(gt)
    pred = as_boxes(pred, len(gt))
    present = np.isfinite(gt).all(axis=1)
    valid = present & np.isfinite(pred).all(axis=1)
    with np.errstate(invalid="ignore"):  # NaN rows: their overlap is replaced below
        found = iou(pred, gt) if size is None else vottoolkit_overlap(pred, gt, size)
    return np.where(valid, np.nan_to_num(found, nan=0.0), 0.0), present


def predicted_scores(confidence, boxes, frames: int) -> np.ndarray:
    """``(frames,) float64`` confidences with NaN where a frame has no prediction: frame 1, a NaN in
    ``boxes`` (the paper's empty prediction) or a row past the end of ``boxes`` or ``confidence``.

    Frame 1 is the initialisation: the toolkit stores it as a special region (IoU 0 with the ground
    truth, which counts in Re's denominator) and reads the confidence dcfkit writes there, ``nan``, as
    never present. (A tracker that reports no confidence at all on frame 1 gets 0 from the toolkit,
    present at τ <= 0; dcfkit keeps frame 1 out of Pr at every τ.)
    """
    boxes = as_boxes(boxes, frames)
    out = np.full(frames, np.nan)
    c = np.asarray(confidence, dtype=np.float64).ravel()[:frames]
    out[:len(c)] = c
    out[~np.isfinite(boxes).all(axis=1)] = np.nan
    out[:1] = np.nan
    return out


def sequence_curves(overlap, gt_present, confidence, taus) -> tuple[np.ndarray, np.ndarray]:
    """``(Pr, Re)``, each ``(K,)``, of one sequence at the thresholds ``taus`` (``compute_tpr_curves``).

    ``overlap``, ``gt_present`` and ``confidence`` are ``(N,)``; ``overlap`` is taken as 0 where the
    ground truth is absent. Re is 0 for a sequence whose ground truth is never present.
    """
    gt_present = np.asarray(gt_present, dtype=bool)
    overlap = np.where(gt_present, np.asarray(overlap, dtype=np.float64), 0.0)
    with np.errstate(invalid="ignore"):  # NaN >= tau is False: no confidence, no prediction
        present = np.asarray(confidence, dtype=np.float64)[None, :] >= np.asarray(taus, dtype=np.float64)[:, None]
    count = present.sum(axis=1)
    total = np.where(present, overlap[None, :], 0.0).sum(axis=1)
    precision = np.where(count > 0, total / np.maximum(count, 1), 1.0)
    visible = int(gt_present.sum())
    recall = total / visible if visible else np.zeros(len(total))
    return precision, recall


def f_score(precision, recall) -> np.ndarray:
    """``2 Pr Re / (Pr + Re)`` elementwise, 0 where ``Pr + Re`` is 0."""
    pr, re = np.asarray(precision, dtype=np.float64), np.asarray(recall, dtype=np.float64)
    den = pr + re
    return np.where(den > 0, 2 * pr * re / np.where(den > 0, den, 1.0), 0.0)


def long_term_scores(sequences: Iterable[tuple]) -> dict:
    """One tracker's long-term scores from ``(overlap, gt_present, confidence)`` per sequence.

    Returns ``f``, ``precision``, ``recall`` and ``threshold`` at the maximum of F, ``sequences``,
    and the curves ``thresholds``, ``precision_curve``, ``recall_curve``, ``f_curve`` (``(K,)``,
    highest threshold first). Thresholds pool every sequence's confidences (:func:`thresholds`).
    """
    sequences = [tuple(np.asarray(a) for a in s) for s in sequences]
    if not sequences:
        raise ValueError("long-term scores need at least one sequence")
    taus = thresholds(np.concatenate([c.ravel() for _, _, c in sequences]))
    curves = [sequence_curves(o, g, c, taus) for o, g, c in sequences]
    precision = np.mean([p for p, _ in curves], axis=0)
    recall = np.mean([r for _, r in curves], axis=0)
    f = f_score(precision, recall)
    best = int(np.argmax(f))  # the first maximum: the highest threshold reaching it
    return {"f": float(f[best]), "precision": float(precision[best]), "recall": float(recall[best]),
            "threshold": float(taus[best]), "sequences": len(sequences), "thresholds": taus,
            "precision_curve": precision, "recall_curve": recall, "f_curve": f}

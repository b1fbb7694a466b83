"""Scoring protocols: the per-frame rules of the toolkits that published tracking results:
``otb`` (the OTB / UAV123 MATLAB toolkit), ``lasot``, ``pysot`` and ``got10k``.
docs/evaluation.md ("Scoring protocols") sets each rule beside the toolkit file it follows.

A :class:`Protocol` says, for one sequence, which frames are in the denominator and what
overlap and centre error each frame gets; :mod:`dcfkit.analysis.metrics` turns those into
curves and averages them. Boxes are ``(N, 4)`` ``(x, y, w, h)``, 1-based as the files hold
them (some rules test ``x > 0``).
"""
from __future__ import annotations

import dataclasses
from typing import Callable

import numpy as np

from dcfkit.errors import shown

__all__ = ["DEFAULT", "PROTOCOLS", "FrameScores", "Protocol", "get_protocol"]

DEFAULT = "otb"


@dataclasses.dataclass(frozen=True)
class FrameScores:
    """Per-frame values of one sequence, each ``(N,) float64`` (``counted`` bool).

    ``counted`` marks the frames in the denominator; ``overlap`` is compared with
    ``> t``, ``error`` and ``norm_error`` with ``<= t``."""

    overlap: np.ndarray
    error: np.ndarray
    norm_error: np.ndarray
    counted: np.ndarray


@dataclasses.dataclass(frozen=True)
class Protocol:
    """A toolkit's scoring rules. ``frames(pred, gt)`` takes ``(N, 4)`` 1-based boxes of
    equal length and returns :class:`FrameScores`; the rest are the curves' thresholds and
    how scores are read off and averaged."""

    name: str
    title: str
    source: str
    frames: Callable[[np.ndarray, np.ndarray], FrameScores]
    success_thresholds: np.ndarray
    precision_thresholds: np.ndarray
    norm_precision_thresholds: np.ndarray
    weighting: str = "sequence"          # default averaging: "sequence" or "frame" (pooled)
    drop_zero_curves: bool = False       # plotDrawSave: an all-zero curve leaves the mean
    overlap_scores: bool = False         # also AO, SR@0.5 and SR@0.75
    precision_index: int = 20            # precision score: curve at 20 px
    norm_precision_index: int = 20       # normalized precision score: curve at 0.2

    @property
    def overlap_keys(self) -> tuple[str, ...]:
        """``("ao", "sr50", "sr75")`` for a protocol with overlap scores, else ``()``."""
        return ("ao", "sr50", "sr75") if self.overlap_scores else ()

    @property
    def score_keys(self) -> tuple[str, ...]:
        """The scalar scores of this protocol, in the order tables show them."""
        return self.overlap_keys + ("auc", "precision", "norm_precision")

    @property
    def thresholds(self) -> dict[str, np.ndarray]:
        """Each curve's thresholds, by the curve's name."""
        return {"precision": self.precision_thresholds, "success": self.success_thresholds,
                "norm_precision": self.norm_precision_thresholds}

    @property
    def rank_key(self) -> str:
        """The score trackers are ranked by (AO for GOT-10k, AUC otherwise)."""
        return "ao" if self.overlap_scores else "auc"

    def describe(self) -> str:
        """One line naming the protocol, for reports: ``protocol otb: ... (source)``."""
        return f"protocol {self.name}: {self.title} ({self.source})"


def _centres(boxes: np.ndarray) -> np.ndarray:
    """``(N, 2)`` centres ``x + (w-1)/2, y + (h-1)/2`` (the convention of all three toolkits)."""
    return boxes[:, :2] + (boxes[:, 2:] - 1) / 2


# --------------------------------------------------------------------------- otb


def _matlab_substitute(pred: np.ndarray, gt: np.ndarray, any_nan: bool = False) -> np.ndarray:
    """calcSeqErrRobust's repair of failed predictions, as a forward fill: row ``i >= 1`` is
    flagged by its own (original) values, and a flagged row takes the last unflagged row
    before it, which is what replacing row i by the already-replaced row i-1 amounts to.
    ``any_nan``: one NaN value flags the row (LaSOT's ``sum(isnan(r))``), not four."""
    with np.errstate(invalid="ignore"):
        nan = np.isnan(pred).any(axis=1, keepdims=True) if any_nan else np.isnan(pred)
        bad = nan | (pred[:, 2:3] <= 0) | (pred[:, 3:4] <= 0)
    flagged = (bad & ~np.isnan(gt)).all(axis=1)
    flagged[:1] = False
    source = np.where(flagged, 0, np.arange(len(pred)))
    return pred[np.maximum.accumulate(source)] if len(pred) else pred.copy()


def _calc_rect_int(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """IoU with calcRectInt's pixel convention; ``fmin``/``fmax`` ignore NaN like MATLAB's."""
    right_a, top_a = a[:, 0] + a[:, 2] - 1, a[:, 1] + a[:, 3] - 1
    right_b, top_b = b[:, 0] + b[:, 2] - 1, b[:, 1] + b[:, 3] - 1
    iw = np.fmax(0, np.fmin(right_a, right_b) - np.fmax(a[:, 0], b[:, 0]) + 1)
    ih = np.fmax(0, np.fmin(top_a, top_b) - np.fmax(a[:, 1], b[:, 1]) + 1)
    inter = iw * ih
    return inter / (a[:, 2] * a[:, 3] + b[:, 2] * b[:, 3] - inter)


def _otb_frames(pred: np.ndarray, gt: np.ndarray, any_nan: bool = False) -> FrameScores:
    n = len(gt)
    with np.errstate(invalid="ignore", divide="ignore"):
        rect = _matlab_substitute(pred, gt, any_nan)
        rect[:1] = gt[:1]  # the first frame is scored with the ground truth
        offset = _centres(rect) - _centres(gt)
        error = np.sqrt((offset ** 2).sum(axis=1))
        norm_error = np.sqrt(((offset / gt[:, 2:]) ** 2).sum(axis=1))
        in_view = (gt > 0).all(axis=1)
        overlap = np.full(n, -1.0)
        overlap[in_view] = _calc_rect_int(rect[in_view], gt[in_view])
    error[~in_view] = -1.0
    norm_error[~in_view] = -1.0
    return FrameScores(overlap, error, norm_error, np.ones(n, dtype=bool))


# --------------------------------------------------------------------------- lasot


def _lasot_frames(pred: np.ndarray, gt: np.ndarray) -> FrameScores:
    absent = np.isnan(gt).any(axis=1)
    # the toolkit's file holds numbers (0,0,0,0 or a box) in an absent frame: repair and score as
    # otb does with a ground truth that is not in view, then fail both thresholds there
    f = _otb_frames(pred, np.where(absent[:, None], 0.0, gt), any_nan=True)
    error, norm_error = f.error.copy(), f.norm_error.copy()
    error[absent] = np.inf
    norm_error[absent] = np.inf
    return FrameScores(f.overlap, error, norm_error, f.counted)


# --------------------------------------------------------------------------- pysot


def _pysot_distance(centre_gt: np.ndarray, centre: np.ndarray) -> np.ndarray:
    """success_error: -1 where the ground truth's centre is not > 0 on both axes."""
    dist = np.full(len(centre_gt), -1.0)
    with np.errstate(invalid="ignore"):
        scored = (centre_gt > 0).sum(axis=1) == 2
    dist[scored] = np.sqrt(((centre_gt[scored] - centre[scored]) ** 2).sum(axis=1))
    return dist


def _pysot_frames(pred: np.ndarray, gt: np.ndarray) -> FrameScores:
    n = len(gt)
    with np.errstate(invalid="ignore", divide="ignore"):
        sized = (gt[:, 2:] > 0).sum(axis=1) == 2
        g, p = gt[sized], pred[sized]
        iw = np.maximum(0, np.minimum(g[:, 0] + g[:, 2], p[:, 0] + p[:, 2]) - np.maximum(g[:, 0], p[:, 0]))
        ih = np.maximum(0, np.minimum(g[:, 1] + g[:, 3], p[:, 1] + p[:, 3]) - np.maximum(g[:, 1], p[:, 1]))
        inter = iw * ih
        overlap = np.full(n, -1.0)
        overlap[sized] = np.maximum(np.minimum(1, inter / (g[:, 2] * g[:, 3] + p[:, 2] * p[:, 3] - inter)), 0)
        wh = gt[:, 2:] + 1e-16
        error = _pysot_distance(_centres(gt), _centres(pred))
        norm_error = _pysot_distance(_centres(gt) / wh, _centres(pred) / wh)
    return FrameScores(overlap, error, norm_error, np.ones(n, dtype=bool))


# --------------------------------------------------------------------------- got10k


def _got10k_frames(pred: np.ndarray, gt: np.ndarray) -> FrameScores:
    counted = ~np.isnan(gt).any(axis=1)
    counted[:1] = False
    with np.errstate(invalid="ignore", divide="ignore"):
        iw = np.maximum(np.minimum(pred[:, 0] + pred[:, 2], gt[:, 0] + gt[:, 2]) - np.maximum(pred[:, 0], gt[:, 0]), 0)
        ih = np.maximum(np.minimum(pred[:, 1] + pred[:, 3], gt[:, 1] + gt[:, 3]) - np.maximum(pred[:, 1], gt[:, 1]), 0)
        inter = iw * ih
        union = pred[:, 2] * pred[:, 3] + gt[:, 2] * gt[:, 3] - inter
        overlap = np.clip(inter / (union + np.finfo(float).eps), 0.0, 1.0)
        offset = _centres(pred) - _centres(gt)
        error = np.sqrt((offset ** 2).sum(axis=1))
        norm_error = np.sqrt(((offset / np.maximum(1.0, gt[:, 2:])) ** 2).sum(axis=1))
    overlap[np.isnan(overlap)] = 0.0  # dcfkit: a NaN prediction overlaps nothing (the toolkit: AO NaN)
    return FrameScores(overlap, error, norm_error, counted)


# --------------------------------------------------------------------------- registry

_OTB = Protocol("otb", "OTB / UAV123 MATLAB toolkit",
                "calcSeqErrRobust.m, calcRectInt.m, genPerfMat.m, plotDrawSave.m", _otb_frames,
                success_thresholds=np.linspace(0.0, 1.0, 21),
                precision_thresholds=np.arange(0, 51, dtype=np.float64),
                norm_precision_thresholds=np.linspace(0.0, 0.5, 51),
                drop_zero_curves=True)

PROTOCOLS: dict[str, Protocol] = {p.name: p for p in (
    _OTB,
    Protocol("pysot", "pysot toolkit OPE benchmark",
             "toolkit/evaluation/ope_benchmark.py, toolkit/utils/statistics.py", _pysot_frames,
             success_thresholds=np.arange(0, 1.05, 0.05),
             precision_thresholds=np.arange(0, 51, 1, dtype=np.float64),
             norm_precision_thresholds=np.arange(0, 51, 1) / 100),
    Protocol("got10k", "got10k toolkit, GOT-10k report",
             "got10k/experiments/got10k.py, got10k/utils/metrics.py", _got10k_frames,
             success_thresholds=np.linspace(0.0, 1.0, 101),
             precision_thresholds=np.arange(0, 51, dtype=np.float64),
             norm_precision_thresholds=np.linspace(0.0, 0.5, 51),
             weighting="frame", overlap_scores=True),
    dataclasses.replace(_OTB, name="lasot", title="LaSOT toolkit", frames=_lasot_frames,
                        source="calc_seq_err_robust.m, eval_tracker.m, calc_rect_int.m, plot_draw_save.m"),
)}


def get_protocol(protocol: str | Protocol) -> Protocol:
    """The :class:`Protocol` named ``protocol`` (case-insensitive); a Protocol passes through."""
    if isinstance(protocol, Protocol):
        return protocol
    try:
        return PROTOCOLS[str(protocol).lower()]
    except KeyError:
        raise ValueError(f"unknown scoring protocol {shown(protocol)}; one of: {', '.join(PROTOCOLS)}") from None

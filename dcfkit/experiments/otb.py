"""OTB's robustness experiments (Wu et al., TPAMI 2015), as the OTB toolkit makes their runs.

**TRE** (``splitSeqTRE.m``): of the frames whose ground truth is valid (all four 1-based
values > 0, none NaN), the last with at least 20 frames from it to the end is the
``E``-th; the 20 segments start at the valid frames numbered ``floor(1 + k E / 19)``,
k = 0..18, and ``E``, and each starts from its frame's ground truth. Short sequences repeat a
start, as the toolkit does. The toolkit also leaves out the frames of its ``initOmit``
files, which only OTB publishes: dcfkit has none.

**SRE** (``shiftInitBB.m``): 12 runs of the whole sequence, from frame 1's box moved by 10%
of its size (left, right, up, down: ``ceil``; the four corners move that corner out, the
opposite one staying: ``round``) or scaled about its centre by 0.8, 0.9, 1.1, 1.2
(``round``), then kept inside the image. Rounding is MATLAB's (halves away from zero), on
1-based boxes.

A run whose first box no tracker can start from (a TRE start whose ground truth lies outside
the image, an SRE box kept inside the image with no width left) is left out with its reason
(:func:`~dcfkit.experiments.starts.plan_runs`), as the toolkit's run would end before its
first frame; the others keep their names.
"""
from __future__ import annotations

import dataclasses
import math

import numpy as np

from dcfkit.datasets import DatasetError, Sequence
from dcfkit.experiments.starts import Plan, plan_runs

__all__ = ["SRE_SHIFTS", "TRE_MIN_FRAMES", "TRE_SEGMENTS", "run_name", "sre_box", "sre_plan", "sre_runs", "tre_plan",
           "tre_runs", "tre_starts"]

TRE_SEGMENTS = 20
TRE_MIN_FRAMES = 20  # a segment's least length (minNum)
SRE_SHIFTS = ("left", "right", "up", "down", "topLeft", "topRight", "bottomLeft", "bottomRight",
              "scale_8", "scale_9", "scale_11", "scale_12")


def run_name(seq: Sequence, k: int) -> str:
    """The name of run ``k`` (1-based) of ``seq``: ``<sequence>_<k>``, k in three digits."""
    return f"{seq.name}_{k:03d}"


def _valid_frames(gt: np.ndarray) -> np.ndarray:
    """0-based indices of the frames splitSeqTRE may start from: 1-based x, y, w, h all > 0."""
    with np.errstate(invalid="ignore"):
        one_based = gt + np.array([1.0, 1.0, 0.0, 0.0])
        return np.flatnonzero((one_based > 0).all(axis=1))


def tre_starts(gt: np.ndarray, segments: int = TRE_SEGMENTS, min_frames: int = TRE_MIN_FRAMES) -> list[int]:
    """The 0-based first frames of the TRE segments of a sequence with ground truth ``gt``."""
    gt = np.asarray(gt, dtype=np.float64).reshape(-1, 4)
    valid = _valid_frames(gt)
    enough = valid[len(gt) - valid >= min_frames]
    if not len(enough):
        raise DatasetError(f"no frame with valid ground truth has {min_frames} frames after it ({len(gt)} frames): "
                           f"too short for TRE")
    last = int(np.searchsorted(valid, enough[-1])) + 1  # E: 1-based position among the valid frames
    # 1:E/(S-1):E in exact integers: floor(1 + k E / (S-1)) while 1 + k E / (S-1) <= E
    ks = [k for k in range(segments) if (segments - 1) + k * last <= last * (segments - 1)]
    positions = [((segments - 1) + k * last) // (segments - 1) for k in ks] + [last]
    return [int(valid[p - 1]) for p in positions]


def tre_plan(seq: Sequence) -> Plan:
    """One run per TRE segment: the frames from its start to the end, from its ground truth
    (a start whose ground truth lies outside the image is left out)."""
    try:
        starts = tre_starts(seq.ground_truth)
    except DatasetError as exc:
        raise DatasetError(f"sequence {seq.name!r}: {exc}") from None
    runs = [(dataclasses.replace(seq, name=run_name(seq, k), frames=seq.frames[s:], ground_truth=seq.ground_truth[s:],
                                 start_box=None), f"from frame {s + 1}") for k, s in enumerate(starts, 1)]
    return plan_runs(seq, runs, "TRE", seq.image_size[::-1])


def tre_runs(seq: Sequence) -> list[Sequence]:
    """The TRE runs of ``seq`` that start (:func:`tre_plan`)."""
    return tre_plan(seq).runs


def _matlab_round(x: float) -> float:
    return math.copysign(math.floor(abs(x) + 0.5), x)


def _shifted(r: list[float], shift: str) -> list[float]:
    """shiftInitBB's move of the 1-based box ``r`` (before it is kept inside the image)."""
    x, y, w, h = r
    right, bottom = x + w - 1, y + h - 1
    if shift.startswith("scale_"):
        ratio = int(shift[6:]) / 10
        cx, cy, sw, sh = x + w / 2, y + h / 2, ratio * w, ratio * h
        return [_matlab_round(v) for v in (cx - sw / 2, cy - sh / 2, sw, sh)]
    moves = {"left": (-math.ceil(0.1 * w), 0), "right": (math.ceil(0.1 * w), 0),
             "up": (0, -math.ceil(0.1 * h)), "down": (0, math.ceil(0.1 * h))}
    if shift in moves:
        return [x + moves[shift][0], y + moves[shift][1], w, h]
    if "Left" in shift:
        x = _matlab_round(x - 0.1 * w)
    else:
        right = _matlab_round(right + 0.1 * w)
    if shift.startswith("top"):
        y = _matlab_round(y - 0.1 * h)
    else:
        bottom = _matlab_round(bottom + 0.1 * h)
    return [x, y, right - x + 1, bottom - y + 1]


def sre_box(box, shift: str, image_size: tuple[int, int]) -> np.ndarray:
    """The SRE first box (0-based) for ``shift`` of :data:`SRE_SHIFTS` from the 0-based ``box``,
    in an image of ``image_size`` ``(height, width)``."""
    if shift not in SRE_SHIFTS:
        raise ValueError(f"unknown SRE shift {shift!r}; one of {', '.join(SRE_SHIFTS)}")
    height, width = image_size
    x, y, w, h = _shifted([float(box[0]) + 1, float(box[1]) + 1, float(box[2]), float(box[3])], shift)
    x, y = max(x, 1.0), max(y, 1.0)
    w = min(w, width - x + 1)
    h = min(h, height - y + 1)
    return np.array([x - 1, y - 1, w, h], dtype=np.float64)


def sre_plan(seq: Sequence) -> Plan:
    """One run of the whole sequence per SRE shift of frame 1's box (its image's size read); a
    box kept inside the image with no width or height left is left out."""
    first = seq.ground_truth[0]
    if not (np.isfinite(first).all() and (first[2:] > 0).all()):
        raise DatasetError(f"sequence {seq.name!r}: SRE shifts frame 1's ground truth, which is NaN or empty")
    size = seq.image_size[::-1]  # (h, w)
    return plan_runs(seq, [(dataclasses.replace(seq, name=run_name(seq, k), start_box=sre_box(first, shift, size)),
                            f"shift {shift}") for k, shift in enumerate(SRE_SHIFTS, 1)], "SRE", size)


def sre_runs(seq: Sequence) -> list[Sequence]:
    """The SRE runs of ``seq`` that start (:func:`sre_plan`)."""
    return sre_plan(seq).runs

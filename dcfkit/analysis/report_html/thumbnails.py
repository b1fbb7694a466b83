"""Small JPEG views of a sequence's frames with the boxes to draw on them, for the HTML report.

Per sequence: frame 1 whole (where the target is in the scene), then, in each third of the
rest, the frame where the trackers overlap the ground truth least on average: a failure
shows there if there is one. Those frames are cropped to the ground truth and every
tracker's box with a margin, so a small target stays visible and a box that drifted away
widens the view. Boxes are returned in thumbnail pixels, not drawn into the JPEG: the page
draws them, and hides a tracker's when its legend entry is clicked.
"""
from __future__ import annotations

import base64
import logging
from typing import Mapping
from typing import Sequence as Seq

import cv2
import numpy as np

from dcfkit.analysis.metrics import as_boxes, iou
from dcfkit.datasets import DatasetError, Sequence

log = logging.getLogger(__name__)

WIDTH = 160          # pixels of every thumbnail's width
QUALITY = 70         # JPEG quality
SEGMENTS = 3         # frames chosen after frame 1, one per equal part of the sequence
MIN_CROP = 320       # narrowest crop in frame pixels: at most 2x zoom, no upscaling blur


def choose_frames(gt: np.ndarray, boxes: Seq[np.ndarray]) -> list[int]:
    """0-based frame indices: 0, then per third of frames 1..N-1 the one whose mean IoU over
    ``boxes`` (each ``(N, 4)``) with ``gt`` is lowest, frames without a valid ground truth
    left out (a third without any gives its middle frame)."""
    n = len(gt)
    valid = np.isfinite(gt).all(axis=1) & (gt[:, 2] > 0) & (gt[:, 3] > 0)
    mean = np.mean([iou(b, gt) for b in boxes], axis=0) if len(boxes) else np.ones(n)  # NaN where gt is
    cost = np.where(valid, mean, np.inf)
    chosen = [0]
    edges = np.linspace(1, n, SEGMENTS + 1).round().astype(int)
    for lo, hi in zip(edges[:-1], edges[1:]):
        if hi > lo:
            part = cost[lo:hi]
            chosen.append(int(lo + np.argmin(part)) if np.isfinite(part).any() else (lo + hi - 1) // 2)
    return sorted(set(chosen))


def crop_window(boxes: np.ndarray, size: tuple[int, int]) -> tuple[float, float, float, float]:
    """``(x, y, w, h)`` of the frame to show for ``boxes`` (finite rows of ``(K, 4)``): their
    union with a margin of one target size, of the frame's aspect, at least
    :data:`MIN_CROP` wide, inside the frame of ``size`` ``(H, W)``."""
    height, width = size
    boxes = boxes[np.isfinite(boxes).all(axis=1) & (boxes[:, 2] > 0) & (boxes[:, 3] > 0)]
    if not len(boxes):
        return 0.0, 0.0, float(width), float(height)
    x0, y0 = np.clip(boxes[:, 0].min(), 0, width), np.clip(boxes[:, 1].min(), 0, height)
    x1 = np.clip((boxes[:, 0] + boxes[:, 2]).max(), 0, width)
    y1 = np.clip((boxes[:, 1] + boxes[:, 3]).max(), 0, height)
    margin = max(boxes[0, 2], boxes[0, 3])  # the first row is the ground truth when there is one
    w = max(x1 - x0 + 2 * margin, (y1 - y0 + 2 * margin) * width / height, min(MIN_CROP, width))
    w = min(w, width)
    h = w * height / width
    cx, cy = (x0 + x1) / 2, (y0 + y1) / 2
    return (float(np.clip(cx - w / 2, 0, width - w)), float(np.clip(cy - h / 2, 0, height - h)), float(w), float(h))


def jpeg_base64(image: np.ndarray) -> str:
    ok, data = cv2.imencode(".jpg", image, [cv2.IMWRITE_JPEG_QUALITY, QUALITY])
    return base64.b64encode(data.tobytes()).decode("ascii")


def _in_view(box: np.ndarray, window: tuple, scale: float) -> list[float] | None:
    if not (np.isfinite(box).all() and box[2] > 0 and box[3] > 0):
        return None
    return [round(float((box[0] - window[0]) * scale), 1), round(float((box[1] - window[1]) * scale), 1),
            round(float(box[2] * scale), 1), round(float(box[3] * scale), 1)]


def thumbnail(seq: Sequence, index: int, boxes: Seq[np.ndarray], whole: bool) -> dict:
    """Frame ``index`` of ``seq`` (the whole frame, or the crop around the boxes) as
    ``{"frame" (1-based), "w", "h", "jpeg" (base64), "gt", "boxes", "iou"}``: the ground truth
    and each tracker's box in thumbnail pixels (None where there is none), and each
    tracker's IoU with the ground truth (None where the ground truth is not valid)."""
    image = seq.frame(index)
    gt = seq.ground_truth[index]
    rows = np.array([gt] + [b[index] for b in boxes])
    window = (0.0, 0.0, float(image.shape[1]), float(image.shape[0])) if whole else crop_window(rows, image.shape[:2])
    scale = WIDTH / window[2]
    height = max(1, round(window[3] * scale))
    x, y, w, h = (int(round(v)) for v in window)
    view = cv2.resize(image[y:y + h, x:x + w], (WIDTH, height), interpolation=cv2.INTER_AREA)
    valid = bool(np.isfinite(gt).all() and gt[2] > 0 and gt[3] > 0)
    overlap = [round(float(v), 3) if valid else None for v in iou(rows[1:], np.tile(gt, (len(rows) - 1, 1)))]
    return {"frame": index + 1, "w": WIDTH, "h": height, "zoom": round(image.shape[1] / window[2], 2),
            "jpeg": jpeg_base64(view), "gt": _in_view(gt, window, scale),
            "boxes": [_in_view(b, window, scale) for b in rows[1:]], "iou": overlap}


def sequence_thumbnails(seq: Sequence, results: Mapping[str, Mapping], trackers: Seq[str]) -> list[dict]:
    """The thumbnails of ``seq`` (see the module) with the boxes of ``trackers`` (in that
    order) from ``results`` (tracker -> sequence name -> result with ``boxes``). A frame that
    cannot be read is left out, with a warning: the report goes on without it."""
    boxes = [as_boxes(results[t][seq.name].boxes, len(seq))  # a short result misses its last frames
             if seq.name in results.get(t, {}) else np.full((len(seq), 4), np.nan) for t in trackers]
    thumbs = []
    for i in choose_frames(seq.ground_truth, boxes):
        try:
            thumbs.append(thumbnail(seq, i, boxes, whole=(i == 0)))
        except DatasetError as exc:
            log.warning("report.html: no thumbnail of frame %d of %r: %s", i + 1, seq.name, exc)
    return thumbs


"""Knowing a target is lost and finding it again (the discrete loop's ``reliability`` and
``redetect`` slots): each detection is scored by the reliability component, and on a frame that
scores below 1 the re-detection component's candidate regions are searched with the filter at
the current scale; a candidate it accepts replaces the frame's detection."""
from __future__ import annotations

import dataclasses

import numpy as np

from dcfkit.components.labels.base import Detection
from dcfkit.components.reliability.base import unreliable
from dcfkit.numerics.patches import round_half_away


@dataclasses.dataclass(frozen=True)
class Located:
    """Where one frame's detection puts the target: its ``position`` (row, col), the ``centre``
    of the search region it was found in, the detection's ``scale`` (the search scale times its
    factor) and ``step`` (image pixels per cell there), the ``detection``, the search
    ``sample``'s spectrum at that scale, its per-channel ``channel_maps`` (None without channel
    weights) and whether re-detection ``jumped`` to it."""

    position: np.ndarray
    centre: np.ndarray
    scale: float
    step: float
    detection: Detection
    sample: np.ndarray
    channel_maps: np.ndarray | None = None
    jumped: bool = False


def judged(tracker, detection: Detection) -> Detection:
    """``detection`` with the reliability component's score (unchanged without one)."""
    if tracker.reliability is None:
        return detection
    return dataclasses.replace(detection, score=float(tracker.reliability.score(detection)))


def gated(tracker, detection: Detection) -> bool:
    """Whether the schedule holds the models on this frame for its unreliable detection (the
    ``reliable`` schedule's frames, whose scale is then kept as well)."""
    return getattr(tracker.schedule, "needs_reliability", False) and unreliable(detection.score)


def recovered(tracker, image: np.ndarray, found: Located) -> Located:
    """``found``, or the re-detection candidate that replaces it when its detection is unreliable."""
    if tracker.redetect is None or not unreliable(found.detection.score):
        return found
    g = tracker.geometry
    region = g.sample_size * tracker.scale  # image pixels one search region covers at the current scale
    centres = tracker.redetect.candidates(found.centre.copy(), region.copy(), tuple(image.shape[:2]))
    probes = [probe(tracker, image, np.asarray(c, dtype=float)) for c in centres]
    if probes:  # the best candidate searched again around its own peak, where the window does not damp it
        best = int(np.argmax([p.detection.score for p in probes]))
        again = probe(tracker, image, probes[best].position)
        probes[best] = again if again.detection.score > probes[best].detection.score else probes[best]
    scores = np.array([p.detection.score for p in probes], dtype=float)
    pick = int(tracker.redetect.accept(float(found.detection.score), scores))
    return probes[pick] if pick >= 0 else found


def probe(tracker, image: np.ndarray, centre: np.ndarray) -> Located:
    """The filter's detection in the search region around ``centre`` at the current scale, placed
    as the loop places the search's."""
    g, p = tracker.geometry, tracker.params
    centre = tracker._clamp(centre, image.shape)
    if p.sampling == "whole_pixel" and p.translation != "exact_centre":
        centre = round_half_away(centre)
    sample = tracker._sample(image, centre, tracker.scale)[None]
    maps = tracker._response(sample)
    channel_maps = tracker._channel_maps[0] if tracker.channel_weights is not None else None
    if not np.all(np.isfinite(maps)):  # a region that overflows the filter is no candidate
        maps = np.zeros_like(maps)
    _, dy, dx = tracker._peak(maps, sample)
    move = np.array([dy, dx]) * g.cell_size * tracker.scale
    if p.translation == "whole_pixel":
        move = round_half_away(move)
    peak = np.unravel_index(int(np.argmax(maps[0])), g.filter_size)
    detection = judged(tracker, Detection(maps[0], (int(peak[0]), int(peak[1])), g.target_cells, (dy, dx)))
    return Located(tracker._clamp(centre + move, image.shape), centre, tracker.scale, g.cell_size * tracker.scale,
                   detection, sample[0], channel_maps, jumped=True)

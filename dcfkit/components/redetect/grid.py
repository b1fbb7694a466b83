"""``grid``: search regions on a square grid around the last reliable position, nearest first.

The target is lost where the filter was last sure of it or near; so the regions to try are
the grid points ``anchor + stride · search_size · (i, j)`` for ``max(|i|, |j|) ≤ rings``,
ordered by ring (then clockwise from the top), the one searched this frame left out. A lost
frame probes the next ``per_frame`` of them, so consecutive lost frames sweep the
neighbourhood: the cost of a frame stays bounded. A candidate is taken when its score is
reliable (≥ 1) and at least ``margin`` times the frame's own score.
"""
from __future__ import annotations

import dataclasses

import numpy as np

from dcfkit.components.redetect.base import Redetect
from dcfkit.components.reliability.base import RELIABLE
from dcfkit.params import param


class Grid(Redetect):
    """Search regions on a grid around the last reliable centre, ``per_frame`` a lost frame."""

    name = "grid"

    @dataclasses.dataclass(frozen=True)
    class Params:
        stride: float = param(0.5, "grid spacing, in search regions (0.5: neighbours overlap by half)",
                              gt=0, le=10)
        rings: int = param(2, "grid rings around the last reliable centre ((2 rings + 1)² - 1 regions)",
                           ge=1, le=50)
        whole_frame: bool = param(False, "extend the rings until they cover the whole frame (rings: ignored)")
        per_frame: int = param(8, "regions probed on one lost frame (the next ones on the next lost frame)",
                               ge=1, le=10000)
        margin: float = param(1.0, "a candidate's score must be at least this times the frame's own score "
                              "(and reliable: >= 1)", ge=1, le=1e6)

    def __init__(self, params=None):
        super().__init__(params)
        self.reset()

    def reset(self) -> None:
        self.anchor = None  # the last reliable centre
        self.next = 0  # the first grid point not yet probed in this lost stretch

    def observe(self, centre: np.ndarray, reliable: bool) -> None:
        if reliable or self.anchor is None:
            self.anchor = np.array(centre, dtype=float)
        if reliable:
            self.next = 0  # a new lost stretch starts from the nearest ring

    def candidates(self, centre: np.ndarray, search_size: np.ndarray, image_size: tuple[int, int]) -> np.ndarray:
        anchor = np.array(centre if self.anchor is None else self.anchor, dtype=float)
        spacing = self.params.stride * np.asarray(search_size, dtype=float)
        rings = self.params.rings
        if self.params.whole_frame:  # enough rings to reach every corner of the frame from the anchor
            far = np.maximum(anchor, np.asarray(image_size, dtype=float) - anchor)
            rings = int(np.ceil(np.max(far / spacing)))
        points = anchor + grid_offsets(rings) * spacing
        inside = np.all((points >= 0) & (points <= np.asarray(image_size, dtype=float) - 1), axis=1)
        searched = np.all(np.abs(points - np.asarray(centre, dtype=float)) < spacing / 2, axis=1)
        points = points[inside & ~searched]
        if len(points) == 0:
            return np.zeros((0, 2))
        start = self.next % len(points)
        chosen = np.take(points, np.arange(start, start + min(self.params.per_frame, len(points))), axis=0,
                         mode="wrap")
        self.next = start + len(chosen)
        return chosen

    def accept(self, current: float, scores: np.ndarray) -> int:
        if len(scores) == 0:
            return -1
        best = int(np.argmax(scores))
        bar = max(RELIABLE, self.params.margin * current)
        return best if scores[best] >= bar else -1


def grid_offsets(rings: int) -> np.ndarray:
    """(N, 2) integer ``(i, j)`` with ``max(|i|, |j|) ≤ rings``, ring 0 (the anchor) first, then
    each ring clockwise from its top-left corner."""
    out = [(0, 0)]
    for k in range(1, rings + 1):
        top = [(-k, j) for j in range(-k, k + 1)]
        right = [(i, k) for i in range(-k + 1, k + 1)]
        bottom = [(k, j) for j in range(k - 1, -k - 1, -1)]
        left = [(i, -k) for i in range(k - 1, -k, -1)]
        out += top + right + bottom + left
    return np.array(out, dtype=float)

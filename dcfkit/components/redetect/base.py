"""The redetect kind: on an unreliable frame, the search regions to try and the one to take."""
from __future__ import annotations

import numpy as np

from dcfkit.components.base import Component, Contract
from dcfkit.contracts import array, scalar


def _candidate_index(value, args, component) -> str | None:
    """-1 or the index of one of the ``args[1]`` candidates."""
    problem = scalar(-1, 1e9, integer=True)(value, args, component)
    if problem is None and int(value) >= len(args[1]):
        problem = f"{int(value)}, expected -1 or the index of one of the {len(args[1])} candidates"
    return problem


class Redetect(Component, declares="redetect"):
    """Proposes where to search for a lost target and decides whether a candidate replaces the
    frame's detection (``redetect:`` in a config; none by default; it needs a ``reliability:``
    component). The tracker calls ``reset()`` at every ``init``; on a frame whose detection
    scores below 1, ``candidates(centre, search_size, image_size)`` for the (K, 2) ``(row,
    col)`` centres of search regions to probe with the filter at the current scale, then
    ``accept(current, scores)`` with the frame's score and the K candidates' scores (each the
    reliability component's); after every detected frame ``observe(centre, reliable)`` with
    the target's centre as decided and whether it was reliable."""

    contract = Contract(required={"candidates": ("centre", "search_size", "image_size"),
                                  "accept": ("current", "scores")},
                        optional={"observe": ("centre", "reliable"), "reset": ()},
                        returns={"candidates": array((None, 2)),
                                 "accept": _candidate_index})

    def candidates(self, centre: np.ndarray, search_size: np.ndarray, image_size: tuple[int, int]) -> np.ndarray:
        """(K, 2) centres (row, col, image pixels) of the regions to search on this frame
        (K may be 0). ``centre``: where this frame was searched; ``search_size``: the (h, w)
        pixels one search region covers."""
        raise NotImplementedError

    def accept(self, current: float, scores: np.ndarray) -> int:
        """The index of the candidate that replaces the frame's detection, or -1 for none."""
        raise NotImplementedError

    def observe(self, centre: np.ndarray, reliable: bool) -> None:
        """Where the target was placed on this frame, and whether the frame was reliable."""

    def reset(self) -> None:
        """Forget the frames of an earlier target."""

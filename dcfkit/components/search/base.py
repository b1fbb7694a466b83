"""The search kind: where a frame's search area is centred."""
from __future__ import annotations

import numpy as np

from dcfkit.components.base import Component, Contract
from dcfkit.contracts import array

MAX_COORDINATE = 2.0**31  # a centre (y, x) in pixels: no image is that large, and int32 holds it


class Search(Component, declares="search"):
    """Where the next search area is centred. The tracker calls ``reset`` at every ``init`` (a
    new target), ``centre()`` at the start of every later frame, and ``observe`` once the target
    is found on it (not on a held blank frame). Positions are (y, x) image pixels, finite."""

    contract = Contract(optional={"reset": ("position",), "centre": (), "observe": ("position",)},
                        returns={"centre": array((2,), kinds="iuf", largest=MAX_COORDINATE)})

    def reset(self, position: np.ndarray) -> None:
        """Start at the first frame's target centre (y, x)."""
        self.position = np.asarray(position, dtype=float)

    def centre(self) -> np.ndarray:
        """Centre (y, x) of the next search area."""
        return self.position.copy()

    def observe(self, position: np.ndarray) -> None:
        """The target centre found in the current frame."""
        self.position = np.asarray(position, dtype=float)

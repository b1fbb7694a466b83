"""Search strategies: where the next frame's search area is centred."""
from __future__ import annotations

import dataclasses

import numpy as np

from .params import param
from .registry import Component


class Search(Component):
    kind = "search"

    def reset(self, position: np.ndarray) -> None:
        """Start at the first frame's target centre (y, x)."""
        self.position = np.asarray(position, dtype=float)

    def centre(self) -> np.ndarray:
        """Centre (y, x) of the next search area."""
        return self.position.copy()

    def observe(self, position: np.ndarray) -> None:
        """The target centre found in the current frame."""
        self.position = np.asarray(position, dtype=float)


class Fixed(Search):
    """Search around the last position (STRCF, BACF)."""

    name = "fixed"


class MotionAware(Search):
    """Eqs. (13)-(14): V^t = p^t - p^{t-1}; the next search centre is p^t + gain · V^t."""

    name = "motion_aware"

    @dataclasses.dataclass(frozen=True)
    class Params:
        gain: float = param(1.0, "multiplier of the last displacement (1 = Eq. 14)")

    def reset(self, position):
        super().reset(position)
        self.velocity = np.zeros(2)  # V^1 = 0 (Algorithm 1)

    def centre(self):
        return self.position + self.params.gain * self.velocity

    def observe(self, position):
        position = np.asarray(position, dtype=float)
        self.velocity = position - self.position  # Eq. (13)
        self.position = position


BUILTIN = (Fixed, MotionAware)

"""Search strategies: where the next frame's search area is centred."""
from __future__ import annotations

import dataclasses

import numpy as np

from dcfkit.components.base import Component, Contract
from dcfkit.contracts import array
from dcfkit.params import param

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


class Fixed(Search):
    """Search around the last position (STRCF, BACF)."""

    name = "fixed"


MAX_GAIN = 10.0


class MotionAware(Search):
    """Eqs. (13)-(14): V^t = p^t - p^{t-1}; the next search centre is p^t + gain · V^t."""

    name = "motion_aware"

    @dataclasses.dataclass(frozen=True)
    class Params:
        # 0: the last position; beyond MAX_GAIN the predicted centre leaves any image (with
        # tracker.clamp_position false, 1e30 px away: the sampling broke); < 0: against the motion
        gain: float = param(1.0, "multiplier of the last displacement (1 = Eq. 14)", ge=0, le=MAX_GAIN)

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

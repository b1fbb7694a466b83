"""The search strategies: the last position, and DR²Track's motion-aware prediction (Eq. 14)."""
from __future__ import annotations

import dataclasses

import numpy as np

from dcfkit.components.search.base import Search
from dcfkit.params import param


class LastPosition(Search):
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

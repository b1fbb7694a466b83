"""The plain Gaussian label of every DCF since MOSSE."""
from __future__ import annotations

import numpy as np

from dcfkit.components.labels.base import Label


class Gaussian(Label):
    """The fixed Gaussian label of STRCF/BACF (Eq. 1)."""

    name = "gaussian"

    def make(self, g, detection):
        return g, np.zeros((0, 2), dtype=int)

"""Labels: the regression target y of each frame's training step (Eq. 1; Eq. 3 repressed).

Where to add one: subclass :class:`~dcfkit.components.labels.base.Label`."""
from __future__ import annotations

from dcfkit.components.labels.base import Detection, Label, gaussian_label
from dcfkit.components.labels.distractors import (
    MAX_MU,
    MAX_NEIGHBOURHOOD,
    DistractorRepressed,
    authors_distractors,
    regional_maxima,
)
from dcfkit.components.labels.gaussian import Gaussian

BUILTIN = (Gaussian, DistractorRepressed)

__all__ = ["BUILTIN", "Detection", "DistractorRepressed", "Gaussian", "Label", "MAX_MU", "MAX_NEIGHBOURHOOD",
           "authors_distractors", "gaussian_label", "regional_maxima"]

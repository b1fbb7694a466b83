"""Regularizers of the filter: spatial (the window w of Eqs. 1, 2, 10) and temporal (θ).

A spatial regularizer returns w² over the filter grid, (H, W) float32 in the centred layout
of the image patch (the target in the middle). The solver's h-step (Eq. 10) uses it as
h = γK (v + z) / (w² + γK); ``inf`` entries force h to zero there, which is BACF's
cropping matrix P (h = P^T P h). The temporal regularizer contributes θ‖h - h_prev‖²
(Eq. 1); its θ is 0 on the first frame (Remark 1).

* :mod:`.base` -- the contracts (:class:`SpatialRegularizer`, :class:`TemporalRegularizer`)
  and :func:`target_mask`;
* :mod:`.windows` -- the fixed ones: ``box`` (STRCF), ``smooth`` (SRDCF), ``crop`` (BACF),
  ``temporal`` (STRCF's θ);
* :mod:`.adaptive` -- AutoTrack's, set each frame from the response's variation.
"""
from __future__ import annotations

from dcfkit.components.regularizers.adaptive import GlobalVariation, LocalVariation, response_variation
from dcfkit.components.regularizers.base import (
    MAX_POWER,
    MAX_THETA,
    MAX_WEIGHT,
    PLACEMENTS,
    SpatialRegularizer,
    TemporalRegularizer,
    target_mask,
)
from dcfkit.components.regularizers.windows import BoxWindow, Crop, SmoothWindow, Temporal

BUILTIN = (BoxWindow, SmoothWindow, Crop, Temporal, LocalVariation, GlobalVariation)

__all__ = ["BUILTIN", "BoxWindow", "Crop", "GlobalVariation", "LocalVariation", "MAX_POWER", "MAX_THETA",
           "MAX_WEIGHT", "PLACEMENTS", "SmoothWindow", "SpatialRegularizer", "Temporal", "TemporalRegularizer",
           "response_variation", "target_mask"]

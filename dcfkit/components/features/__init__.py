"""Feature components: each maps an image patch to a (C, H/cell, W/cell) float32 map.

A feature has ``channels(...)`` and ``extract(patch, cell_size)``; the patch is an
(H, W, 3) uint8 BGR array whose sides are multiples of ``cell_size``. The tracker stacks
the maps of the configured features along the channel axis (the paper uses gray + fHOG + CN,
1 + 31 + 10 = 42 channels at cell size 4).
"""
from __future__ import annotations

from dcfkit.components.features.base import MAX_FEATURE_VALUE, Feature, cell_average, extract_stack
from dcfkit.components.features.colornames import ColorNames
from dcfkit.components.features.fhog import FHOG, fhog
from dcfkit.components.features.gray import MATLAB_GRAY_WEIGHTS, Gray
from dcfkit.components.features.intensity import IntensityTable

BUILTIN = (Gray, FHOG, ColorNames, IntensityTable)

__all__ = ["BUILTIN", "ColorNames", "FHOG", "Feature", "Gray", "IntensityTable", "MATLAB_GRAY_WEIGHTS", "MAX_FEATURE_VALUE",
           "cell_average", "extract_stack", "fhog"]

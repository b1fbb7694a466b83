"""Scale estimators.

``fixed`` (KCF): the target keeps its initial size. ``pyramid`` (STRCF, BACF): the
translation filter is evaluated on samples at a few relative scales and the best response
picks the scale. ``dsst`` (DR²Track and DSST, after Danelljan et al. PAMI 2017): a separate
1-D correlation filter over a pyramid of target-sized fHOG samples; ``fdsst`` (ECO) its
compressed form, 17 scales read at 33. The last two keep the
scale within limits set at init (search region at least ~5 px; target at most the image, or
its initial size if that is larger).
"""
from __future__ import annotations

from dcfkit.components.scale.base import MAX_SCALES, MIN_LAM, ScaleEstimator, scale_limits
from dcfkit.components.scale.dsst import DSST
from dcfkit.components.scale.fdsst import FDSST
from dcfkit.components.scale.pyramid import FixedScale, Pyramid

BUILTIN = (FixedScale, Pyramid, DSST, FDSST)

__all__ = ["BUILTIN", "DSST", "FDSST", "FixedScale", "MAX_SCALES", "MIN_LAM", "Pyramid", "ScaleEstimator", "scale_limits"]

"""Scales searched as a pyramid of factors around the last one (or none: a fixed scale)."""
from __future__ import annotations

import dataclasses

from dcfkit.components.scale.base import MAX_SCALES, ScaleEstimator, check_span, scale_factors
from dcfkit.params import param


class FixedScale(ScaleEstimator):
    """No scale estimation: the box keeps its initial size (KCF). The base class's one search
    scale, 1, and an update that returns the scale it is given (within the limits, which
    hold the initial scale)."""

    name = "fixed"


class Pyramid(ScaleEstimator):
    """Evaluate the translation filter at ``n_scales`` scales ``step`` apart."""

    name = "pyramid"

    @dataclasses.dataclass(frozen=True)
    class Params:
        n_scales: int = param(5, "number of scales searched", ge=1, le=MAX_SCALES)
        step: float = param(1.01, "ratio between neighbouring scales", gt=1)

        def validate(self):
            """step ** ((n_scales - 1) / 2) <= 10: the scales span at most x10 each way."""
            return check_span(self.n_scales, self.step)

    def search_factors(self):
        return scale_factors(self.params.n_scales, self.params.step)

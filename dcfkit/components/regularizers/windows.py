"""The fixed regularizers: STRCF's box window, SRDCF's smooth window, BACF's crop, STRCF's θ."""
from __future__ import annotations

import dataclasses

import numpy as np

from dcfkit.components.regularizers.base import (
    MAX_POWER,
    MAX_THETA,
    MAX_WEIGHT,
    PLACEMENTS,
    SpatialRegularizer,
    TemporalRegularizer,
    target_mask,
)
from dcfkit.params import param


class BoxWindow(SpatialRegularizer):
    """STRCF/DR²Track window: ``inside`` on the target box, ``outside`` elsewhere."""

    name = "box"

    @dataclasses.dataclass(frozen=True)
    class Params:
        inside: float = param(1e-3, "w inside the target box (reg_window_min)", ge=0, le=MAX_WEIGHT)
        outside: float = param(1e5, "w outside the target box (reg_window_max)", ge=0, le=MAX_WEIGHT)
        placement: str = param("centred", "where an odd box sits in an even patch: 'centred' or 'authors' "
                               "(init_regwindow's, a cell lower and to the right)", choices=PLACEMENTS)

        def validate(self):
            """inside <= outside."""
            if self.inside > self.outside:
                return "need inside <= outside"

    def weights_squared(self, shape, target_cells):
        mask = target_mask(shape, target_cells, self.params.placement)
        w = np.where(mask, self.params.inside, self.params.outside)
        return (w**2).astype(np.float32)


class SmoothWindow(SpatialRegularizer):
    """SRDCF's quadratic window: w = min + (edge - min)·((2y/h)² + (2x/w)²) — 'edge' at the box border."""

    name = "smooth"

    @dataclasses.dataclass(frozen=True)
    class Params:
        minimum: float = param(0.1, "w at the target centre", ge=0, le=MAX_WEIGHT)
        edge: float = param(3.0, "w at the border of the target box", ge=0, le=MAX_WEIGHT)
        # <= 0: an infinite weight at the centre
        power: float = param(2.0, "exponent of the normalised distance", gt=0, le=MAX_POWER)

        def validate(self):
            """minimum <= edge."""
            if self.minimum > self.edge:
                return "need minimum <= edge"

    def weights_squared(self, shape, target_cells):
        ys = (np.arange(shape[0]) - (shape[0] - 1) / 2) / max(target_cells[0] / 2, 0.5)
        xs = (np.arange(shape[1]) - (shape[1] - 1) / 2) / max(target_cells[1] / 2, 0.5)
        p = self.params.power
        w = self.params.minimum + (self.params.edge - self.params.minimum) * (
            np.abs(ys)[:, None] ** p + np.abs(xs)[None, :] ** p)
        with np.errstate(over="ignore"):  # w² beyond float32 far from the target: inf, i.e. h = 0 there
            return (w**2).astype(np.float32)


class Crop(SpatialRegularizer):
    """BACF: h is zero outside the target box (cropping matrix P) and λ‖h‖² inside."""

    name = "crop"

    @dataclasses.dataclass(frozen=True)
    class Params:
        lam: float = param(0.01, "λ: ridge weight on the filter inside the box", ge=0, le=MAX_WEIGHT**2)  # λ is w²
        placement: str = param("centred", "where an odd box sits in an even patch: 'centred' or 'authors' "
                               "(BACF's get_subwindow_no_window, a cell lower and to the right)", choices=PLACEMENTS)

    def weights_squared(self, shape, target_cells):
        return np.where(target_mask(shape, target_cells, self.params.placement), self.params.lam,
                        np.inf).astype(np.float32)


class Temporal(TemporalRegularizer):
    """θ/2 ‖h - h_prev‖² of Eq. (1) (STRCF's temporal regularization)."""

    name = "temporal"

    @dataclasses.dataclass(frozen=True)
    class Params:
        theta: float = param(15.0, "θ: weight of the distance to the previous frame's filter", ge=0, le=MAX_THETA)

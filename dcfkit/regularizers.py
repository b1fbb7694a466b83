"""Regularizers of the filter: spatial (the window w of Eqs. 1, 2, 10) and temporal (θ).

A spatial regularizer returns w² over the filter grid, (H, W) float32 in the centred layout
of the image patch (the target in the middle). The solver's h-step (Eq. 10) uses it as
h = γK (v + z) / (w² + γK); ``inf`` entries force h to zero there, which is BACF's
cropping matrix P (h = P^T P h). The temporal regularizer contributes θ‖h - h_prev‖²
(Eq. 1); its θ is 0 on the first frame (Remark 1).
"""
from __future__ import annotations

import dataclasses

import numpy as np

from .params import param
from .registry import Component, Contract


PLACEMENTS = ("centred", "authors")


def target_mask(shape: tuple[int, int], target_cells: tuple[float, float], placement: str = "centred") -> np.ndarray:
    """Boolean (H, W): the target-sized box (its size in cells, floored) in the middle of the patch.

    'centred': centred on the patch centre (size - 1) / 2, the lower of two middles when the
    box cannot be; 'authors': STRCF's and DR²Track's init_regwindow, which starts the box at
    1-based floor((n+1)/2) + mod(n+1, 2) - floor(r/2), and BACF's crop (floor(n/2) + 1 -
    floor(r/2)), the same cells: one lower than 'centred' when the patch has an even and the
    box an odd number of cells."""
    mask = np.zeros(shape, dtype=bool)
    spans = []
    for size, extent in zip(shape, target_cells):
        extent = int(min(max(np.floor(extent), 1), size))
        if placement == "authors":
            start = (size + 1) // 2 + (size + 1) % 2 - 1 - extent // 2
        else:
            start = (size - extent) // 2
        spans.append(slice(start, start + extent))
    mask[spans[0], spans[1]] = True
    return mask


MAX_WEIGHT = 1e10  # of w: w² (and a crop's λ, up to MAX_WEIGHT²) stays far inside float32
MAX_THETA = 1e10  # θ: the solver adds it to its penalty γ and multiplies last frame's filter by it
MAX_POWER = 10.0  # smooth's exponent: the window's float64 distances to it stay finite


class SpatialRegularizer(Component):
    """The spatial weight w of Eqs. (1), (2), (10) (``regularizers.spatial``). The tracker calls
    ``weights_squared`` once per ``init`` (a new target) and gives the result to the solver."""

    kind = "regularizer"
    role = "spatial"
    contract = Contract(required={"weights_squared": ("shape", "target_cells")})

    def weights_squared(self, shape: tuple[int, int], target_cells: tuple[float, float]) -> np.ndarray:
        """w² over the (H, W) filter grid, centred layout: (H, W) float32, >= 0, ``inf`` where h must be 0."""
        raise NotImplementedError


class TemporalRegularizer(Component):
    """The temporal term θ/2 ‖h - h_prev‖² of Eq. (1) (``regularizers.temporal``): it has no
    methods; the tracker reads ``params.theta`` every training frame and passes it to the solver."""

    kind = "regularizer"
    role = "temporal"
    contract = Contract(params={"theta": (float, 0.0, MAX_THETA)})


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


BUILTIN = (BoxWindow, SmoothWindow, Crop, Temporal)

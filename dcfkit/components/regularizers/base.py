"""The regularizers' contracts (spatial: the window w of Eqs. 1, 2, 10; temporal: θ) and the
target box they share."""
from __future__ import annotations

import numpy as np

from dcfkit.components.base import Component, Contract
from dcfkit.contracts import array, scalar

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


class SpatialRegularizer(Component, declares="regularizer"):
    """The spatial weight w of Eqs. (1), (2), (10) (``regularizers.spatial``). The tracker calls
    ``reset()`` and ``weights_squared`` once per ``init`` (a new target), then ``adapt`` after
    every detection, and gives the w² in force to the solver. A fixed window (all the built-ins
    but AutoTrack's) keeps w² as it is; an adaptive one keeps its state, explicit and small."""

    role = "spatial"
    contract = Contract(required={"weights_squared": ("shape", "target_cells")},
                        optional={"reset": (), "adapt": ("w2", "detection")},
                        returns={"weights_squared": array(lambda args, r: tuple(args[0]), kinds="iuf", finite=False,
                                                          nonnegative=True),
                                 "adapt": array(lambda args, r: args[0].shape, kinds="iuf", finite=False,
                                                nonnegative=True)})

    def weights_squared(self, shape: tuple[int, int], target_cells: tuple[float, float]) -> np.ndarray:
        """w² over the (H, W) filter grid, centred layout: (H, W) float32, >= 0, ``inf`` where h must be 0."""
        raise NotImplementedError

    def reset(self) -> None:
        """Forget what earlier targets left (the fixed windows keep nothing)."""

    def adapt(self, w2: np.ndarray, detection) -> np.ndarray:
        """The w² for this frame's training, given the one in force and the frame's
        :class:`dcfkit.components.labels.base.Detection`: (H, W) float32 as ``weights_squared``'s. Fixed: ``w2``."""
        return w2


class TemporalRegularizer(Component, declares="regularizer"):
    """The temporal term θ/2 ‖h - h_prev‖² of Eq. (1) (``regularizers.temporal``). The tracker
    calls ``reset()`` at every ``init`` and ``weight(detection)`` every training frame
    (``detection`` None on the first), and passes the θ it returns to the solver. The fixed
    term returns ``params.theta``; an adaptive one may return ``inf``, the limit in which the
    filter cannot change: the tracker then keeps the last filter and does not train."""

    role = "temporal"
    contract = Contract(params={"theta": (float, 0.0, MAX_THETA)},
                        optional={"reset": (), "weight": ("detection",)},
                        returns={"weight": scalar(0.0, MAX_THETA, inf=True)})

    def reset(self) -> None:
        """Forget what earlier targets left (the fixed term keeps nothing)."""

    def weight(self, detection) -> float:
        """θ for this frame's training: in [0, MAX_THETA], or ``inf`` to keep the last filter."""
        return self.params.theta

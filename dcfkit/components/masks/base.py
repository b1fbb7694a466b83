"""The mask kind: a learned spatial mask on the filter grid (CSR-DCF's spatial reliability map)."""
from __future__ import annotations

import numpy as np

from dcfkit.components.base import Component, Contract
from dcfkit.contracts import array


class Mask(Component, declares="mask"):
    """Where the filter may be non-zero, learnt from each training frame (``mask:`` in a config;
    none by default). The tracker calls ``reset()`` at every ``init``, then ``make`` once per
    training frame, before the solver trains; the filter is held at zero where the mask is
    False (w² = ``inf`` there, BACF's crop P learnt per frame), so it takes a solver with a
    spatial term. State between frames (a colour model) lives in the instance."""

    contract = Contract(required={"make": ("image", "centre", "target", "region", "shape")},
                        optional={"reset": ()},
                        returns={"make": array(lambda args, m: tuple(args[4]), kinds="b")})

    def make(self, image: np.ndarray, centre: np.ndarray, target: np.ndarray, region: np.ndarray,
             shape: tuple[int, int]) -> np.ndarray:
        """The training frame (H, W, 3) uint8 BGR or (H, W) gray; the target's ``centre`` (y, x)
        and size ``target`` (h, w) in image pixels this frame; the ``region`` (h, w) image pixels
        the filter grid covers, centred on ``centre`` -> (``shape``) bool, the target in the
        middle: True where the filter may be non-zero."""
        raise NotImplementedError

    def reset(self) -> None:
        """Forget what earlier targets left."""

"""The feature kind: a map of channels per cell of a patch."""
from __future__ import annotations

import math

import cv2
import numpy as np

from dcfkit.components.base import Component, Contract
from dcfkit.contracts import array, scalar


def cell_average(x: np.ndarray, cell_size: int) -> np.ndarray:
    """Average (H, W[, C]) over non-overlapping whole cells -> (H // cell, W // cell[, C]) float32."""
    if cell_size == 1:
        return x.astype(np.float32, copy=False)
    h, w = x.shape[0] // cell_size, x.shape[1] // cell_size
    whole = x[:h * cell_size, :w * cell_size].astype(np.float32, copy=False)
    return cv2.resize(whole, (w, h), interpolation=cv2.INTER_AREA)


MAX_FEATURE_VALUE = 1e6  # the built-ins' maps stay within ±1; beyond this the solvers' float32 sums overflow


def _map_shape(args, feature) -> tuple[int, int, int]:
    """(C, H // cell_size, W // cell_size) of ``extract(patch, cell_size)``."""
    patch, cell_size = args
    return feature.channels(), patch.shape[0] // cell_size, patch.shape[1] // cell_size


class Feature(Component, declares="feature"):
    """Maps search patches to feature maps. The tracker calls ``reset()`` at every ``init``
    (a new target), then ``extract`` on each patch; ``channels()`` whenever it checks a map."""

    contract = Contract(required={"channels": (), "extract": ("patch", "cell_size")}, optional={"reset": ()},
                        returns={"channels": scalar(1, math.inf, integer=True),
                                 "extract": array(_map_shape, largest=MAX_FEATURE_VALUE)})

    def channels(self) -> int:
        """C, the number of channels ``extract`` returns (at least 1)."""
        raise NotImplementedError

    def extract(self, patch: np.ndarray, cell_size: int) -> np.ndarray:
        """(H, W, 3) uint8 BGR, sides multiples of ``cell_size`` (CSR-DCF's template: up to a cell more,
        left out) -> (C, H // cell, W // cell) float32, finite."""
        raise NotImplementedError

    def reset(self) -> None:
        """Forget what earlier targets left (the built-in features keep nothing)."""


def extract_stack(features, patch: np.ndarray, cell_size: int) -> np.ndarray:
    """Concatenate every feature's map of ``patch`` (gray patches are treated as BGR)."""
    if patch.ndim == 2:
        patch = cv2.cvtColor(patch, cv2.COLOR_GRAY2BGR)
    maps = [f.extract(patch, cell_size) for f in features]
    return (maps[0] if len(maps) == 1 else np.concatenate(maps, axis=0)).astype(np.float32, copy=False)

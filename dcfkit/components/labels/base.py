"""The label kind: a :class:`Label` makes each frame's desired response from the last detection."""
from __future__ import annotations

import dataclasses

import numpy as np

from dcfkit.components.base import Component, Contract
from dcfkit.contracts import array, pair, within_grid
from dcfkit.numerics.response import wrap


@dataclasses.dataclass
class Detection:
    """What the last detection saw, in feature cells of the training grid.

    response: (H, W) float32 response at the chosen scale (circular layout, as computed);
    peak: (row, col) integer index of its maximum; target_cells: (h, w) target size in cells;
    offset: the sub-cell peak as a signed (dy, dx) offset in cells (None: the grid peak);
    score: the reliability component's score (≥ 1: reliable; None: the config has none).
    """

    response: np.ndarray
    peak: tuple[int, int]
    target_cells: tuple[float, float]
    offset: tuple[float, float] | None = None
    score: float | None = None


def gaussian_label(shape: tuple[int, int], sigma: float) -> np.ndarray:
    """g of Eq. (1): exp(-(dy² + dx²) / 2σ²) over circular offsets, peak at (0, 0)."""
    dy = wrap(np.arange(shape[0]), shape[0])[:, None]
    dx = wrap(np.arange(shape[1]), shape[1])[None, :]
    with np.errstate(over="ignore"):  # a σ so small that σ² underflows: a delta label, not NaN
        return np.exp(-0.5 * (dy**2 + dx**2) / max(sigma**2, np.finfo(float).tiny)).astype(np.float32)


class Label(Component, declares="label"):
    """Makes each frame's training label. The tracker calls ``reset()`` at every ``init`` (a new
    target), then ``make`` once per training frame: ``detection`` None on the first."""

    contract = Contract(required={"make": ("g", "detection")}, optional={"reset": ()},
                        returns={"make": pair(array(lambda args, label: args[0].shape), within_grid,
                                              ("y", "offsets"))})

    def make(self, g: np.ndarray, detection: Detection | None) -> tuple[np.ndarray, np.ndarray]:
        """Training label from the base Gaussian ``g`` and the last detection.

        Returns (y, distractors): y (H, W) float32; distractors (N, 2) int signed (dy, dx)
        offsets in cells from the target of the repressed peaks (empty for fixed labels).
        """
        raise NotImplementedError

    def reset(self) -> None:
        """Forget what earlier targets left (the built-in labels keep nothing)."""

"""Label generators: the regression target y of the training step.

``gaussian`` is the fixed g of Eq. (1). ``distractor_repressed`` is Eq. (3): the top-N local
maxima of the last response map outside the target area ([η]: shifted so the response
peak sits on the label's peak) are repressed with strength μ. Two variants:

* ``multiplicative`` — the paper's g ⊙ d, d = 1 - μ P^T Δ(R[η]). Since g is nearly zero at
  distractors far from the target, it changes the label very little.
* ``subtractive`` — the authors' public code: y = g - μ R̃(p) at each distractor p (R̃ = R /
  max R); their code overwrites y(p) with -μ R̃(p), which equals this where g(p) ≈ 0.

Labels are (H, W) float32 maps with the target peak at index (0, 0) (circular layout).
"""
from __future__ import annotations

import dataclasses

import numpy as np

from .params import param
from .registry import Component
from .response import local_maxima, wrap


@dataclasses.dataclass
class Detection:
    """What the last detection saw, in feature cells of the training grid.

    response: (H, W) float32 response at the chosen scale (circular layout, as computed);
    peak: (row, col) integer index of its maximum; target_cells: (h, w) target size in cells.
    """

    response: np.ndarray
    peak: tuple[int, int]
    target_cells: tuple[float, float]


def gaussian_label(shape: tuple[int, int], sigma: float) -> np.ndarray:
    """g of Eq. (1): exp(-(dy² + dx²) / 2σ²) over circular offsets, peak at (0, 0)."""
    dy = wrap(np.arange(shape[0]), shape[0])[:, None]
    dx = wrap(np.arange(shape[1]), shape[1])[None, :]
    with np.errstate(over="ignore"):  # a σ so small that σ² underflows: a delta label, not NaN
        return np.exp(-0.5 * (dy**2 + dx**2) / max(sigma**2, np.finfo(float).tiny)).astype(np.float32)


class Label(Component):
    kind = "label"

    def make(self, g: np.ndarray, detection: Detection | None) -> tuple[np.ndarray, np.ndarray]:
        """Training label from the base Gaussian ``g`` and the last detection.

        Returns (y, distractors): y (H, W) float32; distractors (N, 2) int signed (dy, dx)
        offsets in cells from the target of the repressed peaks (empty for fixed labels).
        """
        raise NotImplementedError


class Gaussian(Label):
    """The fixed Gaussian label of STRCF/BACF (Eq. 1)."""

    name = "gaussian"

    def make(self, g, detection):
        return g, np.zeros((0, 2), dtype=int)


class DistractorRepressed(Label):
    """DR²Track's dynamic label (Eq. 3): repress the top-N background local maxima."""

    name = "distractor_repressed"

    @dataclasses.dataclass(frozen=True)
    class Params:
        top_n: int = param(30, "N: how many of the highest background local maxima are repressed")
        mu: float = param(0.25, "μ: repression strength")
        variant: str = param("subtractive", "'subtractive' (authors' code) or 'multiplicative' (paper's g⊙d)",
                             choices=("subtractive", "multiplicative"))
        neighbourhood: int = param(3, "side of the window in which a local maximum is the largest")
        exclusion: float = param(1.0, "P^T: ignore maxima within this many target sizes of the peak")

        def validate(self):
            if self.top_n < 0:
                return "top_n must be >= 0"
            if self.mu < 0:
                return "mu must be >= 0"
            if self.neighbourhood < 3 or self.neighbourhood % 2 == 0:
                return "neighbourhood must be an odd number >= 3"
            if self.exclusion < 0:
                return "exclusion must be >= 0"

    def distractors(self, detection: Detection) -> tuple[np.ndarray, np.ndarray]:
        """Δ and P^T of Eq. (3): (N, 2) signed offsets from the peak, and their normalised values."""
        r = detection.response
        top = float(r[detection.peak])
        if not np.isfinite(top) or top <= 0 or self.params.top_n == 0:
            return np.zeros((0, 2), dtype=int), np.zeros(0, np.float32)
        rows, cols = local_maxima(r, self.params.neighbourhood)
        h, w = r.shape
        dy = wrap(rows - detection.peak[0], h)
        dx = wrap(cols - detection.peak[1], w)
        half_h = 0.5 * self.params.exclusion * detection.target_cells[0]
        half_w = 0.5 * self.params.exclusion * detection.target_cells[1]
        outside = (np.abs(dy) > half_h) | (np.abs(dx) > half_w)
        values = r[rows, cols] / top
        keep = outside & (values > 0)
        offsets = np.stack([dy[keep], dx[keep]], axis=1)[: self.params.top_n]
        return offsets.astype(int), values[keep][: self.params.top_n].astype(np.float32)

    def make(self, g, detection):
        if detection is None:
            return g, np.zeros((0, 2), dtype=int)
        offsets, values = self.distractors(detection)
        y = g.copy()
        idx = (offsets[:, 0] % g.shape[0], offsets[:, 1] % g.shape[1])
        if self.params.variant == "subtractive":
            y[idx] -= self.params.mu * values
        else:
            y[idx] *= 1.0 - self.params.mu * values
        return y, offsets


BUILTIN = (Gaussian, DistractorRepressed)

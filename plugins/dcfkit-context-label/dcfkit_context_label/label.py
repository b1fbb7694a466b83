"""The context-aware label: Mueller et al., "Context-Aware Correlation Filter Tracking", CVPR 2017.

Mueller, Smith and Ghanem sample k context patches a_i around the target (up, down, left,
right) and add them to the ridge regression with a zero target:

    min_w ‖A_0 w − y‖² + λ1 ‖w‖² + λ2 Σ_i ‖A_i w‖²

Adaptation to dcfkit's label interface. dcfkit's solvers learn from one sample and one
label; the training sample (about five target sizes wide) already contains the context
patches, as circular shifts of the sample, and the desired response to the shift by p is the
label value y(p). So instead of adding rows A_i w ≈ 0, the label is lowered where the context
patches sit:

    y(p) = g(p) − strength · c(p)    at the k context offsets p, y = g elsewhere,

with c(p) = 1 (``use_response: false``: a fixed repression, whether or not a distractor is
there) or c(p) = max(R(p) / R(peak), 0), the last response normalised by its peak
(``use_response: true``). ``strength`` plays the part of λ2. Unlike DR²Track's
``distractor_repressed`` label, the places are fixed, not detected.
"""
from __future__ import annotations

import dataclasses

import numpy as np

from dcfkit.components.labels import Detection, Label
from dcfkit.params import param


class ContextAware(Label):
    """Context-aware label (Mueller et al., CVPR 2017): g minus a dip at k fixed context patches."""

    name = "context_aware"

    @dataclasses.dataclass(frozen=True)
    class Params:
        strength: float = param(0.1, "how much the label is lowered at each context patch (λ2's part)")
        distance: float = param(1.0, "distance of the context patches from the target, in target sizes")
        diagonals: bool = param(False, "also the 4 diagonal patches (k = 8 instead of 4)")
        use_response: bool = param(False, "scale the repression by the last response there (R / R(peak))")

        def validate(self):
            if self.strength < 0:
                return "strength must be >= 0"
            if self.distance <= 0:
                return "distance must be > 0"

    def context_offsets(self, target_cells: tuple[float, float]) -> np.ndarray:
        """(k, 2) int signed (dy, dx) offsets in cells: up, down, left, right, then the diagonals."""
        dy = round(self.params.distance * target_cells[0])
        dx = round(self.params.distance * target_cells[1])
        offsets = [(-dy, 0), (dy, 0), (0, -dx), (0, dx)]
        if self.params.diagonals:
            offsets += [(-dy, -dx), (-dy, dx), (dy, -dx), (dy, dx)]
        return np.array(offsets, dtype=int)

    def make(self, g: np.ndarray, detection: Detection | None) -> tuple[np.ndarray, np.ndarray]:
        """y (H, W) float32 with the target peak at (0, 0), and the repressed (N, 2) int offsets.

        Frame 1 (``detection`` is None) trains on g: the target size in cells comes with the
        first detection. Offsets that do not fit in the sample, or round to the target itself,
        are skipped.
        """
        none = np.zeros((0, 2), dtype=int)
        if detection is None:
            return g, none
        h, w = g.shape
        offsets = self.context_offsets(detection.target_cells)
        fits = (np.abs(offsets[:, 0]) <= (h - 1) // 2) & (np.abs(offsets[:, 1]) <= (w - 1) // 2)
        offsets = offsets[fits & offsets.any(axis=1)]
        offsets = offsets[np.sort(np.unique(offsets, axis=0, return_index=True)[1])]  # drop repeats
        if self.params.use_response:
            r = detection.response
            top = float(r[detection.peak])
            if not np.isfinite(top) or top <= 0:
                return g, none
            at = ((detection.peak[0] + offsets[:, 0]) % h, (detection.peak[1] + offsets[:, 1]) % w)
            weight = np.maximum(r[at] / top, 0.0)
            offsets, weight = offsets[weight > 0], weight[weight > 0]
        else:
            weight = np.ones(len(offsets))
        y = g.copy()
        y[offsets[:, 0] % h, offsets[:, 1] % w] -= self.params.strength * weight
        return y, offsets

"""Label generators: the regression target y of the training step.

``gaussian`` is the fixed g of Eq. (1). ``distractor_repressed`` is Eq. (3): the top-N local
maxima of the last response map outside the target area ([η]: shifted so the response
peak sits on the label's peak) are repressed with strength μ. Two variants:

* ``multiplicative`` — the paper's g ⊙ d, d = 1 - μ P^T Δ(R[η]). Since g is nearly zero at
  distractors far from the target, it changes the label very little.
* ``subtractive`` — y = g - μ R̃(p) at each distractor p (R̃ = R / max R);
* ``overwrite`` — the authors' public code: y(p) = -μ R̃(p), which equals ``subtractive``
  where g(p) ≈ 0.

With ``mirrored`` the label is turned by 180° about the target (y(-p)), which is what the
authors' code learns: its solver takes ŷ where the correlation R = F⁻¹(Σ conj(ĥ) ẑ) needs
conj(ŷ), the same for the symmetric Gaussian but not for a repressed label.

Which maxima are distractors (``selection``): ``local_maxima`` takes the maxima of 3x3
neighbourhoods of the circular map outside the target-sized area around the grid peak;
``authors`` follows DR²Track's tracker.m (see :func:`authors_distractors`).

Labels are (H, W) float32 maps with the target peak at index (0, 0) (circular layout).
"""
from __future__ import annotations

import dataclasses
import itertools

import numpy as np

from dcfkit.components.labels.base import Detection, Label
from dcfkit.components.regularizers import target_mask
from dcfkit.numerics.patches import round_half_away
from dcfkit.numerics.maxima import components, local_maxima, regional_maxima
from dcfkit.numerics.response import wrap
from dcfkit.params import param

MAX_MU = 1e6


MAX_NEIGHBOURHOOD = 101


class DistractorRepressed(Label):
    """DR²Track's dynamic label (Eq. 3): repress the top-N background local maxima."""

    name = "distractor_repressed"

    @dataclasses.dataclass(frozen=True)
    class Params:
        top_n: int = param(30, "N: how many of the highest background local maxima are repressed", ge=0)
        # y = g - μR̃ is float32, and so are the filter and response it trains
        mu: float = param(0.25, "μ: repression strength", ge=0, le=MAX_MU)
        variant: str = param("subtractive", "'subtractive' g - μR̃, 'overwrite' -μR̃ (the authors' code) or "
                             "'multiplicative' (the paper's g⊙d)",
                             choices=("subtractive", "overwrite", "multiplicative"))
        selection: str = param("local_maxima", "'local_maxima' (3x3 maxima of the circular map outside the target "
                               "area) or 'authors' (DR²Track's code: regional maxima, its exclusion box, at most one "
                               "maximum means none)", choices=("local_maxima", "authors"))
        mirrored: bool = param(False, "repress each distractor's mirror image through the target instead (the "
                               "authors' solver reads ŷ where correlation needs its conjugate, so their filter "
                               "learns the label turned by 180°)")
        # at most MAX_NEIGHBOURHOOD: the map is padded by half of it on every side
        neighbourhood: int = param(3, "side of the window in which a local maximum is the largest (odd)",
                                   ge=3, le=MAX_NEIGHBOURHOOD)
        exclusion: float = param(1.0, "P^T: ignore maxima within this many target sizes of the peak", ge=0)

        def validate(self):
            """neighbourhood an odd number."""
            if self.neighbourhood % 2 == 0:
                return "neighbourhood must be an odd number >= 3"

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
        p = self.params
        if p.selection == "authors":
            offsets, values = authors_distractors(detection, p.top_n)
        else:
            offsets, values = self.distractors(detection)
        y = g.copy()
        for (dy, dx), value in zip(offsets, values):  # offsets may repeat (authors): apply each once, in order
            idx = (dy % g.shape[0], dx % g.shape[1])
            if p.variant == "subtractive":
                y[idx] -= p.mu * value
            elif p.variant == "overwrite":
                y[idx] = -p.mu * value
            else:
                y[idx] *= 1.0 - p.mu * value
        if p.mirrored:  # y(-p): circular indices negated
            y = np.roll(y[::-1, ::-1], 1, axis=(0, 1))
            offsets = -offsets
        return y, offsets


def authors_distractors(detection: Detection, top_n: int) -> tuple[np.ndarray, np.ndarray]:
    """Distractors as DR²Track's tracker.m picks them: (N, 2) (dy, dx) offsets from the target
    and their values R̃, highest first; an offset appears once per value that matched it.

    R̃ = R / max R is centred (circshift by floor(size/2)) and moved by the rounded sub-cell
    peak, so the peak sits at the middle. The values are those of its regional maxima outside
    the target (:func:`_strongest_maxima`). Each of them is looked up among the pixels outside
    the target box (:func:`~dcfkit.components.regularizers.target_mask`, 'authors'): every pixel holding
    exactly that value is a distractor (MATLAB's ``y(row, col)``: rows x columns of the matches).
    """
    r = detection.response
    h, w = r.shape
    top = r.max()
    if not np.isfinite(top) or top <= 0 or top_n <= 0:
        return np.zeros((0, 2), dtype=int), np.zeros(0, np.float32)
    dy, dx = detection.offset if detection.offset is not None else (0.0, 0.0)
    shift = (h // 2 - int(round_half_away(dy)), w // 2 - int(round_half_away(dx)))
    rn = np.roll(r / top, shift, axis=(0, 1))
    wanted = _strongest_maxima(rn, detection.target_cells, top_n)
    flat = rn.ravel()
    where = np.flatnonzero(~target_mask((h, w), detection.target_cells, "authors").ravel() & (flat >= wanted.min()))
    where = where[np.argsort(flat[where])]  # the pixels outside that may match, by value
    values = flat[where]
    offsets, kept = [], []
    for value, start, stop in zip(wanted, values.searchsorted(wanted, "left"), values.searchsorted(wanted, "right")):
        found = where[start:stop]
        for row, col in itertools.product(np.unique(found // w), np.unique(found % w)) if len(found) > 1 else \
                ((p // w, p % w) for p in found.tolist()):
            offsets.append((row - h // 2, col - w // 2))
            kept.append(value)
    if not offsets:
        return np.zeros((0, 2), dtype=int), np.zeros(0, np.float32)
    return np.array(offsets, dtype=int), np.array(kept, np.float32)


def _strongest_maxima(rn: np.ndarray, target_cells, top_n: int) -> np.ndarray:
    """The ``top_n`` highest values of the regional maxima of the centred map ``rn`` outside a
    box of floor(size/2 ± target/2) cells (1-based) around the middle, one per connected
    component (its first pixel in column-major order, MATLAB's PixelIdxList{i}(1)). With at
    most one component, tracker.m's stand-in list [max, 0], which the lookup finds outside
    the target box only if the peak moved there."""
    h, w = rn.shape
    maxima = regional_maxima(rn)
    reg = np.floor(target_cells)
    rows = slice(max(int(np.floor(h / 2 - reg[0] / 2)) - 1, 0), int(np.floor(h / 2 + reg[0] / 2)))
    cols = slice(max(int(np.floor(w / 2 - reg[1] / 2)) - 1, 0), int(np.floor(w / 2 + reg[1] / 2)))
    maxima[rows, cols] = False
    labels, count = components(maxima)
    if count <= 1:
        return np.array([rn.max(), 0], rn.dtype)[:top_n]
    cols, rows = np.nonzero(labels.T)  # column-major
    _, first = np.unique(labels[rows, cols], return_index=True)
    first = np.sort(first)  # in the order MATLAB meets them
    values = rn[rows[first], cols[first]]
    return values[np.argsort(-values, kind="stable")][:top_n]

"""CSR-DCF's spatial reliability map (Lukežič et al., CVPR 2017, Sec. 3.1), as the authors'
``create_csr_tracker.m`` and ``track_csr_tracker.m`` learn it each frame."""
from __future__ import annotations

import dataclasses

import cv2
import numpy as np

from dcfkit.components.base import Target, running_average
from dcfkit.components.masks.base import Mask
from dcfkit.components.masks.segmentation import background_histogram, foreground_histogram, hsv255, on_grid, \
    posterior
from dcfkit.numerics.patches import round_half_away
from dcfkit.params import param

GRAY_SUM = 10  # create_csr_tracker: a frame whose channels differ from their mean by less in sum is gray


def box_mask(shape: tuple[int, int], target_cells: tuple[float, float]) -> np.ndarray:
    """The authors' fallback ``target_dummy_mask``: floor(target cells) + 1 cells from 1-based
    ⌊(n - target) / 2⌋ (one cell above and left of the middle), (H, W) bool."""
    mask = np.zeros(shape, bool)
    spans = []
    for n, extent in zip(shape, target_cells):
        extent = int(np.floor(extent))
        start = max(int(np.floor((n - extent) / 2)) - 1, 0)
        spans.append(slice(start, start + extent + 1))
    mask[spans[0], spans[1]] = True
    return mask


def disk(radius: int) -> np.ndarray:
    """MATLAB's ``strel('disk', r)`` for the small radii used: the cells within r (uint8)."""
    r = np.arange(-radius, radius + 1)
    return (r[:, None] ** 2 + r[None, :] ** 2 <= radius**2).astype(np.uint8)


class CSRSegmentation(Mask):
    """CSR-DCF's spatial reliability: colour histograms of target and surroundings, a spatial
    prior, an MRF-smoothed posterior, binarised on the filter grid (Lukežič et al. 2017)."""

    name = "csr_segmentation"

    @dataclasses.dataclass(frozen=True)
    class Params:
        n_bins: int = param(16, "histogram bins per colour channel", ge=2, le=64)
        colour_space: str = param("hsv", "'hsv' (MATLAB's rgb2hsv on 0..255) or 'bgr'", choices=("hsv", "bgr"))
        learning_rate: float = param(0.04, "weight of each frame's histograms in the colour model (hist_lr)",
                                     gt=0, le=1)
        threshold: float = param(0.5, "the posterior, over its maximum, above which a pixel is the target",
                                 ge=0, lt=1)
        min_area: float = param(0.05, "a mask smaller than this fraction of the box mask is replaced by the box "
                                "mask (mask_normal)", ge=0, le=1)
        dilation: int = param(1, "radius (cells) of the disk the mask is dilated by (0: none)", ge=0, le=10)
        unseen_colour: str = param("neutral", "a pixel whose colour neither histogram holds: 'neutral' posterior "
                                   "0.5, or 'discard' the frame's segmentation, which takes the box mask (the "
                                   "authors': their 0/0 is a NaN that their MRF spreads over the whole patch)",
                                   choices=("neutral", "discard"))
        histogram_box: str = param("previous_scale", "the box the histograms are taken from: 'previous_scale' "
                                   "the new centre with the scale before this frame's scale update (the "
                                   "authors' region), or 'current'", choices=("previous_scale", "current"))

    def reset(self) -> None:
        self.hist_fg = self.hist_bg = self.last_target = None
        self.colour = True
        self.box = None

    def start(self, target: Target) -> None:
        self.box = box_mask(target.filter_size, target.target_cells)

    def make(self, image, centre, target, region, shape):
        first = self.hist_fg is None and self.last_target is None
        if first:
            self.colour = image.ndim == 3 and not _gray(image)
        box = self.box if self.box is not None and self.box.shape == tuple(shape) else \
            box_mask(shape, (1.0, 1.0))
        if not self.colour:  # the authors: no segmentation on a gray sequence
            self.last_target = np.asarray(target, float)
            return box.copy()
        hist_size = target if first or self.params.histogram_box == "current" else self.last_target
        self.last_target = np.asarray(target, float)
        self._learn_histograms(image, centre, np.asarray(hist_size, float))
        mask = self._segment(image, centre, np.asarray(target, float), np.floor(region).astype(int), tuple(shape),
                             first)
        if mask is None or mask.sum() < box.sum() * self.params.min_area:
            return box.copy()
        if self.params.dilation:
            mask = cv2.dilate(mask.astype(np.uint8), disk(self.params.dilation)).astype(bool)
        return mask

    def _learn_histograms(self, image, centre, size) -> None:
        """The target box (the authors' round([c - s/2, c + s/2]) - 1, c 1-based) and the ring
        of half its size around it, their histograms averaged into the colour model."""
        height, width = image.shape[:2]
        c = np.asarray(centre, float) + 1.5  # the authors' 1-based centre (dcfkit's is x + (w-1)/2)
        (y1, x1), (y2, x2) = (round_half_away(c - size / 2) - 1).astype(int), (round_half_away(c + size / 2)
                                                                                - 1).astype(int)
        x1, x2 = (min(max(v, 0), width - 1) for v in (x1, x2))
        y1, y2 = (min(max(v, 0), height - 1) for v in (y1, y2))
        dx, dy = (x2 - x1 + 1) // 2, (y2 - y1 + 1) // 2
        ox1, ox2 = max(x1 - dx, 0), min(x2 + dx + 1, width - 1)
        oy1, oy2 = max(y1 - dy, 0), min(y2 + dy + 1, height - 1)
        pixels = self._colours(image[oy1:max(oy2, y2) + 1, ox1:max(ox2, x2) + 1])
        inner = (x1 - ox1, y1 - oy1, x2 - ox1, y2 - oy1)
        fg = foreground_histogram(pixels, inner, self.params.n_bins)
        bg = background_histogram(pixels, inner, (0, 0, ox2 - ox1, oy2 - oy1), self.params.n_bins)
        rate = self.params.learning_rate
        self.hist_fg = running_average(self.hist_fg, fg, rate)
        self.hist_bg = running_average(self.hist_bg, bg, rate)

    def _segment(self, image, centre, target, size, grid, first) -> np.ndarray:
        """The binarised foreground posterior over the region's whole pixels around the authors' ⌊c⌋
        (get_patch), zero outside the image (and the first frame's box), on the filter ``grid``; None
        if the posterior was discarded."""
        size = np.maximum(size, 2)
        # the authors' 1-based floor(c) + (1:h) - floor(h/2), their c being dcfkit's centre + 1.5
        firsts = [int(np.floor(np.asarray(centre, float)[a] + 0.5)) + 1 - size[a] // 2 for a in range(2)]
        rows, cols = (np.clip(f + np.arange(n), 0, image.shape[a] - 1) for a, (f, n) in enumerate(zip(firsts, size)))

        def pixels(r, c):  # the patch's colours at its rows r x columns c, edges replicated
            return self._colours(image[np.ix_(rows[r], cols[c])])

        size = (int(size[0]), int(size[1]))
        q = posterior(pixels, size, self.hist_fg, self.hist_bg, target, self.params.n_bins, self.params.unseen_colour)
        if q is None:
            return None
        # the authors' valid_pixels_mask (the patch on the image), and on the first frame init_mask_padded
        keep = [(max(-f, 0), min(max(image.shape[a] - f, 0), n)) for a, (f, n) in enumerate(zip(firsts, size))]
        if first:  # ones over the given box from 1-based floor(n/2 - b/2)
            for a, (n, b) in enumerate(zip(size, round_half_away(target).astype(int))):
                start = max(int(np.floor(n / 2 - b / 2)) - 1, 0)
                keep[a] = (max(keep[a][0], start), min(keep[a][1], start + int(b)))
        return on_grid(q, size, tuple(keep), grid, self.params.threshold)

    def _colours(self, bgr: np.ndarray) -> np.ndarray:
        return hsv255(bgr) if self.params.colour_space == "hsv" else bgr


def _gray(image: np.ndarray) -> bool:
    """create_csr_tracker's test: the channels' summed deviation from their mean below 10."""
    deviation = image.astype(np.float32) - image.mean(axis=2, dtype=np.float32, keepdims=True)
    return float(np.abs(deviation).sum()) < GRAY_SUM

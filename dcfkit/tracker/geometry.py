"""The sizes a tracker fixes at its first frame, and its cosine window."""
from __future__ import annotations

import dataclasses

import numpy as np

from dcfkit.config.tracker_params import TrackerParams
from dcfkit.numerics.patches import centre_size_to_box, round_half_away, sampler, whole_pixel_sampler


def hann2d(shape: tuple[int, int], interior: bool = True) -> np.ndarray:
    """Cosine window, (H, W) float32: without zero borders (hann(n + 2) trimmed: BACF, DR²Track)
    or, with ``interior=False``, hann(n) itself, zero on the border (STRCF)."""
    pad = 2 if interior else 0
    ends = slice(1, -1) if interior else slice(None)
    return np.outer(np.hanning(shape[0] + pad)[ends], np.hanning(shape[1] + pad)[ends]).astype(np.float32)


@dataclasses.dataclass
class Geometry:
    """Sizes fixed at init, in pixels at scale 1 unless stated (see STRCF's init_size)."""

    base_target: np.ndarray      # (h, w) target
    sample_size: np.ndarray      # (h, w) resampled search patch, a multiple of the cell size
    filter_size: tuple[int, int]  # (H, W) in cells
    target_cells: tuple[float, float]
    cell_size: int               # pixels per cell (tracker.cell_size, or smaller for a small target)
    # CSR-DCF's template ('padded_square'): its side in image pixels at the first scale, that scale,
    # and the whole pixels it is resized to, of which sample_size is the top-left corner; None:
    # sample_size is the region
    template: float | None = None
    template_scale: float | None = None
    resized: int | None = None

    def region(self, scale: float) -> np.ndarray:
        """The (h, w) image pixels the sample covers at ``scale`` (CSR-DCF's template: its side
        times their scale, exactly 1.0 at the first scale)."""
        if self.template is None:
            return self.sample_size * scale
        return np.full(2, self.template * (scale / self.template_scale))


def geometry(p: TrackerParams, target: np.ndarray, area_of: np.ndarray | None = None) -> tuple[Geometry, float]:
    """STRCF's init_size, in its arithmetic (a floor of a size decides a sample's pixels), with
    BACF's smaller cells for a target whose search area has too few of them. ``area_of``: the
    size the search area is computed from (default ``target``; DR²Track's code takes the
    annotation's size before its floor, ``tracker.init_area: given``)."""
    cell, low, high = p.cell_size, p.min_image_sample_size, p.max_image_sample_size
    if p.search_area_shape == "padded_square":
        return _padded_square(p, target)
    area = float(np.prod((target if area_of is None else area_of) * p.search_area_scale))
    if p.cell_selection_thresh > 0 and area / cell**2 < p.cell_selection_thresh * high / cell**2:
        smaller = min(cell, max(1, int(np.ceil(np.sqrt(area / (p.cell_selection_thresh * high / cell**2))))))
        low, high = low * (smaller / cell) ** 2, high * (smaller / cell) ** 2  # the same areas in cells
        cell = smaller
    scale = 1.0
    if area > high:
        scale = np.sqrt(area / high)
    elif area < low:
        scale = np.sqrt(area / low)
    base_target = target / scale
    region = (np.full(2, np.sqrt(np.prod(base_target * p.search_area_scale))) if p.search_area_shape == "square"
              else np.floor(base_target * p.search_area_scale))
    cells = np.maximum(round_half_away(region / cell), 4).astype(int)
    target_cells = tuple(float(v) for v in base_target / cell)
    geom = Geometry(base_target, cells * cell, (int(cells[0]), int(cells[1])), target_cells, cell)
    return geom, float(scale)


def _padded_square(p: TrackerParams, target: np.ndarray) -> tuple[Geometry, float]:
    """CSR-DCF's template (create_csr_tracker.m): a square of side the mean of floor(size +
    padding √(wh)), rescaled to at most ``max_image_sample_size`` (at least the smallest),
    floored, in whole cells (floored), with cells of min(cell_size, ceil(wh / cell_area))."""
    cell = p.cell_size
    if p.cell_area > 0:
        cell = min(cell, max(1, int(np.ceil(np.prod(target) / p.cell_area))))
    side = float(np.mean(np.floor(target + (p.search_area_scale - 1) * np.sqrt(np.prod(target)))))
    ratio = min(1.0, float(np.sqrt(p.max_image_sample_size / side**2)))
    ratio = max(ratio, float(np.sqrt(p.min_image_sample_size / side**2)))
    resized = int(np.floor(ratio * side))
    cells = max(resized // cell, 4)
    base_target = target * ratio
    geom = Geometry(base_target, np.array([cells * cell] * 2), (cells, cells),
                    tuple(float(v) for v in base_target / cell), cell, side, 1.0 / ratio, max(resized, cells * cell))
    return geom, 1.0 / ratio


def patch_sampler(p: TrackerParams, g: Geometry, shape, centre: np.ndarray, scale: float):
    """The search patch's sampler at ``centre`` and ``scale`` for images of ``shape``
    (``tracker.sampling``; an InputError if its copy would be over the image budget)."""
    if p.sampling != "whole_pixel":
        return sampler(shape, centre, g.sample_size * scale, g.sample_size)
    if g.template is not None:  # CSR-DCF's template: floor(side x their scale) pixels, resized, then whole cells
        return whole_pixel_sampler(shape, round_half_away(centre), g.region(scale), g.sample_size, p.resize,
                                   (g.resized, g.resized))
    return whole_pixel_sampler(shape, round_half_away(centre), g.sample_size * scale, g.sample_size)


def label_sigma(p: TrackerParams, g: Geometry) -> float:
    """The label's σ in cells: ``tracker.output_sigma`` if set (CSR-DCF's fixed y_sigma), else
    ``output_sigma_factor`` times the square root of the target's whole cells."""
    if p.output_sigma > 0:
        return float(p.output_sigma)
    return float(np.sqrt(np.prod(np.floor(np.asarray(g.target_cells)).clip(1))) * p.output_sigma_factor)


def reported_box(centre: np.ndarray, size: np.ndarray, convention: str) -> tuple[float, float, float, float]:
    """The (x, y, w, h) box, 0-based, of a target at ``centre`` (y, x) of ``size`` (h, w), as
    ``tracker.box_output`` says: 'exact', 'rounded', or the authors' 'half_size' / 'floor_half'.
    A rounded size is at least one pixel: below a pixel the authors' codes report an empty box,
    which no toolkit scores as a box (docs/reference.md)."""
    (cy, cx) = centre
    if convention == "half_size":  # DR²Track's [pos - round(size) / 2, round(size)]
        h, w = np.maximum(round_half_away(size), 1.0)
        return float(cx - w / 2), float(cy - h / 2), float(w), float(h)
    if convention == "floor_half":  # BACF's [pos - floor(floor(size) / 2), floor(size)]
        h, w = np.maximum(np.floor(size), 1.0)
        return float(cx - np.floor(w / 2)), float(cy - np.floor(h / 2)), float(w), float(h)
    box = centre_size_to_box(centre, size)
    if convention == "rounded":  # round([pos - (sz - 1)/2, sz]), 1-based
        x, y, w, h = round_half_away(np.add(box, (1, 1, 0, 0))) - (1, 1, 0, 0)
        return float(x), float(y), float(max(w, 1.0)), float(max(h, 1.0))
    return box


def limit_step(tracker) -> float | None:
    """The step the scale limits are whole powers of (``tracker.scale_limits``), if any: the
    scale estimator's, as the authors' codes take their scale search's."""
    if tracker.params.scale_limits != "step_powers":
        return None
    return getattr(getattr(tracker.scale_estimator, "params", None), "step", None)

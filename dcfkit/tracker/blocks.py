"""The continuous loop's feature blocks: each feature at its own cell size, on its own odd
grid of Fourier coefficients (C-COT / ECO's multi-resolution samples), and how the search
patch is cut and described (ECO's init_features 'odd_cells', sample_patch, extract_features).

Positions here are ECO's: 1-based (y, x) pixels, as the authors' code keeps them; the loop
converts at its edges.
"""
from __future__ import annotations

import dataclasses

import cv2
import numpy as np

from dcfkit.components.features.base import Feature
from dcfkit.components.solvers.eco_cg import regularization_filter
from dcfkit.config.tracker_params import TrackerParams
from dcfkit.numerics.fourier_series import frequencies, interp_fourier, odd
from dcfkit.numerics.patches import pixel_cropper, round_half_away
from dcfkit.tracker.geometry import hann2d


@dataclasses.dataclass
class Block:
    """One feature's geometry: its map (h, w) cells, its filter's odd (H, W) coefficients,
    cosine window, interpolation kernel's coefficients per axis, label's half spectrum and
    the spatial regularization filter."""

    feature: Feature
    cell: int
    dim: int
    size: tuple[int, int]
    filter_size: tuple[int, int]
    window: np.ndarray
    interp_y: np.ndarray
    interp_x: np.ndarray
    label: np.ndarray
    reg: np.ndarray


@dataclasses.dataclass
class Layout:
    """What the first frame fixes: the scale of the sample, the target at that scale, the
    sample's pixels (the support of every block), the output grid and the blocks (sorted
    by cell size, as ECO's init_features)."""

    scale: float
    base_target: np.ndarray
    support: np.ndarray
    output: tuple[int, int]
    blocks: list[Block]


def odd_cells_support(size: np.ndarray, cells: list[int]) -> np.ndarray:
    """ECO's 'odd_cells' sample size: an odd number of the largest cells, plus the few pixels
    (fewer than that cell) that give the most blocks an odd number of cells per axis."""
    big = max(cells)
    base = (1 + 2 * round_half_away(np.asarray(size, float) / (2 * big))) * big
    counts = [sum(int(np.sum(np.floor((base + added) / c) % 2 == 1)) for c in cells) for added in range(big)]
    return round_half_away(base + int(np.argmax(counts))).astype(int)


def initial_scale(p: TrackerParams, target: np.ndarray) -> float:
    """The sample's scale: the search area (``search_area_scale`` x the target) brought within
    [min, max]_image_sample_size (ECO's tracker.m)."""
    area = float(np.prod(target * p.search_area_scale))
    if area > p.max_image_sample_size:
        return float(np.sqrt(area / p.max_image_sample_size))
    if area < p.min_image_sample_size:
        return float(np.sqrt(area / p.min_image_sample_size))
    return 1.0


def layout(p: TrackerParams, s, target: np.ndarray, features: list[Feature]) -> Layout:
    """The first frame's :class:`Layout` for a target of ``target`` (h, w) pixels, ``s`` the
    eco solver's parameters (cell sizes, compressed dimensions and regularization window)."""
    scale = initial_scale(p, target)
    base = target / scale
    region = (np.full(2, np.sqrt(np.prod(base * p.search_area_scale))) if p.search_area_shape == "square"
              else np.floor(base * p.search_area_scale))
    order = sorted(range(len(features)), key=lambda i: s.cell_sizes[i])  # stable, as MATLAB's sort
    support = odd_cells_support(region, [s.cell_sizes[i] for i in order])
    sizes = [tuple(int(v) for v in np.floor(support / s.cell_sizes[i])) for i in order]
    filters = [tuple(int(v) for v in odd(sz)) for sz in sizes]
    output = (max(f[0] for f in filters), max(f[1] for f in filters))
    sigma = np.sqrt(np.prod(np.floor(base))) * p.output_sigma_factor * (np.array(output) / support)
    reg = regularization_filter(support, base, s.reg_window_min, s.reg_window_edge, s.reg_window_power,
                                s.reg_sparsity_threshold)
    blocks = []
    for i, size, fsize in zip(order, sizes, filters):
        ky, kx = frequencies(fsize)
        gy = np.sqrt(2 * np.pi) * sigma[0] / output[0] * np.exp(-2 * (np.pi * sigma[0] * ky / output[0]) ** 2)
        gx = np.sqrt(2 * np.pi) * sigma[1] / output[1] * np.exp(-2 * (np.pi * sigma[1] * kx / output[1]) ** 2)
        interp = [interp_fourier(n, s.interpolation_a, s.interpolation_centering).astype(np.complex64) for n in fsize]
        blocks.append(Block(features[i], s.cell_sizes[i], s.compressed_dims[i], size, fsize, hann2d(size),
                            interp[0], interp[1], (gy.astype(np.float32) * gx.astype(np.float32)).astype(np.complex64),
                            reg))
    return Layout(scale, base, support, output, blocks)


def sample_patch(image: np.ndarray, pos: np.ndarray, region: np.ndarray, out: np.ndarray) -> np.ndarray:
    """ECO's sample_patch: ``region`` (h, w) pixels around the whole 1-based pixel ``pos``,
    from the image taken every df-th pixel (df = floor(shrink - 0.1), on the grid through
    ``pos``), edges replicated, resized bilinearly to ``out`` (h, w)."""
    pos = np.floor(pos).astype(int)
    df = max(int(np.floor(np.min(region / out) - 0.1)), 1)
    if df > 1:
        offset = np.mod(pos - 1, df)
        pos = (pos - 1 - offset) // df + 1
        region = region / df
        image = image[offset[0]::df, offset[1]::df]
    size = np.maximum(round_half_away(region), 2).astype(int)
    first = pos - np.floor((size + 1) / 2).astype(int)  # 0-based: 1-based pos + 1 - floor((n+1)/2), minus 1
    patch = np.ascontiguousarray(pixel_cropper(image.shape, int(first[0]), int(first[1]), int(size[0]),
                                               int(size[1]))(image))
    if tuple(patch.shape[:2]) == (int(out[0]), int(out[1])):
        return patch
    return cv2.resize(patch, (int(out[1]), int(out[0])), interpolation=cv2.INTER_LINEAR)


def extract(blocks: list[Block], patch: np.ndarray) -> list[np.ndarray]:
    """Each block's (C, h, w) float32 map of ``patch``, scaled to mean square 1 over the whole
    block, all channels together (ECO-HC's normalize_power 2, normalize_size, normalize_dim)."""
    if patch.ndim == 2:
        patch = cv2.cvtColor(patch, cv2.COLOR_GRAY2BGR)
    out = []
    for b in blocks:
        x = b.feature.extract(patch, b.cell).astype(np.float32, copy=False)
        total = np.sum(x * x, dtype=np.float32) + np.float32(np.finfo(float).eps)
        out.append(x * np.sqrt(np.float32(x.size) / total))
    return out

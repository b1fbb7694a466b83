"""Feature components: each maps an image patch to a (C, H/cell, W/cell) float32 map.

A feature has ``channels(...)`` and ``extract(patch, cell_size)``; the patch is an
(H, W, 3) uint8 BGR array whose sides are multiples of ``cell_size``. The tracker stacks
the maps of the configured features along the channel axis (the paper uses gray + fHOG + CN,
1 + 31 + 10 = 42 channels at cell size 4).
"""
from __future__ import annotations

import dataclasses
import math

import cv2
import numpy as np

from dcfkit.components.base import Component, Contract
from dcfkit.components.features.colornames import load_table, table_path_problem
from dcfkit.components.features.fhog import ARITHMETICS, fhog
from dcfkit.contracts import array, scalar
from dcfkit.params import param


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
        """(H, W, 3) uint8 BGR, sides multiples of ``cell_size`` -> (C, H/cell, W/cell) float32, finite."""
        raise NotImplementedError

    def reset(self) -> None:
        """Forget what earlier targets left (the built-in features keep nothing)."""


MAX_ORIENTS = 36  # fhog's bins of 5 degrees
MIN_CLIP = 1e-6

# rgb2gray's weights of R, G, B in MATLAB and Octave, applied to the unrounded colour values
MATLAB_GRAY_WEIGHTS = (0.298936, 0.587043, 0.114021)


class Gray(Feature):
    """Gray level in [-0.5, 0.5], averaged over each cell."""

    name = "gray"

    @dataclasses.dataclass(frozen=True)
    class Params:
        conversion: str = param("opencv", "'opencv': cv2's BGR2GRAY, rounded to whole gray levels; 'matlab': "
                                "rgb2gray of the unrounded values, as the authors' get_colorspace",
                                choices=("opencv", "matlab"))

    def channels(self) -> int:
        return 1

    def extract(self, patch, cell_size):
        if self.params.conversion == "matlab":
            # products summed in one fixed order (a BLAS matmul's order depends on the processor)
            r, g, b = (np.float32(w) for w in MATLAB_GRAY_WEIGHTS)
            pixels = patch.astype(np.float32)
            gray = (pixels[..., 0] * b + pixels[..., 1] * g) + pixels[..., 2] * r
        else:
            gray = cv2.cvtColor(patch, cv2.COLOR_BGR2GRAY).astype(np.float32)
        gray *= 1.0 / 255.0
        gray -= 0.5
        return cell_average(gray, cell_size)[None]


class FHOG(Feature):
    """Felzenszwalb HOG: 18 signed + 9 unsigned orientation bins + 4 texture channels."""

    name = "fhog"

    @dataclasses.dataclass(frozen=True)
    class Params:
        # at most MAX_ORIENTS: 3 channels each, the size of the maps and the solver's time; clip at least
        # MIN_CLIP: a smaller one keeps only which bins are empty, or rounds to float32's 0
        n_orients: int = param(9, "unsigned orientation bins (signed ones: twice as many)", ge=2, le=MAX_ORIENTS)
        clip: float = param(0.2, "truncation of the normalised histograms", ge=MIN_CLIP, le=1)
        soft_orientation: bool = param(False, "split each gradient between the two nearest orientation bins "
                                              "(false: nearest bin only, as Piotr's fhog used by STRCF/BACF)")
        channel_order: str = param("bgr", "which colour channel's gradient a pixel takes when two are equally "
                                   "strong: the first of 'bgr' (OpenCV's order) or of 'rgb' (MATLAB's: the "
                                   "authors' code)", choices=("bgr", "rgb"))
        arithmetic: str = param("exact", "'exact' square roots and arctan, or the estimates and acos table of "
                                "Piotr's compiled gradientMex that the authors' MATLAB runs: 'sse' the same on every "
                                "machine, 'sse_cpu' this processor's (x86 only)", choices=ARITHMETICS)

        def validate(self):
            """gradientMex's arithmetic only with soft_orientation false."""
            if self.arithmetic != "exact" and self.soft_orientation:
                return (f"arithmetic {self.arithmetic!r} (Piotr's gradientMex) bins orientations hard: "
                        "set soft_orientation false")

    def channels(self) -> int:
        return 3 * self.params.n_orients + 4

    def extract(self, patch, cell_size):
        p = self.params
        return fhog(patch, cell_size=cell_size, n_orients=p.n_orients, clip=p.clip, soft_orientation=p.soft_orientation,
                    channel_order=p.channel_order, arithmetic=p.arithmetic)


class ColorNames(Feature):
    """The 10-D normalised Color Names (van de Weijer et al. 2009), averaged over each cell."""

    name = "colornames"

    @dataclasses.dataclass(frozen=True)
    class Params:
        table_path: str = param("", "a .npy/.mat CN table; empty: read it from the installed OpenCV")

        def validate(self):
            return table_path_problem(self.table_path) if self.table_path else None

    def channels(self) -> int:
        return 10

    def extract(self, patch, cell_size):
        from dcfkit.components.features.kernels import colornames_cells  # numba, compiled on first use

        table = load_table(self.params.table_path)
        out = np.empty((table.shape[1], patch.shape[0] // cell_size, patch.shape[1] // cell_size), np.float32)
        colornames_cells(np.ascontiguousarray(patch), table, cell_size, out)
        return out


BUILTIN = (Gray, FHOG, ColorNames)


def extract_stack(features, patch: np.ndarray, cell_size: int) -> np.ndarray:
    """Concatenate every feature's map of ``patch`` (gray patches are treated as BGR)."""
    if patch.ndim == 2:
        patch = cv2.cvtColor(patch, cv2.COLOR_GRAY2BGR)
    maps = [f.extract(patch, cell_size) for f in features]
    return (maps[0] if len(maps) == 1 else np.concatenate(maps, axis=0)).astype(np.float32, copy=False)

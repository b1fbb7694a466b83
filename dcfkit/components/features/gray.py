"""Gray level, averaged per cell."""
from __future__ import annotations

import dataclasses

import cv2
import numpy as np

from dcfkit.components.features.base import Feature, cell_average
from dcfkit.numerics.imresize import imresize
from dcfkit.params import param

# rgb2gray's weights of R, G, B in MATLAB and Octave, applied to the unrounded colour values
MATLAB_GRAY_WEIGHTS = (0.298936, 0.587043, 0.114021)


class Gray(Feature):
    """Gray level in [-0.5, 0.5], averaged over each cell."""

    name = "gray"

    @dataclasses.dataclass(frozen=True)
    class Params:
        conversion: str = param("opencv", "'opencv': cv2's BGR2GRAY, rounded to whole gray levels; 'matlab': "
                                "rgb2gray of the unrounded values, as the authors' get_colorspace; 'csr': CSR-DCF's "
                                "uint8 arithmetic, single((gray / 255) - 0.5) on a uint8 image: 1 where the cell's "
                                "whole gray level is at least 128, else 0", choices=("opencv", "matlab", "csr"))
        pooling: str = param("cells", "each cell's value: 'cells' the mean of its pixels, 'matlab_bicubic' MATLAB's "
                             "imresize of the map to the cell grid (CSR-DCF's get_csr_features)",
                             choices=("cells", "matlab_bicubic"))

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
        if self.params.pooling == "cells" and self.params.conversion != "csr":
            gray *= 1.0 / 255.0
            gray -= 0.5
            return cell_average(gray, cell_size)[None]
        if self.params.pooling == "matlab_bicubic":  # a uint8 map stays uint8 (rounded), as MATLAB's
            whole = gray.astype(np.uint8) if self.params.conversion != "matlab" else gray
            cells = imresize(whole, (patch.shape[0] // cell_size, patch.shape[1] // cell_size)).astype(np.float32)
        else:
            cells = cell_average(gray, cell_size)
        if self.params.conversion == "csr":  # uint8 / 255 rounds to 0 or 1; uint8 - 0.5 rounds back (to 0 or 1)
            return (np.rint(cells) >= 128).astype(np.float32)[None]
        return (cells * np.float32(1.0 / 255.0) - np.float32(0.5))[None]

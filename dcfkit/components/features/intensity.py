"""A lookup table over gray levels, averaged per cell: ECO's intensity-channel feature
(``get_table_feature`` with ``intensityChannelNorm6``, which ECO-HC uses on gray sequences in
place of Color Names). dcfkit does not ship the authors' table: ``table_path`` names it; without
one the table is the gray level itself, (v / 255 - 0.5), one channel."""
from __future__ import annotations

import dataclasses
import functools

import cv2
import numpy as np

from dcfkit.components.features.base import Feature, cell_average
from dcfkit.components.features.colornames import table_path_problem
from dcfkit.errors import ConfigError
from dcfkit.params import param


@functools.lru_cache(maxsize=4)
def load_gray_table(path: str) -> np.ndarray:
    """The (256, C) float32 table of a .npy file, or the first array of 256 rows of a .mat file
    (no path: the gray level, (256, 1))."""
    if not path:
        table = (np.arange(256, dtype=np.float32) / np.float32(255) - np.float32(0.5))[:, None]
        table.setflags(write=False)
        return table
    problem = table_path_problem(path)
    if problem:
        raise ConfigError(f"intensity_table.{problem}")
    try:
        if path.endswith(".npy"):
            found = [np.load(path)]
        else:
            import scipy.io  # lazy: only for a .mat table

            found = [v for v in scipy.io.loadmat(path).values() if isinstance(v, np.ndarray)]
    except (OSError, ValueError) as exc:
        raise ConfigError(f"intensity_table.table_path: {path} cannot be read ({exc})") from None
    table = next((v for v in found if v.ndim == 2 and v.shape[0] == 256 and 1 <= v.shape[1] <= 256), None)
    if table is None:
        raise ConfigError(f"intensity_table.table_path: {path} holds no array of 256 rows (one per gray level)")
    table = np.ascontiguousarray(table, dtype=np.float32)
    table.setflags(write=False)
    return table


class IntensityTable(Feature):
    """Each pixel's gray level mapped through a (256, C) table, averaged over each cell."""

    name = "intensity_table"

    @dataclasses.dataclass(frozen=True)
    class Params:
        table_path: str = param("", "a .mat/.npy table of 256 rows, one per gray level (ECO's "
                                "intensityChannelNorm6.mat); empty: the gray level itself")

        def validate(self):
            return table_path_problem(self.table_path) if self.table_path else None

    def channels(self) -> int:
        return load_gray_table(self.params.table_path).shape[1]  # an unreadable table is said at load

    def extract(self, patch, cell_size):
        table = load_gray_table(self.params.table_path)
        gray = cv2.cvtColor(patch, cv2.COLOR_BGR2GRAY)
        cells = cell_average(table[gray], cell_size)
        cells = cells.reshape(cells.shape[:2] + (table.shape[1],))  # OpenCV drops a single channel's axis
        return np.ascontiguousarray(np.moveaxis(cells, -1, 0))

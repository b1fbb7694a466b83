"""The 10-D normalised Color Names table (van de Weijer et al. 2009, 'CNnorm').

The table maps each RGB colour, quantised to 32 levels per channel, to 10 values. dcfkit
does not ship it: it is compiled into OpenCV's contrib build (as a contiguous 32768x10
float32 array, used by its CSRT tracker), so :func:`load_table` reads it out of the installed
``cv2`` binary once, checks shape and SHA-256, and caches it as ``.npy`` in the user cache
directory. A ``.npy``/``.mat`` file can be named instead (``colornames.table_path``).
"""
from __future__ import annotations

import dataclasses
import functools
import glob
import hashlib
import os
from pathlib import Path

import numpy as np

from dcfkit.components.features.base import Feature
from dcfkit.errors import ConfigError, clip, shown
from dcfkit.numerics.imresize import imresize
from dcfkit.opencv_check import contrib_advice
from dcfkit.params import param

SHAPE = (32768, 10)
SHA256 = "e6a0a45f68cf5880d018f9e2f82dff180e992296d335b0fa8eb253b9db403ec0"
# first row of the table, as float32 bytes: how it is found inside the OpenCV binary
_FIRST_ROW = np.array([0.45975, 0.014802, 0.044289, -0.028193, 0.001151], np.float32).tobytes()


def table_index(bgr: np.ndarray) -> np.ndarray:
    """Row of the table for each pixel of an (H, W, 3) uint8 BGR image: R/8 + 32 G/8 + 1024 B/8."""
    q = bgr >> 3
    return q[..., 2].astype(np.int32) | (q[..., 1].astype(np.int32) << 5) | (q[..., 0].astype(np.int32) << 10)


def _cache_dir() -> Path:
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return Path(base) / "dcfkit"


def _verify(table: np.ndarray, source: str) -> np.ndarray:
    table = np.ascontiguousarray(table, dtype=np.float32)
    if table.shape != SHAPE:
        raise ConfigError(f"Color Names table from {source} has shape {table.shape}, expected {SHAPE}")
    digest = hashlib.sha256(table.tobytes()).hexdigest()
    if digest != SHA256:
        raise ConfigError(f"Color Names table from {source} failed its checksum (sha256 {digest[:12]}…, expected "
                          f"{SHA256[:12]}…): it is not the normalised 10-D CN table")
    table.setflags(write=False)
    return table


def _from_opencv() -> np.ndarray:
    try:
        import cv2  # lazy: only when the table is read out of OpenCV
    except ImportError as exc:  # pragma: no cover - cv2 is a dependency
        raise ConfigError(f"cannot import cv2 to read the Color Names table: {exc}") from None
    folder = os.path.dirname(cv2.__file__)
    binaries = sorted(glob.glob(os.path.join(folder, "**", "cv2*.so"), recursive=True)
                      + glob.glob(os.path.join(folder, "**", "cv2*.pyd"), recursive=True))
    for path in binaries:
        data = Path(path).read_bytes()
        start = data.find(_FIRST_ROW)
        if start >= 0:
            table = np.frombuffer(data, np.float32, count=SHAPE[0] * SHAPE[1], offset=start).reshape(SHAPE)
            return _verify(table, path)
    where = ", ".join(binaries) or "no cv2 binary"
    raise ConfigError(f"the Color Names table was not found in the installed OpenCV ({where}); "
                      f"{contrib_advice(cv2)} (or set colornames.table_path to a .npy/.mat file)")


def _expanded(path: str) -> Path | None:
    """``path`` with ``~`` expanded, or None if it names an unknown user's home."""
    try:
        return Path(path).expanduser()
    except RuntimeError:  # pathlib: "Could not determine home directory"
        return None


def _is_file(p: Path | None) -> bool:
    try:
        return p is not None and p.is_file()
    except OSError:  # e.g. a name too long for the file system: no such file
        return False


def table_path_problem(path: str) -> str | None:
    """Why ``path`` cannot name a table (checked when a config is read), or None."""
    p = _expanded(path)
    if not path.endswith((".npy", ".mat")):
        return f"table_path: {shown(path)} must be a .npy or .mat file"
    if not _is_file(p):
        return f"table_path: file not found: {clip(path)}"
    return None


def _read(p: Path) -> np.ndarray | None:
    """The array of a .npy file, or the first (32768, 10) one of a .mat file (None: none there)."""
    if p.suffix == ".npy":
        return np.load(p)
    import scipy.io  # lazy: only for a user-supplied .mat table

    try:
        data = scipy.io.loadmat(str(p))
    except scipy.io.matlab.MatReadError as exc:  # said as numpy says an unreadable file
        raise ValueError(str(exc)) from None
    return next((v for v in data.values() if isinstance(v, np.ndarray) and v.shape == SHAPE), None)


def _from_file(path: str) -> np.ndarray:
    p = _expanded(path)
    if not _is_file(p):
        raise ConfigError(f"colornames.table_path: file not found: {p or path}")
    if p.suffix not in (".npy", ".mat"):
        raise ConfigError(f"colornames.table_path: {p} must be a .npy or .mat file")
    try:
        table = _read(p)
    except (OSError, ValueError, EOFError) as exc:  # not an array file
        raise ConfigError(f"colornames.table_path: {p} cannot be read ({type(exc).__name__}: {exc})") from None
    if table is None:
        raise ConfigError(f"colornames.table_path: {p} holds no {SHAPE[0]}x{SHAPE[1]} array")
    return _verify(table, str(p))


@functools.lru_cache(maxsize=4)
def load_table(path: str = "") -> np.ndarray:
    """The verified (32768, 10) float32 table, from ``path`` or the OpenCV binary (cached)."""
    if path:
        return _from_file(path)
    cached = _cache_dir() / f"colornames_{SHA256[:16]}.npy"
    if cached.is_file():
        try:
            return _verify(np.load(cached), str(cached))
        except (ConfigError, ValueError, OSError):
            pass  # a damaged cache is rebuilt below
    table = _from_opencv()
    try:
        cached.parent.mkdir(parents=True, exist_ok=True)
        tmp = cached.with_suffix(f".{os.getpid()}.tmp.npy")
        np.save(tmp, table)
        os.replace(tmp, cached)
    except OSError:
        pass  # a read-only home only costs the next process a re-read
    return table


class ColorNames(Feature):
    """The 10-D normalised Color Names (van de Weijer et al. 2009), averaged over each cell."""

    name = "colornames"

    @dataclasses.dataclass(frozen=True)
    class Params:
        table_path: str = param("", "a .npy/.mat CN table; empty: read it from the installed OpenCV")
        pooling: str = param("cells", "each cell's value: 'cells' the mean of its pixels, 'matlab_bicubic' MATLAB's "
                             "imresize of the map to the cell grid (CSR-DCF's get_csr_features)",
                             choices=("cells", "matlab_bicubic"))

        def validate(self):
            return table_path_problem(self.table_path) if self.table_path else None

    def channels(self) -> int:
        return 10

    def extract(self, patch, cell_size):
        from dcfkit.components.features.kernels import colornames_cells  # numba, compiled on first use

        table = load_table(self.params.table_path)
        if self.params.pooling == "matlab_bicubic":  # each pixel's names, then the map resized
            names = table[table_index(np.ascontiguousarray(patch))].astype(np.float64)
            cells = imresize(names, (patch.shape[0] // cell_size, patch.shape[1] // cell_size))
            return np.ascontiguousarray(cells.transpose(2, 0, 1), np.float32)
        out = np.empty((table.shape[1], patch.shape[0] // cell_size, patch.shape[1] // cell_size), np.float32)
        colornames_cells(np.ascontiguousarray(patch), table, cell_size, out)
        return out

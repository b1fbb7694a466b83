"""Real 2-D FFTs over the last two axes, with a selectable backend.

``scipy`` (default) uses :mod:`scipy.fft` with one worker; ``pyfftw`` builds FFTW plans
once per (shape, dtype) and reuses them, one thread. Both keep float32/complex64 data in
single precision. Forward transforms are unnormalised, inverse ones scaled by 1/K (numpy
convention), which is the convention the solver's equations assume (Eq. 10's K).
:func:`multiply` is the elementwise product of spectra, rounded the same way on every machine.
``rfft2_rows``/``irfft2_rows`` transform maps that are zero outside a band of rows (CSR-DCF's
constrained filter); scipy's spare the other rows' work and keep the whole transforms' bits.
"""
from __future__ import annotations

import numpy as np

from dcfkit.errors import shown

BACKENDS = ("scipy", "pyfftw")


class Backend:
    """An FFT backend: ``rfft2`` and ``irfft2`` over the last two axes, and the transforms of maps
    that are zero outside a band of rows (a filter constrained to a mask), computed whole here;
    a backend may spare the rows' work."""

    def rfft2(self, x: np.ndarray) -> np.ndarray:
        raise NotImplementedError

    def irfft2(self, xf: np.ndarray, shape: tuple[int, int]) -> np.ndarray:
        raise NotImplementedError

    def rfft2_rows(self, x: np.ndarray, rows: slice) -> np.ndarray:
        """``rfft2(x)`` for an ``x`` that is zero outside ``rows`` of its second-last axis."""
        return self.rfft2(x)

    def irfft2_rows(self, xf: np.ndarray, shape: tuple[int, int], rows: slice) -> np.ndarray:
        """``irfft2(xf, shape)`` on ``rows`` of its second-last axis, zero outside them."""
        out = self.irfft2(xf, shape)
        band = np.zeros(out.shape[-2], bool)
        band[rows] = True
        out[..., ~band, :] = 0
        return out


class ScipyFFT(Backend):
    name = "scipy"
    full = False  # half spectra (W//2 + 1 columns) of real maps

    def __init__(self):
        import scipy.fft  # lazy: only the chosen backend is imported

        self._fft = scipy.fft

    def rfft2(self, x: np.ndarray) -> np.ndarray:
        return self._fft.rfft2(x, axes=(-2, -1), workers=1)

    def irfft2(self, xf: np.ndarray, shape: tuple[int, int]) -> np.ndarray:
        return self._fft.irfft2(xf, s=shape, axes=(-2, -1), workers=1)

    def rfft2_rows(self, x: np.ndarray, rows: slice) -> np.ndarray:
        """Only ``rows`` transformed along the last axis (the others' transforms are zero), then
        every column: pocketfft's rfft2 takes the axes in this order, so for an ``x`` that is +0
        outside ``rows`` the bits are its own. An empty band is transformed whole, whose zeros
        may be signed."""
        if not _spares(rows, x.shape[-2]):
            return super().rfft2_rows(x, rows)
        out = np.zeros((*x.shape[:-1], x.shape[-1] // 2 + 1), np.result_type(x.dtype, np.complex64))
        out[..., rows, :] = self._fft.rfft(x[..., rows, :], axis=-1, workers=1)
        return self._fft.fft(out, axis=-2, workers=1, overwrite_x=True)

    def irfft2_rows(self, xf: np.ndarray, shape: tuple[int, int], rows: slice) -> np.ndarray:
        """Every column inverted, then only ``rows`` along the last axis, unscaled, and 1/(H W)
        applied last: pocketfft's irfft2 in the same order, its bits (it takes 1/N in long double,
        rounded to the output's precision, which 1/N in double is not for every N)."""
        h, w = shape
        if not _spares(rows, h):
            return super().irfft2_rows(xf, shape, rows)
        columns = self._fft.ifft(xf, n=h, axis=-2, norm="forward", workers=1)
        band = self._fft.irfft(columns[..., rows, :], n=w, axis=-1, norm="forward", workers=1)
        out = np.zeros((*xf.shape[:-2], h, w), band.dtype)
        out[..., rows, :] = band * band.dtype.type(np.longdouble(1) / (h * w))
        return out


SPARED_BAND = 2 / 3  # a band of more rows is transformed whole: its separate passes cost more than they spare


def _spares(rows: slice, n: int) -> bool:
    """Whether transforming only ``rows`` of ``n`` is worth it: a band, at most SPARED_BAND of them."""
    start, stop, _ = rows.indices(n)
    return 0 < stop - start <= SPARED_BAND * n


class PyFFTW(Backend):
    """pyfftw with plans cached per (shape, dtype). Inputs are copied into the plan's own
    buffer (FFTW's multi-dimensional c2r transform overwrites its input) and outputs copied
    out of it, so callers' arrays are never touched or aliased."""

    name = "pyfftw"
    full = False

    def __init__(self):
        import pyfftw  # lazy: only the chosen backend is imported

        self._pyfftw = pyfftw
        self._plans: dict = {}

    def _plan(self, key, build):
        plan = self._plans.get(key)
        if plan is None:
            plan = self._plans[key] = build()
        return plan

    def rfft2(self, x: np.ndarray) -> np.ndarray:
        builders = self._pyfftw.builders
        plan = self._plan(("r", x.shape, x.dtype.str),
                          lambda: builders.rfft2(self._pyfftw.empty_aligned(x.shape, x.dtype), axes=(-2, -1),
                                                 threads=1, planner_effort="FFTW_ESTIMATE"))
        plan.input_array[...] = x
        return plan().copy()

    def irfft2(self, xf: np.ndarray, shape: tuple[int, int]) -> np.ndarray:
        builders = self._pyfftw.builders
        plan = self._plan(("i", xf.shape, xf.dtype.str, tuple(shape)),
                          lambda: builders.irfft2(self._pyfftw.empty_aligned(xf.shape, xf.dtype), s=shape,
                                                  axes=(-2, -1), threads=1, planner_effort="FFTW_ESTIMATE"))
        plan.input_array[...] = xf
        return plan().copy()


class FullSpectra(Backend):
    """Whole complex spectra (..., H, W) in place of half ones, with scipy.fft: ``rfft2`` is fft2
    and ``irfft2`` the complex ifft2 (callers needing a real map take its real part). As DR²Track's
    code computes: shift_sample's Nyquist frequency (+N/2) makes the shifted sample complex, and
    run_training's ifft2 (no 'symmetric') keeps the filter's imaginary part."""

    name = "full"
    full = True

    def __init__(self):
        import scipy.fft  # lazy: only the chosen backend is imported

        self._fft = scipy.fft

    def rfft2(self, x: np.ndarray) -> np.ndarray:
        return self._fft.fft2(x, axes=(-2, -1), workers=1)

    def irfft2(self, xf: np.ndarray, shape: tuple[int, int]) -> np.ndarray:
        return self._fft.ifft2(xf, s=shape, axes=(-2, -1), workers=1)


def multiply(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Elementwise product of complex arrays (broadcast), ``(ar br - ai bi) + i (ar bi + ai br)``
    with each product rounded: numpy's complex64 product fuses them (FMA) on processors with
    AVX2 and not on others, so its last bits depend on the machine."""
    a, b = np.asarray(a), np.asarray(b)
    out = np.empty(np.broadcast_shapes(a.shape, b.shape), np.result_type(a, b))
    out.real = a.real * b.real - a.imag * b.imag
    out.imag = a.real * b.imag + a.imag * b.real
    return out


def make_fft(backend: str = "scipy", full: bool = False):
    """An FFT backend by name ('scipy' or 'pyfftw'); ``full``: :class:`FullSpectra` (scipy's)."""
    if full:
        return FullSpectra()
    if backend == "scipy":
        return ScipyFFT()
    if backend == "pyfftw":
        return PyFFTW()
    raise ValueError(f"unknown FFT backend {shown(backend)}; choose one of {', '.join(BACKENDS)}")

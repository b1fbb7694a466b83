"""Detection: the response map (Eq. 12) and its peak (its maxima: :mod:`dcfkit.numerics.maxima`).

Filters and samples are Fourier maps of real signals, shape (C, H, W//2+1) complex64.
The response is the circular cross-correlation R(τ) = Σ_c Σ_x h_c(x) s_c(x+τ), i.e.
R = F⁻¹(Σ_c conj(ĥ_c) ⊙ ŝ_c); the paper writes the same operation as a convolution with
the mirrored filter. Offsets τ are circular: index i stands for i - H when i > H // 2.
"""
from __future__ import annotations

import numpy as np

from dcfkit.numerics.fft import multiply


def response_spectra(hf: np.ndarray, sf: np.ndarray) -> np.ndarray:
    """The spectra of Eq. (12)'s responses: sum over channels of conj(ĥ) ẑ, (..., H, Wr)."""
    return np.einsum("chw,...chw->...hw", hf.conj(), sf)


def response(hf: np.ndarray, sf: np.ndarray, shape: tuple[int, int], fft) -> np.ndarray:
    """Eq. (12): (C, H, Wr) filter and (..., C, H, Wr) samples -> (..., H, W) float32 response."""
    return np.real(fft.irfft2(response_spectra(hf, sf), shape)).astype(np.float32, copy=False)


def _moments(spectrum, ey, ex, fy, fx) -> tuple[complex, ...]:
    """:func:`dcfkit.numerics.peak_kernels.moments`: the interpolant's value and derivative sums, in a fixed
    order (a BLAS would sum in the order of its processor kernel)."""
    from dcfkit.numerics import peak_kernels  # lazy: numba, compiled on first use

    return peak_kernels.moments(spectrum, np.ascontiguousarray(ey, np.complex128),
                                np.ascontiguousarray(ex, np.complex128), fy, fx)


def wrap(index, size: int):
    """Circular index -> signed offset in [-(size // 2), (size - 1) // 2]."""
    return (np.asarray(index) + size // 2) % size - size // 2


def subpixel_peak(r: np.ndarray, iterations: int = 5) -> tuple[float, float, float]:
    """Peak of a circular (H, W) map as a signed (dy, dx) offset, and its value.

    Starts at the grid maximum and takes Newton steps on the map's trigonometric (Fourier)
    interpolant, as STRCF/SRDCF do, which avoids the bias of per-axis parabolas towards whole
    cells. A step that leaves the cell around the grid maximum or lowers the value is dropped.
    """
    h, w = r.shape
    i, j = np.unravel_index(int(np.argmax(r)), r.shape)
    y0, x0, best = float(wrap(i, h)), float(wrap(j, w)), float(r[i, j])
    if iterations <= 0 or h < 3 or w < 3:
        return y0, x0, best
    spectrum = np.fft.fft2(r.astype(np.float64)) / (h * w)
    fy, fx = np.fft.fftfreq(h), np.fft.fftfreq(w)
    c = 2j * np.pi  # d/dy of exp(2πi f y), per unit of y, is 2πi f
    ky, kx = c * fy, c * fx
    y, x = y0, x0
    for _ in range(iterations):
        _, m10, m01, m20, m02, m11 = _moments(spectrum, np.exp(ky * y), np.exp(kx * x), fy, fx)
        gy, gx = (c * m10).real, (c * m01).real
        hyy, hxx, hxy = (c * c * m20).real, (c * c * m02).real, (c * c * m11).real
        det = hyy * hxx - hxy * hxy
        if not (det > 0 and hyy < 0):  # not a local maximum of the interpolant: stop
            break
        y -= (hxx * gy - hxy * gx) / det
        x -= (hyy * gx - hxy * gy) / det
    if abs(y - y0) > 1 or abs(x - x0) > 1:
        return y0, x0, best
    value = float(_moments(spectrum, np.exp(ky * y), np.exp(kx * x), fy, fx)[0].real)
    return (y, x, value) if value >= best else (y0, x0, best)


def _signed_frequencies(n: int) -> np.ndarray:
    """0, 1, ..., ceil((n-1)/2), then negative: the authors' ``ky``/``kx`` grid (the Nyquist
    frequency of an even n counts as +n/2; numpy's fftfreq makes it -n/2)."""
    k = np.arange(n)
    return np.where(k <= (n - 1) // 2 + (n % 2 == 0), k, k - n).astype(np.float64)


def _key(y: float, x: float) -> object:
    """A Newton step's point as a key, bit for bit (+0.0 and -0.0 differ); one with a NaN is never
    alike another."""
    if y != y or x != x:
        return object()  # a NaN step runs on, as it always did
    return np.array([y, x], dtype=np.float64).tobytes()


def newton_peak(maps: np.ndarray, iterations: int = 5, spectra: np.ndarray | None = None
                ) -> tuple[int, float, float, float]:
    """The authors' ``resp_newton`` (STRCF, BACF, DR²Track): over (S, H, W) circular maps, the
    best map and its peak as a signed (dy, dx) offset in cells, with its value.

    From each map's grid maximum (ties: first in column-major order, as MATLAB's max), take
    ``iterations`` unconditional Newton steps on the trigonometric interpolant over the
    authors' frequency grid (:func:`_signed_frequencies`, their Hessian included); a map whose
    interpolated value ends below its grid maximum keeps the grid maximum. The best map has
    the largest value. Unlike :func:`subpixel_peak`, nothing keeps the steps near the grid
    maximum, and the map with the largest grid value need not be the one chosen. Steps that
    come back to a point they reached before stop there, with the point all the steps would
    end on (the same bits, sooner: BACF takes 50).
    """
    maps = np.asarray(maps, dtype=np.float64)
    n_maps, h, w = maps.shape
    ky, kx = _signed_frequencies(h), _signed_frequencies(w)
    best = (-1, 0.0, 0.0, -np.inf)
    for s in range(n_maps):
        r = maps[s]
        flat = int(np.argmax(r.T))  # column-major: MATLAB's max(max(r, [], 1), [], 2)
        row, col = flat % h, flat // h
        init_value = float(r[row, col])
        y0 = 2 * np.pi * (((row + (h - 1) // 2) % h) - (h - 1) // 2) / h
        x0 = 2 * np.pi * (((col + (w - 1) // 2) % w) - (w - 1) // 2) / w
        # resp_newton refines on the response's spectrum as computed (complex with FullSpectra)
        spectrum = np.fft.fft2(r) if spectra is None else np.asarray(spectra[s], np.complex128)
        y, x = y0, x0
        seen = {_key(y, x): 0}  # each point the steps reached -> after how many steps
        path = [(y, x)]
        for i in range(iterations):
            m00, m10, m01, m20, m02, m11 = _moments(spectrum, np.exp(1j * ky * y), np.exp(1j * kx * x), ky, kx)
            grad_y, grad_x = -m10.imag, -m01.imag
            ival = 1j * m00
            h_yy, h_xx, h_xy = (-m20 + ival).real, (-m02 + ival).real, (-m11).real
            det = h_yy * h_xx - h_xy * h_xy
            with np.errstate(divide="ignore", invalid="ignore"):
                y, x = y - (h_xx * grad_y - h_xy * grad_x) / det, x - (h_yy * grad_x - h_xy * grad_y) / det
            first = seen.setdefault(_key(y, x), i + 1)
            if first != i + 1:
                # the steps cycle in the last bits: a step depends on (y, x) alone, so the point
                # after all the iterations is the cycle's, bit for bit
                y, x = path[first + (iterations - first) % (i + 1 - first)]
                break
            path.append((y, x))
        value = float(_moments(spectrum, np.exp(1j * ky * y), np.exp(1j * kx * x), ky, kx)[0].real) / (h * w)
        if not value >= init_value:  # lower (or NaN): the grid maximum
            y, x, value = y0, x0, init_value
        if value > best[3]:
            dy = (np.mod(y + np.pi, 2 * np.pi) - np.pi) / (2 * np.pi) * h
            dx = (np.mod(x + np.pi, 2 * np.pi) - np.pi) / (2 * np.pi) * w
            best = (s, float(dy), float(dx), value)
    return best


def shift_spectrum(xf: np.ndarray, dy: float, dx: float, shape: tuple[int, int], full: bool = False) -> np.ndarray:
    """Spectra of maps translated so that x'(p) = x(p + (dy, dx)), circularly (sub-cell shifts
    interpolate in the Fourier domain; the Nyquist frequency of an even size counts as positive,
    as the authors' ``shift_sample``): half spectra (..., H, W//2+1), or whole ones (..., H, W)
    if ``full``. Whole spectra take that grid on both axes, as ``shift_sample`` does, so a
    shifted real map turns complex (its Nyquist bins lose their conjugate symmetry)."""
    ky = (_signed_frequencies(shape[0]) / shape[0])[:, None]
    kx = ((_signed_frequencies(shape[1]) / shape[1]) if full else np.fft.rfftfreq(shape[1]))[None, :]
    phase = np.exp(2j * np.pi * (ky * dy + kx * dx)).astype(np.complex64)
    return multiply(xf, phase)


def channel_responses(hf: np.ndarray, sf: np.ndarray, shape: tuple[int, int], fft) -> np.ndarray:
    """Eq. (12) per channel, unsummed: (C, H, Wr) filter and (..., C, H, Wr) samples ->
    (..., C, H, W) float32 (CSR-DCF's ``response_chann``)."""
    return np.real(fft.irfft2(hf.conj() * sf, shape)).astype(np.float32, copy=False)


def parabola_peak(r: np.ndarray) -> tuple[float, float]:
    """CSR-DCF's peak of a circular (H, W) map: the grid maximum (the first in column-major
    order, as MATLAB's ``find``), each axis refined by the parabola through it and its two
    neighbours (0.5 (p₊ - p₋) / (2 p₀ - p₊ - p₋), 0 if not finite), then wrapped to a signed
    (dy, dx) offset (beyond half the grid: negative)."""
    h, w = r.shape
    flat = int(np.argmax(r.T))
    row, col = flat % h, flat // h
    out = []
    for index, size, line in ((row, h, r[:, col]), (col, w, r[row, :])):
        before, here, after = (float(line[(index + k) % size]) for k in (-1, 0, 1))
        with np.errstate(divide="ignore", invalid="ignore"):
            delta = 0.5 * (after - before) / (2 * here - after - before)
        offset = index + (delta if np.isfinite(delta) else 0.0)
        out.append(offset - size if offset + 1 > size / 2 else offset)
    return out[0], out[1]


def apce(response: np.ndarray) -> float:
    """Wang et al.'s APCE: ``|max - min|² / mean((R - min)²)``; 0 for a flat map."""
    r = np.asarray(response, dtype=np.float64)
    low = r.min()
    energy = float(np.mean((r - low) ** 2))
    return float((r.max() - low) ** 2 / energy) if energy > 0 else 0.0

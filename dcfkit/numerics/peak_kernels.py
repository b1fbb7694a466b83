"""Compiled (numba) sums of the Fourier-interpolated peak (:mod:`dcfkit.numerics.response`).

A BLAS would sum the interpolant's products in the order of its processor kernel, which moves
the peak's last bits from machine to machine; numpy's einsum sums in a fixed order but is five
times slower on these maps. Loaded on first use (numba's import costs 0.25 s), cached on disk.
"""
from __future__ import annotations

import numba


@numba.njit(cache=True, nogil=True)
def moments(spectrum, ey, ex, fy, fx):  # pragma: no cover - compiled
    """The interpolant's weighted sums m_ab = Σ_ij fy_i^a fx_j^b ey_i S_ij ex_j for ab = 00, 10,
    01, 20, 02, 11 (its value and, times the frequency factors, its first and second
    derivatives), complex128, summed row by row in index order. spectrum (H, W) complex128;
    ey (H,), ex (W,) complex128; fy (H,), fx (W,) float64."""
    m00 = m10 = m01 = m20 = m02 = m11 = 0j
    for i in range(spectrum.shape[0]):
        r0 = r1 = r2 = 0j  # Σ_j fx_j^b S_ij ex_j of row i
        for j in range(spectrum.shape[1]):
            t = spectrum[i, j] * ex[j]
            r0 += t
            r1 += fx[j] * t
            r2 += fx[j] * fx[j] * t
        r0, r1, r2 = ey[i] * r0, ey[i] * r1, ey[i] * r2
        m00 += r0
        m10 += fy[i] * r0
        m20 += fy[i] * fy[i] * r0
        m01 += r1
        m11 += fy[i] * r1
        m02 += r2
    return m00, m10, m01, m20, m02, m11

"""Compiled (numba) per-frequency arithmetic of the ADMM solver (Eqs. 6-11).

Imported on the first solver call (numba's import takes about 0.25 s); machine code is cached
on disk as for :mod:`dcfkit.components.features.kernels`. Each loop fuses what numpy does in several
passes with temporaries, with the same single-precision operations in the same order: complex
products as ``fma(ar, br, -ai bi) + i fma(ar, bi, ai br)`` (numpy's SIMD loops on FMA
hardware), channel sums in channel order, a division by a real number as a product with its
float32 reciprocal, Python scalars rounded to float32. The trackers' boxes are therefore
bit-identical to the numpy formulation's on the development machine (x86-64 with FMA); where
numpy's complex loops do not use FMA, the two differ in the last bit.

Spectra are passed as float32 views of (C, H, Wr) complex64 arrays, (C, H, 2 Wr) with real
and imaginary parts interleaved, so that every operation is explicitly single precision.
"""
from __future__ import annotations

import numba
import numpy as np
from llvmlite import ir
from numba import types
from numba.extending import intrinsic


@intrinsic
def _fma(typingctx, a, b, c):  # pragma: no cover - compiled
    """Single-rounding a * b + c in float32 (LLVM's fma)."""
    sig = types.float32(types.float32, types.float32, types.float32)

    def codegen(context, builder, signature, args):
        f32 = ir.FloatType()
        fn = builder.module.declare_intrinsic("llvm.fma", [f32], ir.FunctionType(f32, [f32, f32, f32]))
        return builder.call(fn, args)

    return sig, codegen


@numba.njit(cache=True, nogil=True, inline="always")
def _mul(ar, ai, br, bi):  # pragma: no cover - compiled
    return _fma(ar, br, -(ai * bi)), _fma(ar, bi, ai * br)


@numba.njit(cache=True, nogil=True)
def prepare(xf, yf, v_prev, theta, aa, rhs0):  # pragma: no cover - compiled
    """aa = Σ_c |x̂_c|² (H, Wr); rhs0 = x̂ ⊙ conj(ŷ) + θ v̂ˡ, the part of Eq. (9)'s right-hand
    side constant over the iterations while θ is (θ = 0: no v_prev)."""
    n, h, w2 = xf.shape
    m = h * w2 // 2
    th = np.float32(theta)
    Y, A = yf.reshape(2 * m), aa.reshape(m)
    A[:] = 0.0
    for c in range(n):  # flat per-channel rows: loops LLVM vectorises
        X, V, R = xf[c].reshape(2 * m), v_prev[c].reshape(2 * m), rhs0[c].reshape(2 * m)
        for p in range(m):
            xr, xi = X[2 * p], X[2 * p + 1]
            A[p] = A[p] + (xr * xr - (-xi) * xi)
            re, im = _mul(xr, xi, Y[2 * p], -Y[2 * p + 1])
            if theta != 0:  # AutoTrack's θ-step may take θ below 0
                re = re + V[2 * p] * th
                im = im + V[2 * p + 1] * th
            R[2 * p], R[2 * p + 1] = re, im


@numba.njit(cache=True, nogil=True)
def v_step(xf, rhs0, hf, uf, gamma, c, aa, first, t, vf):  # pragma: no cover - compiled
    """Eq. (9) by Sherman-Morrison at every frequency: with b = rhs0 + γ ĥ - û (b = rhs0 on the
    first iteration), v̂ = (b - x̂ (x̂ᴴ b) / (c + x̂ᴴx̂)) / c. t: (H, 2 Wr) scratch."""
    n, h, w2 = xf.shape
    m = h * w2 // 2
    g = np.float32(gamma)
    inv_c = np.float32(1.0 / c)
    c32 = np.float32(c)
    T, A = t.reshape(2 * m), aa.reshape(m)
    T[:] = 0.0
    for k in range(n):  # b into vf, and t = Σ_k conj(x̂_k) b_k
        X, R, H = xf[k].reshape(2 * m), rhs0[k].reshape(2 * m), hf[k].reshape(2 * m)
        U, V = uf[k].reshape(2 * m), vf[k].reshape(2 * m)
        if first:
            V[:] = R
        else:
            for q in range(2 * m):
                V[q] = (R[q] + H[q] * g) - U[q]
        for p in range(m):
            ar, ai = X[2 * p], -X[2 * p + 1]
            br, bi = V[2 * p], V[2 * p + 1]
            T[2 * p] = T[2 * p] + (ar * br - ai * bi)
            T[2 * p + 1] = T[2 * p + 1] + (ar * bi + ai * br)
    for p in range(m):
        r = np.float32(1.0) / (c32 + A[p])
        T[2 * p] = T[2 * p] * r
        T[2 * p + 1] = T[2 * p + 1] * r
    for k in range(n):
        X, V = xf[k].reshape(2 * m), vf[k].reshape(2 * m)
        for p in range(m):
            re, im = _mul(X[2 * p], X[2 * p + 1], T[2 * p], T[2 * p + 1])
            V[2 * p] = (V[2 * p] - re) * inv_c
            V[2 * p + 1] = (V[2 * p + 1] - im) * inv_c


@numba.njit(cache=True, nogil=True)
def h_input(vf, uf, gamma, out):  # pragma: no cover - compiled
    """The spectrum Eq. (10) transforms back: v̂ + û / γ."""
    s = np.float32(1.0 / gamma)
    for k in range(vf.shape[0]):
        for i in range(vf.shape[1]):
            for j in range(vf.shape[2]):
                out[k, i, j] = vf[k, i, j] + uf[k, i, j] * s


@numba.njit(cache=True, nogil=True)
def multiplier(vf, hf, gamma, first, uf):  # pragma: no cover - compiled
    """Eq. (11): û ← û + γ (v̂ - ĥ) (û = γ (v̂ - ĥ) on the first iteration), in place."""
    g = np.float32(gamma)
    for k in range(vf.shape[0]):
        for i in range(vf.shape[1]):
            for j in range(vf.shape[2]):
                step = (vf[k, i, j] - hf[k, i, j]) * g
                uf[k, i, j] = step if first else uf[k, i, j] + step

"""ECO's first frame: the filter f and the projection matrix P learnt jointly (Danelljan et
al., CVPR 2017, Sec. 3.1, Eqs. 6-7) by Gauss-Newton, each linearised problem solved by
conjugate gradient (ECO's train_joint, lhs_operation_joint).

With the projected sample z = Pᵀx, the residual of Eq. (6) is linearised at (f, P) in
(Δf, ΔP): r ≈ z·(f + Δf) + (ΔPᵀx)·f - y, and its normal equations (Eq. 7) are solved for
(f + Δf, ΔP) with the penalty λ‖P + ΔP‖². Blocks are as in :mod:`.eco_cg`; x (C, H, Wh)
complex, P (C, D) float32. The ΔP part of the gradient sums the columns kx < 0 twice and
leaves out kx = 0, as the authors' code does (their ``XH * fyf - XH(:, fi:end) * ...``).
"""
from __future__ import annotations

import math
from typing import Sequence

import numpy as np

from dcfkit.components.solvers.eco_cg import apply_regularization, inner, output_shape, pcg, preconditioner
from dcfkit.numerics.fourier_series import symmetrize, window_of


def project(x: np.ndarray, p: np.ndarray) -> np.ndarray:
    """(..., C, H, W) -> (..., D, H, W): the channels mixed by P (C, D)."""
    # einsum, not a BLAS product: its sums' order would depend on the processor and the threads
    return np.einsum("...chw,cd->...dhw", x, p.astype(x.real.dtype)).astype(x.dtype, copy=False)


def pca_projection(x: np.ndarray, dim: int) -> np.ndarray:
    """(C, D) float32: the first ``dim`` principal directions of the (C, H, W) map's pixels,
    mean removed (ECO's init_projection_matrix, 'pca')."""
    flat = x.reshape(x.shape[0], -1).T.astype(np.float64)
    flat = flat - flat.mean(axis=0)
    u, _, _ = np.linalg.svd(flat.T @ flat)
    return u[:, :dim].astype(np.float32)


def _data_grad(xh: np.ndarray, g: np.ndarray) -> np.ndarray:
    """2 Re Σ_{kx<0} conj(x_c) g_d -> (C, D): the ΔP part of Xᴴ applied to (D, H, Wh) g."""
    return 2 * np.einsum("chw,dhw->cd", xh[..., :-1], g[..., :-1]).real


def _summed(parts: Sequence[np.ndarray], shape) -> np.ndarray:
    out = np.zeros(shape, dtype=np.complex64)
    for part in parts:
        win = window_of(shape, part.shape)
        out[win] += part
    return out


def _lhs(v: list, k: int, xs, zs, f0, reg, lam: float) -> list:
    """The Gauss-Newton normal equations' left side for v = [f_1..f_K, ΔP_1..ΔP_K]."""
    f, dp = v[:k], v[k:]
    shape = output_shape(f)
    sh = _summed([(z * fi).sum(axis=0) for z, fi in zip(zs, f)], shape)
    bp = _summed([(project(x, d) * g).sum(axis=0) for x, d, g in zip(xs, dp, f0)], shape)
    out_f, out_p = [], []
    for x, z, fi, g, r, d in zip(xs, zs, f, f0, reg, dp):
        win = window_of(shape, fi.shape)
        out_f.append((np.conj(z) * (sh[win] + bp[win]) + apply_regularization(fi, r)).astype(np.complex64))
        both = np.conj(g) * (bp[win] + sh[win])
        out_p.append((_data_grad(np.conj(x), both) + lam * d).astype(np.float32))
    return out_f + out_p


def _dot_joint(k: int):
    return lambda a, b: inner(a[:k], b[:k]) + float(sum(np.vdot(x, y).real for x, y in zip(a[k:], b[k:])))


def train_joint(xs: Sequence[np.ndarray], yfs: Sequence[np.ndarray], projections: Sequence[np.ndarray],
                reg: Sequence[np.ndarray], energy: Sequence[np.ndarray], opts) -> tuple[list, list]:
    """(filters, projections) after ``opts.init_gn_iterations`` Gauss-Newton steps of
    ceil(``opts.init_cg_iterations`` / steps) Fletcher-Reeves CG iterations each, from zero
    filters. ``xs``: the first sample's blocks (C, H, Wh) complex64, unprojected; ``energy``:
    |Pᵀx|² of each block under the initial P (the filter's preconditioner)."""
    k, lam = len(xs), opts.projection_reg
    total_dim = sum(x.shape[0] for x in xs)
    f = [np.zeros((p.shape[1],) + x.shape[1:], np.complex64) for x, p in zip(xs, projections)]
    ps = [np.array(p, np.float32) for p in projections]
    m_f = [preconditioner(e, r, opts.precond_data_param, opts.precond_reg_param) for e, r in zip(energy, reg)]
    m_p = [np.full(p.shape, opts.precond_proj_param * (2 * float(np.sum(np.abs(y) ** 2)) / total_dim + lam),
                   np.float32) for p, y in zip(ps, yfs)]
    diag = m_f + m_p
    cg_iterations = math.ceil(opts.init_cg_iterations / opts.init_gn_iterations)
    for _ in range(opts.init_gn_iterations):
        zs = [project(x, p) for x, p in zip(xs, ps)]
        f0 = [fi.copy() for fi in f]
        rhs_f = [(np.conj(z) * y).astype(np.complex64) for z, y in zip(zs, yfs)]
        rhs_p = [(_data_grad(np.conj(x), np.conj(g) * y) - lam * p).astype(np.float32)
                 for x, g, y, p in zip(xs, f0, yfs, ps)]
        x0 = f0 + [np.zeros_like(p) for p in ps]
        sol, _ = pcg(lambda v: _lhs(v, k, xs, zs, f0, reg, lam), rhs_f + rhs_p,
                     lambda r: [ri / mi for ri, mi in zip(r, diag)], _dot_joint(k), x0, cg_iterations,
                     fletcher_reeves=True)
        f = [symmetrize(fi.astype(np.complex64)) for fi in sol[:k]]
        ps = [(p + d.real).astype(np.float32) for p, d in zip(ps, sol[k:])]
    return f, ps

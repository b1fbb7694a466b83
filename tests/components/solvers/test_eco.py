"""ECO's training against independent references: the normal equations' operator and its CG
solve against a dense solve, the regularization filter against the window it stands for, and
the first frame's Gauss-Newton against its own objective and a dense solve of one step."""
import numpy as np
import pytest
from scipy.signal import convolve2d

from dcfkit.components.solvers.eco_cg import (
    apply_regularization,
    inner,
    lhs_filter,
    pcg,
    regularization_filter,
)
from dcfkit.components.solvers.eco_joint import _dot_joint, pca_projection, project, train_joint
from dcfkit.numerics import fourier_series as fs


def hermitian_half(rng, c, h, w):
    """The half spectrum of a real (c, h, w) map (h, w odd)."""
    return fs.half(fs.centred_dft(rng.standard_normal((c, h, w)))).astype(np.complex64)


def test_regularization_filter_is_the_sparse_windows_dft():
    reg = regularization_filter((61, 61), (20, 12), 1e-4, 1e-2, 2, 0.05)
    assert reg.shape[0] % 2 == 1 and reg.shape[1] % 2 == 1
    assert np.allclose(reg, reg[::-1, ::-1])  # a real even window: symmetric coefficients
    # each kept coefficient is the real part of the window's DFT / N, summed here term by term
    n = np.arange(61) - 30
    window = (1e-2 - 1e-4) * ((n[:, None] / 10.0) ** 2 + (n[None, :] / 6.0) ** 2) + 1e-4
    idx = np.arange(61)
    for dy in range(-(reg.shape[0] // 2), reg.shape[0] // 2 + 1):
        for dx in range(-(reg.shape[1] // 2), reg.shape[1] // 2 + 1):
            if (dy, dx) == (0, 0):
                continue
            coef = np.sum(window * np.exp(-2j * np.pi * (dy * idx[:, None] + dx * idx[None, :]) / 61)).real / 61**2
            kept = reg[dy + reg.shape[0] // 2, dx + reg.shape[1] // 2]
            assert kept == pytest.approx(coef, abs=1e-7) or (kept == 0 and abs(coef) < 0.05 * reg.max())
    # the window the coefficients describe is least in the middle of the sample (where the
    # target is, at t = π), about reg_window_min there
    grid = np.zeros((61, 61))
    grid[30 - reg.shape[0] // 2:31 + reg.shape[0] // 2, 30 - reg.shape[1] // 2:31 + reg.shape[1] // 2] = reg
    spatial = np.fft.ifft2(np.fft.ifftshift(grid)).real * 61**2
    assert np.unravel_index(np.argmin(spatial), spatial.shape) == (30, 30)
    assert spatial.min() == pytest.approx(1e-4, abs=2e-4) and spatial[0, 30] > 20 * spatial.min()


def test_regularization_is_the_double_convolution_of_the_full_spectrum():
    rng = np.random.default_rng(0)
    hf = hermitian_half(rng, 2, 9, 11)
    reg = regularization_filter((45, 45), (12, 16), 1e-4, 1e-2, 2, 0.05)
    out = apply_regularization(hf, reg)
    for c in range(2):
        full = fs.full(hf[c])
        twice = convolve2d(convolve2d(full, reg, "full"), reg, "valid")  # Wᴴ W as full then valid
        assert np.allclose(out[c], fs.half(twice), atol=1e-5)


def hermitian_coordinates(template):
    """pack/unpack between real vectors and lists of half spectra whose kx = 0 column is
    conjugate symmetric (the spectra of real maps), and the metric that is the full spectra's
    inner product in those coordinates."""
    def pack(parts):
        out = []
        for p in parts:
            dc = (p.shape[-2] - 1) // 2
            body, col = p[..., :-1].ravel(), p[..., :dc, -1].ravel()
            out += [body.real, body.imag, col.real, col.imag, p[..., dc, -1].real.ravel()]
        return np.concatenate(out)

    def unpack(v):
        parts, at = [], 0
        for t in template:
            dc = (t.shape[-2] - 1) // 2
            p = np.zeros(t.shape, complex)
            nb, nc, nd = t[..., :-1].size, t[..., :dc, -1].size, t[..., dc, -1].size
            p[..., :-1] = (v[at:at + nb] + 1j * v[at + nb:at + 2 * nb]).reshape(t[..., :-1].shape)
            at += 2 * nb
            p[..., :dc, -1] = (v[at:at + nc] + 1j * v[at + nc:at + 2 * nc]).reshape(t[..., :dc, -1].shape)
            at += 2 * nc
            p[..., dc, -1] = v[at:at + nd].reshape(t[..., dc, -1].shape)
            at += nd
            parts.append(fs.symmetrize(p))
        return parts

    dcs = pack([_dc_mask(t) for t in template])
    metric = np.where(dcs > 0, 1.0, 2.0)
    return pack, unpack, metric


def _dc_mask(t):
    m = np.zeros(t.shape, complex)
    m[..., (t.shape[-2] - 1) // 2, -1] = 1
    return m


def dense(op, template):
    """The real matrix of ``op`` in :func:`hermitian_coordinates`."""
    pack, unpack, metric = hermitian_coordinates(template)
    n = len(pack([np.zeros(t.shape, complex) for t in template]))
    return np.stack([pack(op(unpack(e))) for e in np.eye(n)], axis=1), pack, unpack, metric


def test_cg_converges_to_the_dense_solution_of_the_normal_equations():
    rng = np.random.default_rng(1)
    samples = [np.stack([hermitian_half(rng, 2, 7, 7) for _ in range(3)]),
               np.stack([hermitian_half(rng, 1, 5, 5) for _ in range(3)])]
    weights = np.array([0.5, 0.3, 0.2], np.float32)
    reg = [regularization_filter((35, 35), (10, 10), 0.2, 1.0, 2, 0.05)] * 2
    labels = [fs.half(fs.centred_dft(rng.standard_normal((n, n)))) for n in (7, 5)]
    rhs = [np.conj(np.einsum("n,ndhw->dhw", weights, x)) * y for x, y in zip(samples, labels)]
    op = lambda f: lhs_filter([np.asarray(b, np.complex64) for b in f], samples, weights, reg)  # noqa: E731
    template = [np.zeros((2, 7, 4)), np.zeros((1, 5, 3))]
    matrix, pack, unpack, metric = dense(op, template)
    gram = metric[:, None] * matrix  # symmetric: the operator is self-adjoint in the full spectra's product
    assert np.allclose(gram, gram.T, atol=1e-5 * np.abs(gram).max())
    # the same operator written independently: Σ_n w_n (sample n's ridge data term) + the regularization
    zero = [np.zeros((1, 1))] * 2

    def independent(f):
        parts = [ridge_operator([x[n].astype(complex) for x in samples], zero)(f) for n in range(3)]
        smooth = ridge_operator([np.zeros(x.shape[1:], complex) for x in samples], reg)(f)
        return [sum(w * p[k] for w, p in zip(weights, parts)) + smooth[k] for k in range(2)]

    assert np.allclose(dense(independent, template)[0], matrix, atol=1e-5 * np.abs(matrix).max())
    solution = unpack(np.linalg.solve(matrix, pack(rhs)))
    x, _ = pcg(op, [r.astype(np.complex64) for r in rhs], lambda r: r, inner,
               [np.zeros(t.shape, np.complex64) for t in template], 200, fletcher_reeves=True)
    for got, want in zip(x, solution):
        assert np.allclose(got, want, rtol=1e-3, atol=1e-4 * np.abs(want).max())
    # warm start with Polak-Ribière and a remembered direction reaches it too
    x1, state = pcg(op, [r.astype(np.complex64) for r in rhs], lambda r: r, inner,
                    [np.zeros(t.shape, np.complex64) for t in template], 5, fletcher_reeves=False)
    x2, _ = pcg(op, [r.astype(np.complex64) for r in rhs], lambda r: r, inner, x1, 200, False, 0.6, state)
    for got, want in zip(x2, solution):
        assert np.allclose(got, want, rtol=1e-3, atol=1e-4 * np.abs(want).max())


def objective(xs, yfs, ps, f, reg, lam):
    """‖Σ_k (Pᵀx_k) f_k - y‖² + Σ_k ‖W f_k‖² + λ Σ_k ‖P_k‖², over full spectra."""
    out = (max(y.shape[0] for y in yfs), 2 * max(y.shape[1] for y in yfs) - 1)
    r = -fs.full(yfs[0]).astype(complex)
    total = 0.0
    for x, y, p, fk, rk in zip(xs, yfs, ps, f, reg):
        resp = fs.full(np.sum(project(x, p) * fk, axis=0))
        py, px = (out[0] - resp.shape[0]) // 2, (out[1] - resp.shape[1]) // 2
        r[py:out[0] - py, px:out[1] - px] += resp
        for c in range(fk.shape[0]):
            total += np.sum(np.abs(convolve2d(fs.full(fk[c]), rk, "full")) ** 2)
        total += lam * np.sum(p**2)
    return float(np.sum(np.abs(r) ** 2) + total)


class Opts:
    projection_reg = 1e-3
    init_gn_iterations = 1
    init_cg_iterations = 40
    precond_data_param, precond_reg_param, precond_proj_param = 0.75, 0.25, 40.0


def joint_problem(seed=2):
    rng = np.random.default_rng(seed)
    maps = [rng.standard_normal((4, 9, 9)).astype(np.float32), rng.standard_normal((3, 7, 7)).astype(np.float32)]
    xs = [fs.half(fs.centred_dft(m)).astype(np.complex64) for m in maps]
    g = np.exp(-0.5 * ((np.arange(9) - 4) ** 2)[:, None] / 1.5 - 0.5 * ((np.arange(9) - 4) ** 2)[None] / 1.5)
    y = fs.half(fs.centred_dft(np.fft.ifftshift(g))).astype(np.complex64)
    yfs = [y, y[1:-1, 1:]]
    reg = [regularization_filter((27, 27), (8, 8), 0.2, 1.0, 2, 0.05)] * 2  # well conditioned for float32 CG
    ps = [pca_projection(m, 2) for m in maps]
    return xs, yfs, ps, reg


def test_gauss_newton_lowers_the_joint_objective():
    xs, yfs, ps, reg = joint_problem()
    energy = [np.abs(project(x, p)) ** 2 for x, p in zip(xs, ps)]
    zero = [np.zeros((p.shape[1],) + x.shape[1:]) for x, p in zip(xs, ps)]
    losses = [objective(xs, yfs, ps, zero, reg, Opts.projection_reg)]
    for steps in (1, 3, 6):
        opts = type("O", (Opts,), {"init_gn_iterations": steps, "init_cg_iterations": 40 * steps})
        f, p = train_joint(xs, yfs, ps, reg, energy, opts)
        losses.append(objective(xs, yfs, p, f, reg, Opts.projection_reg))
    assert losses[1] < 0.5 * losses[0]
    assert losses[3] <= losses[2] <= losses[1] * 1.0001


def ridge_operator(zs, reg):
    """f -> Zᴴ (Σ_k Z_k f_k) + Wᴴ W f on full spectra, written independently of the solver:
    each block's response padded into the largest grid, the regularization two 2-D
    convolutions (full, then valid) of each channel."""
    def op(f):
        fulls = [fs.full(fk) for fk in f]
        out_shape = max(z.shape[-2] for z in zs), 2 * max(z.shape[-1] for z in zs) - 1
        total = np.zeros(out_shape, complex)
        for z, fk in zip(zs, fulls):
            resp = np.sum(fs.full(z) * fk, axis=0)
            py, px = (out_shape[0] - resp.shape[0]) // 2, (out_shape[1] - resp.shape[1]) // 2
            total[py:out_shape[0] - py, px:out_shape[1] - px] += resp
        out = []
        for z, fk, r in zip(zs, fulls, reg):
            py, px = (out_shape[0] - fk.shape[-2]) // 2, (out_shape[1] - fk.shape[-1]) // 2
            data = np.conj(fs.full(z)) * total[py:out_shape[0] - py, px:out_shape[1] - px]
            smooth = np.stack([convolve2d(convolve2d(c, r, "full"), r, "valid") for c in fk])
            out.append(fs.half(data + smooth))
        return out
    return op


def test_one_gauss_newton_step_solves_the_filters_ridge_problem():
    """From f = 0 the first step's filter is the ridge solution on the PCA-projected sample
    (ΔP's equations decouple: λ ΔP = -λ P, which λ = 1e-7 leaves for later steps)."""
    xs, yfs, ps, reg = joint_problem(3)
    zs = [project(x, p).astype(complex) for x, p in zip(xs, ps)]
    template = [np.zeros((p.shape[1],) + x.shape[1:]) for x, p in zip(xs, ps)]
    matrix, pack, unpack, metric = dense(ridge_operator(zs, reg), template)
    want = unpack(np.linalg.solve(matrix, pack([np.conj(z) * y for z, y in zip(zs, yfs)])))
    opts = type("O", (Opts,), {"init_gn_iterations": 1, "init_cg_iterations": 600, "projection_reg": 1e-7})
    f, p = train_joint(xs, yfs, ps, reg, [np.ones(z.shape, np.float32) for z in zs], opts)
    for got, w in zip(f, want):
        assert np.allclose(got, w, rtol=1e-3, atol=1e-3 * np.abs(w).max())
    assert _dot_joint(len(f))(f + p, f + p) > 0

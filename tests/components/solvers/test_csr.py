"""admm_csr against a dense constrained least-squares solve, and its running average."""
import numpy as np
import pytest

from dcfkit.components.solvers import ADMMCsr, CSRParams, csr_filter
from dcfkit.components.solvers.csr import constrained_rows
from dcfkit.numerics.fft import Backend, make_fft

FFT = make_fft("scipy")


def correlation_matrix(x: np.ndarray) -> np.ndarray:
    """Dense (K, K) A with A h = the circular correlation R(τ) = Σ_p h(p) x(p + τ), built
    from unit vectors by the definition (no FFT)."""
    H, W = x.shape
    A = np.zeros((H * W, H * W))
    for ty in range(H):
        for tx in range(W):
            A[ty * W + tx] = np.roll(x, (-ty, -tx), axis=(0, 1)).ravel()  # row τ: x(p + τ) over p
    return A


def dense_solution(x, y, mask, lam):
    """argmin ½‖A h - y‖² + λ/2 ‖h‖² over h zero outside the mask, by the normal equations."""
    A = correlation_matrix(x)[:, mask.ravel()]
    h_s = np.linalg.solve(A.T @ A + lam * np.eye(A.shape[1]), A.T @ y.ravel())
    h = np.zeros(mask.size)
    h[mask.ravel()] = h_s
    return h.reshape(mask.shape)


@pytest.mark.parametrize("lam", [0.05, 0.5])
def test_many_iterations_converge_to_the_dense_constrained_solution(lam):
    rng = np.random.default_rng(0)
    shape = (8, 10)
    x = rng.standard_normal((2, *shape)).astype(np.float32)
    y = np.exp(-0.5 * (np.minimum(np.arange(8), 8 - np.arange(8))[:, None] ** 2
                       + np.minimum(np.arange(10), 10 - np.arange(10))[None, :] ** 2)).astype(np.float32)
    mask = np.zeros(shape, bool)
    mask[2:6, 3:8] = True
    w2 = np.where(mask, 0, np.inf).astype(np.float32)
    p = CSRParams(iterations=400, mu0=5, beta=3, mu_max=20, lam=lam)
    hf = csr_filter(FFT.rfft2(x).astype(np.complex64), FFT.rfft2(y).astype(np.complex64), w2, p, FFT)
    h = FFT.irfft2(hf, shape)
    for c in range(2):  # each channel its own problem
        expected = dense_solution(x[c].astype(float), y.astype(float), mask, lam)
        np.testing.assert_allclose(h[c], expected, atol=2e-4 * np.abs(expected).max())
    assert np.abs(h[:, ~mask]).max() < 1e-6 * np.abs(h).max()  # zero up to the transforms' rounding


def test_the_filter_is_averaged_over_frames_and_the_frame_filter_kept():
    rng = np.random.default_rng(1)
    shape = (6, 6)
    xs = [FFT.rfft2(rng.standard_normal((1, *shape)).astype(np.float32)).astype(np.complex64) for _ in range(2)]
    yf = FFT.rfft2(np.eye(6, dtype=np.float32)).astype(np.complex64)
    w2 = np.zeros(shape, np.float32)
    solver = ADMMCsr(CSRParams(learning_rate=0.25))
    first = solver.train(xs[0], yf, w2, 0.0, FFT)
    second = solver.train(xs[1], yf, w2, 0.0, FFT)
    np.testing.assert_allclose(first, csr_filter(xs[0], yf, w2, solver.params, FFT))
    np.testing.assert_allclose(solver.frame_filter, csr_filter(xs[1], yf, w2, solver.params, FFT))
    np.testing.assert_allclose(second, 0.75 * first + 0.25 * solver.frame_filter, rtol=1e-6)
    solver.reset()
    assert solver.model is None and solver.frame_filter is None


def test_the_constrained_band_runs_from_the_first_to_the_last_row_the_mask_opens():
    w2 = np.full((9, 5), np.inf, np.float32)
    assert constrained_rows(w2) == slice(0, 0)
    w2[2, 1] = w2[6, 4] = 0.5  # two separated rows: the band holds both and the rows between
    assert constrained_rows(w2) == slice(2, 7)
    w2[8, 0] = np.nan  # refused by the regularizer's contract; inside, so that it reaches the filter
    assert constrained_rows(w2) == slice(2, 9)


class WholeTransforms(type(FFT)):
    """scipy's transforms with the band ones computed whole (the Backend's)."""

    rfft2_rows, irfft2_rows = Backend.rfft2_rows, Backend.irfft2_rows


@pytest.mark.parametrize("mask_rows", [(3, 9), (0, 16), (5, 6), (0, 0), (2, 4, 11, 13)])
def test_the_filter_is_the_one_computed_with_whole_transforms(mask_rows):
    """Sparing the rows outside the mask changes no value of the filter: masks of a band, every
    row, one row, none, and two separated groups."""
    rng = np.random.default_rng(len(mask_rows))
    shape = (16, 14)
    mask = np.zeros(shape, bool)
    for top, bottom in zip(mask_rows[::2], mask_rows[1::2]):
        mask[top:bottom, 2:11] = True
    w2 = np.where(mask, rng.uniform(0, 1, shape), np.inf).astype(np.float32)
    xf = FFT.rfft2(rng.standard_normal((3, *shape)).astype(np.float32)).astype(np.complex64)
    yf = FFT.rfft2(rng.standard_normal(shape).astype(np.float32)).astype(np.complex64)
    p = CSRParams()
    assert np.array_equal(csr_filter(xf, yf, w2, p, FFT), csr_filter(xf, yf, w2, p, WholeTransforms()))

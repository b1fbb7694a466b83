"""Detection (Eq. 12), peak and local maxima against brute force."""
import itertools

import numpy as np
import pytest

from dcfkit.numerics import peak_kernels
from dcfkit.numerics.fft import make_fft
from dcfkit.numerics.response import local_maxima, response, subpixel_peak, wrap


@pytest.mark.parametrize("backend", ["scipy", "pyfftw"])
def test_response_is_circular_cross_correlation(backend):
    rng = np.random.default_rng(0)
    fft = make_fft(backend)
    C, H, W = 3, 7, 6
    h = rng.standard_normal((C, H, W)).astype(np.float32)
    s = rng.standard_normal((2, C, H, W)).astype(np.float32)  # two search scales
    got = response(fft.rfft2(h), fft.rfft2(s), (H, W), fft)
    for k in range(2):
        for ty, tx in itertools.product(range(H), range(W)):
            brute = sum(h[c, y, x] * s[k, c, (y + ty) % H, (x + tx) % W]
                        for c in range(C) for y in range(H) for x in range(W))
            assert got[k, ty, tx] == pytest.approx(brute, abs=1e-4)


@pytest.mark.parametrize("size, dtype", [(3, np.float32), (3, np.float64), (5, np.float32), (7, np.float64)])
def test_local_maxima_match_brute_force(size, dtype):
    rng = np.random.default_rng(1)
    r = rng.standard_normal((9, 11)).astype(dtype)
    rows, cols = local_maxima(r, size)
    H, W = r.shape
    brute = []
    offsets = range(-(size // 2), size // 2 + 1)
    for y, x in itertools.product(range(H), range(W)):
        neigh = [r[(y + dy) % H, (x + dx) % W] for dy in offsets for dx in offsets if dy or dx]
        if r[y, x] >= max(neigh):
            brute.append((y, x))
    assert sorted(zip(rows.tolist(), cols.tolist())) == sorted(brute)
    values = r[rows, cols]
    assert np.all(np.diff(values) <= 0)  # highest first


def test_flat_map_has_no_local_maxima():
    rows, _ = local_maxima(np.ones((5, 5), np.float32))
    assert rows.size == 0


@pytest.mark.parametrize("true_dy,true_dx", [(0.3, -0.2), (-2.4, 3.1), (5.45, -5.0)])
def test_subpixel_peak_recovers_the_peak_of_a_band_limited_map(true_dy, true_dx):
    """A sum of low-frequency cosines is its own Fourier interpolant; its maximum is known."""
    H, W = 16, 15
    y = np.arange(H)[:, None]
    x = np.arange(W)[None, :]
    r = sum(np.cos(2 * np.pi * k * (y - true_dy) / H) / k + np.cos(2 * np.pi * k * (x - true_dx) / W) / k
            for k in (1, 2, 3))
    got_y, got_x, value = subpixel_peak(r.astype(np.float32))
    assert got_y == pytest.approx(true_dy, abs=1e-3)
    assert got_x == pytest.approx(true_dx, abs=1e-3)
    assert value == pytest.approx(2 * (1 + 1 / 2 + 1 / 3), rel=1e-4)
    assert value >= r.max()


def test_wrap_gives_signed_offsets():
    assert wrap(np.arange(6), 6).tolist() == [0, 1, 2, -3, -2, -1]
    assert wrap(np.arange(5), 5).tolist() == [0, 1, 2, -2, -1]


def test_shift_spectrum_matches_roll_for_whole_cells():
    from dcfkit.numerics.response import shift_spectrum

    fft = make_fft("scipy")
    x = np.random.default_rng(2).standard_normal((3, 8, 10)).astype(np.float32)
    shifted = fft.irfft2(shift_spectrum(fft.rfft2(x), 2, -3, (8, 10)), (8, 10))
    np.testing.assert_allclose(shifted, np.roll(x, (-2, 3), axis=(1, 2)), atol=1e-5)


def test_subpixel_peak_of_a_map_whose_hessian_has_a_cross_term():
    """cos(a·dy) + cos(b·dx) + cos(a·dy + b·dx), dy = y - y0, dx = x - x0: band-limited, maximal (3) at
    (y0, x0), with ∂²/∂y∂x = -ab ≠ 0 there, so a Newton step without the cross term misses it."""
    H, W, y0, x0 = 16, 16, 0.4, 0.35
    y = np.arange(H)[:, None]
    x = np.arange(W)[None, :]
    a, b = 2 * np.pi / H, 2 * np.pi / W
    r = np.cos(a * (y - y0)) + np.cos(b * (x - x0)) + np.cos(a * (y - y0) + b * (x - x0))
    got_y, got_x, value = subpixel_peak(r.astype(np.float32))
    assert got_y == pytest.approx(y0, abs=1e-3) and got_x == pytest.approx(x0, abs=1e-3)
    assert value == pytest.approx(3.0, rel=1e-4)


def test_peak_moments_are_the_matrix_products():
    """peak_kernels.moments (compiled, summed in index order) against numpy's matrix products:
    m_ab = (fy^a ey) @ S @ (fx^b ex); and a 2x2 case by hand."""
    rng = np.random.default_rng(3)
    s = rng.standard_normal((7, 5)) + 1j * rng.standard_normal((7, 5))
    ey, ex = np.exp(1j * rng.standard_normal(7)), np.exp(1j * rng.standard_normal(5))
    fy, fx = rng.standard_normal(7), rng.standard_normal(5)
    got = peak_kernels.moments(s, ey, ex, fy, fx)
    want = [(fy**a * ey) @ s @ (fx**b * ex) for a, b in ((0, 0), (1, 0), (0, 1), (2, 0), (0, 2), (1, 1))]
    np.testing.assert_allclose(got, want, rtol=1e-12)
    one = np.ones(2, complex)
    m = peak_kernels.moments(np.array([[1, 2j], [3, 4]]), one, one, np.array([0.0, 1.0]), np.array([2.0, 3.0]))
    assert m[0] == 8 + 2j and m[1] == 7 and m[2] == 2 * 1 + 3 * 2j + 2 * 3 + 3 * 4  # Σ S, row 1, fx-weighted

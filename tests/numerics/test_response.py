"""Detection (Eq. 12) and its peak against brute force."""
import itertools

import numpy as np
import pytest

from dcfkit.numerics import peak_kernels
from dcfkit.numerics.fft import make_fft
from dcfkit.numerics.response import (
    _signed_frequencies,
    newton_peak,
    response,
    shift_spectrum,
    subpixel_peak,
    wrap,
)


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


# The authors' MATLAB detail this option reproduces, against an independent reference (the
# line worked out by hand or re-run in numpy, a brute-force loop, a dense solve). file.m:line
# cites ../shared/reference/DR2Track/DR2Track1 unless STRCF's (../shared/reference/STRCF) is named.
# --------------------------------------------------------------------------------------------
# the authors' MATLAB: response: the authors' frequency grid, resp_newton, shift_sample
# --------------------------------------------------------------------------------------------

def matlab_k(n):
    """tracker.m:18: ky = circshift(-floor((n-1)/2):ceil((n-1)/2), [1, -floor((n-1)/2)]); a row
    vector, so the shift is along its columns: np.roll by -floor((n-1)/2)."""
    return np.roll(np.arange(-((n - 1) // 2), int(np.ceil((n - 1) / 2)) + 1), -((n - 1) // 2))


@pytest.mark.parametrize("n", [7, 8, 50, 1, 2])
def test_signed_frequencies_are_the_authors_grid(n):
    assert np.array_equal(_signed_frequencies(n), matlab_k(n))


def test_signed_frequencies_hand_values():
    assert _signed_frequencies(8).tolist() == [0, 1, 2, 3, 4, -3, -2, -1]   # Nyquist +4 (fftfreq: -4)
    assert _signed_frequencies(7).tolist() == [0, 1, 2, 3, -3, -2, -1]


def cosine_peak_map(h, w, dy, dx):
    """Σ_k cos(2πk(y - dy)/h)/k + cos(2πk(x - dx)/w)/k, k = 1..3: band-limited (so its own
    trigonometric interpolant), maximal, 2(1 + 1/2 + 1/3), at (dy, dx) only."""
    y = np.arange(h)[:, None]
    x = np.arange(w)[None, :]
    return sum(np.cos(2 * np.pi * k * (y - dy) / h) / k + np.cos(2 * np.pi * k * (x - dx) / w) / k
               for k in (1, 2, 3))


def ridge_map(y0, x0, n=16):
    """cos(2π(3(y-y0) + 4(x-x0))/n) + cos(2π(2(y-y0) + 3(x-x0))/n): band-limited; both cosines are 1
    only where 3Y + 4X ≡ 0 and 2Y + 3X ≡ 0 (mod n), a system of determinant 1, so (y0, x0) is the
    one maximum (2) on the torus. Its Hessian ∝ -[[13, 18], [18, 25]] (eigenvalues 38 and 0.03) is
    nearly flat along one direction, along which whole cells far from the peak stay high."""
    y = np.arange(n)[:, None] - y0
    x = np.arange(n)[None, :] - x0
    return np.cos(2 * np.pi * (3 * y + 4 * x) / n) + np.cos(2 * np.pi * (2 * y + 3 * x) / n)


def signed(i, n):
    return (i + n // 2) % n - n // 2


@pytest.mark.parametrize("shape", [(16, 15), (15, 16)])
@pytest.mark.parametrize("true_dy, true_dx", [(0.3, -0.2), (-2.4, 3.1), (5.45, -5.0)])
def test_newton_peak_finds_an_off_grid_peak(shape, true_dy, true_dx):
    r = cosine_peak_map(*shape, true_dy, true_dx).astype(np.float32)
    best, dy, dx, value = newton_peak(r[None])
    assert best == 0
    assert dy == pytest.approx(true_dy, abs=1e-4) and dx == pytest.approx(true_dx, abs=1e-4)
    assert value == pytest.approx(2 * (1 + 1 / 2 + 1 / 3), rel=1e-5)


def test_newton_peak_breaks_grid_ties_in_column_major_order():
    # resp_newton.m:3-4 takes max over rows, then over columns: of equal maxima the one in the
    # first column wins (row-major argmax would pick (0, 5), the first in reading order)
    r = np.zeros((8, 9), np.float32)
    r[0, 5] = r[3, 2] = r[6, 2] = 1.0
    best, dy, dx, value = newton_peak(r[None], iterations=0)
    assert (best, dy, dx, value) == (0, pytest.approx(3.0), pytest.approx(2.0), pytest.approx(1.0))
    # a tie in the same column: the lower row index
    r = np.zeros((8, 9), np.float32)
    r[6, 2] = r[2, 2] = 1.0
    assert newton_peak(r[None], iterations=0)[1:3] == (pytest.approx(2.0), pytest.approx(2.0))


def test_newton_peak_picks_the_map_with_the_highest_refined_value():
    """Map 0 peaks on the grid at 1.98; map 1 is the ridge map with its maximum 2 at (0.2, 0),
    whose highest sample is only 1.9754 (at (3, -2)): resp_newton compares the refined values."""
    r0 = 0.99 * (np.cos(2 * np.pi * np.arange(16)[:, None] / 16) + np.cos(2 * np.pi * np.arange(16)[None, :] / 16))
    r1 = ridge_map(0.2, 0.0)
    assert r0.max() > r1.max()  # by the grid, map 0 would win
    best, dy, dx, value = newton_peak(np.stack([r0, r1]).astype(np.float32))
    assert best == 1
    assert (dy, dx) == (pytest.approx(0.2, abs=1e-4), pytest.approx(0.0, abs=1e-4))
    assert value == pytest.approx(2.0, rel=1e-5)


def test_newton_peak_falls_back_to_the_grid_maximum():
    """r = cos(2πy/16) + f(x), f(x) = cos(θ(x - s)) + c cos(7θ(x - s)), θ = 2π/16, s = 0.2, c = -0.03.
    Its grid maximum is (0, 0) (checked), but along x f has a local MINIMUM at s (f''(s) = -θ² - 49cθ²
    > 0), and Newton's steps from x = 0 converge to it (the loop below, on the analytic f): the point
    (0, s) is a saddle of value 2 + c = 1.97, below the grid value r(0, 0) = 1.97134; resp_newton.m:53-55
    then keeps the grid maximum."""
    theta, s, c = 2 * np.pi / 16, 0.2, -0.03
    y = np.arange(16)[:, None]
    x = np.arange(16)[None, :]
    r = np.cos(2 * np.pi * y / 16) + np.cos(theta * (x - s)) + c * np.cos(7 * theta * (x - s))
    assert np.unravel_index(np.argmax(r), r.shape) == (0, 0)
    u = 0.0
    for _ in range(5):  # Newton on f alone (r is separable and cos(2πy/16) is stationary at y = 0)
        d1 = -theta * np.sin(theta * (u - s)) - 7 * c * theta * np.sin(7 * theta * (u - s))
        d2 = -theta**2 * np.cos(theta * (u - s)) - 49 * c * theta**2 * np.cos(7 * theta * (u - s))
        u -= d1 / d2
    assert u == pytest.approx(s, abs=1e-6) and 2 + c < r[0, 0]
    best, dy, dx, value = newton_peak(r[None].astype(np.float32))
    assert (best, dy, dx) == (0, 0.0, 0.0)
    assert value == pytest.approx(r[0, 0], rel=1e-6)


def test_newton_peak_may_leave_the_grid_maximum_cell_unlike_subpixel_peak():
    """The ridge map with its maximum at (0.2, 0): its highest sample (by 0.015) is (3, -2), 2.8 cells
    away. resp_newton's unbounded steps reach the true maximum; subpixel_peak stays within one cell."""
    r = ridge_map(0.2, 0.0).astype(np.float32)
    i, j = np.unravel_index(np.argmax(r), r.shape)
    grid = (signed(i, 16), signed(j, 16))
    assert grid == (3, -2)
    _, dy, dx, value = newton_peak(r[None])
    assert (dy, dx, value) == (pytest.approx(0.2, abs=1e-4), pytest.approx(0.0, abs=1e-4), pytest.approx(2.0))
    sy, sx, _ = subpixel_peak(r)
    assert abs(sy - grid[0]) <= 1 and abs(sx - grid[1]) <= 1


def resp_newton_sums(maps, iterations, spectra=None):
    """STRCF's resp_newton.m (implementation/resp_newton.m:3-60, the multi-scale version), with its
    matrix products exp_iky * R * exp_ikx written as double sums over the full spectrum R = fft2(r):
    S_ab = Σ_k,l ky^a kx^b R e^{i(ky y + kx x)}; grad = -imag(S_10, S_01); H_yy = real(-S_20 + i S_00)
    (their ival term, lines 34-36), H_xx = real(-S_02 + i S_00), H_xy = -real(S_11). Returns the scale
    (first maximum of the values, line 58), the signed displacement in cells (lines 59-60) and the value.
    ``spectra``: R per map as DR²Track's code has it (responsef, complex when its filter is), not fft2(r)."""
    n_maps, h, w = maps.shape
    ky, kx = matlab_k(h)[:, None], matlab_k(w)[None, :]
    outcomes = []
    for i, r in enumerate(maps.astype(np.float64)):
        spectrum = np.fft.fft2(r) if spectra is None else spectra[i]
        row = np.argmax(r, axis=0)  # lines 3-7: the first maximum of each column, then the first column
        col = int(np.argmax(r[row, np.arange(w)]))
        row = int(row[col])
        init = r[row, col]
        y0 = 2 * np.pi * (np.mod(row + (h - 1) // 2, h) - (h - 1) // 2) / h
        x0 = 2 * np.pi * (np.mod(col + (w - 1) // 2, w) - (w - 1) // 2) / w
        y, x = y0, x0

        def s(a, b):
            return np.sum(ky**a * kx**b * spectrum * np.exp(1j * (ky * y + kx * x)))

        for _ in range(iterations):
            gy, gx = -s(1, 0).imag, -s(0, 1).imag
            hyy, hxx, hxy = (-s(2, 0) + 1j * s(0, 0)).real, (-s(0, 2) + 1j * s(0, 0)).real, -s(1, 1).real
            det = hyy * hxx - hxy * hxy
            y, x = y - (hxx * gy - hxy * gx) / det, x - (hyy * gx - hxy * gy) / det
        value = s(0, 0).real / (h * w)
        if value < init:  # lines 53-56
            y, x, value = y0, x0, init
        outcomes.append((y, x, value))
    best = int(np.argmax([v for _, _, v in outcomes]))
    y, x, value = outcomes[best]
    return best, (np.mod(y + np.pi, 2 * np.pi) - np.pi) / (2 * np.pi) * h, \
        (np.mod(x + np.pi, 2 * np.pi) - np.pi) / (2 * np.pi) * w, value


@pytest.mark.parametrize("shape", [(10, 12), (8, 8), (9, 12), (12, 9)])
@pytest.mark.parametrize("iterations", [1, 2, 5])
def test_newton_peak_matches_resp_newton_on_maps_with_nyquist_content(shape, iterations):
    """Noisy peaked maps with an even side carry Nyquist content, where the authors' grid (Nyquist
    +n/2) makes the interpolant complex and their Hessian's extra i·S_00 term matters (before
    convergence: iterations 1 and 2)."""
    rng = np.random.default_rng(sum(shape) + iterations)
    h, w = shape
    maps = np.stack([cosine_peak_map(h, w, *rng.uniform(-2, 2, 2)) * a + 0.3 * rng.standard_normal(shape)
                     for a in (1.0, 1.1, 0.9)]).astype(np.float32)
    best, dy, dx, value = newton_peak(maps, iterations)
    ref_best, ref_dy, ref_dx, ref_value = resp_newton_sums(maps, iterations)
    assert best == ref_best
    assert (dy, dx) == (pytest.approx(ref_dy, abs=1e-9), pytest.approx(ref_dx, abs=1e-9))
    assert value == pytest.approx(ref_value, rel=1e-9)


@pytest.mark.parametrize("shape, dy, dx", [((8, 10), 0.3, -1.7), ((8, 9), -2.5, 0.6), ((7, 10), 1.25, 2.5)])
def test_shift_spectrum_uses_the_authors_nyquist(shape, dy, dx):
    """shift_sample.m: xf .* exp(1i*shift(1)*ky) .* exp(1i*shift(2)*kx), shift = 2π (dy, dx)/size,
    on the FULL spectrum with the authors' ky, kx (Nyquist +n/2); dcfkit keeps half spectra."""
    h, w = shape
    x = np.random.default_rng(5).standard_normal((2, h, w))
    ky = matlab_k(h)[:, None]
    kx = matlab_k(w)[None, :]
    full = np.fft.fft2(x) * np.exp(1j * 2 * np.pi * dy / h * ky) * np.exp(1j * 2 * np.pi * dx / w * kx)
    got = shift_spectrum(np.fft.rfft2(x).astype(np.complex64), dy, dx, shape)
    tol = 2e-5 * np.abs(full).max()
    np.testing.assert_allclose(got, full[..., : w // 2 + 1], atol=tol)
    if h % 2 == 0:  # numpy's fftfreq (Nyquist -h/2) gives another shift: the case tells them apart
        numpy_ky = (np.fft.fftfreq(h) * h)[:, None]
        other = np.fft.fft2(x) * np.exp(1j * 2 * np.pi * dy / h * numpy_ky) * np.exp(1j * 2 * np.pi * dx / w * kx)
        assert np.abs(other - full).max() > 100 * tol


@pytest.mark.parametrize("shape, dy, dx", [((8, 10), 0.3, -1.7), ((7, 10), 1.25, 2.5)])
def test_whole_spectra_shift_as_the_authors_and_turn_complex(shape, dy, dx):
    """tracker.spectra full: shift_sample.m's product on the whole spectrum, so the shifted map of a
    real one is complex where an even side's Nyquist bins lose their symmetry (DR²Track's xf)."""
    h, w = shape
    x = np.random.default_rng(6).standard_normal((2, h, w))
    ky, kx = matlab_k(h)[:, None], matlab_k(w)[None, :]
    full = np.fft.fft2(x) * np.exp(1j * 2 * np.pi * dy / h * ky) * np.exp(1j * 2 * np.pi * dx / w * kx)
    got = shift_spectrum(np.fft.fft2(x).astype(np.complex64), dy, dx, shape, full=True)
    np.testing.assert_allclose(got, full, atol=2e-5 * np.abs(full).max())
    assert np.abs(np.fft.ifft2(got).imag).max() > 1e-3 * np.abs(x).max()  # no longer a real map


def test_newton_peak_refines_on_the_spectra_it_is_given():
    """DR²Track's resp_newton refines on responsef as computed: with a complex filter that is not
    fft2 of the real map. Given fft2 of the maps, the result is the default's."""
    rng = np.random.default_rng(9)
    h, w = 10, 12
    maps = np.stack([cosine_peak_map(h, w, *rng.uniform(-2, 2, 2)) * a + 0.3 * rng.standard_normal((h, w))
                     for a in (1.0, 1.1)]).astype(np.float32)
    assert newton_peak(maps, 5, np.fft.fft2(maps.astype(np.float64))) == newton_peak(maps, 5)
    spectra = np.fft.fft2(maps.astype(np.float64)) * (1 + 0.05j * rng.standard_normal((2, h, w)))
    best, dy, dx, value = newton_peak(maps, 5, spectra)
    ref_best, ref_dy, ref_dx, ref_value = resp_newton_sums(maps, 5, spectra)
    assert best == ref_best and (dy, dx) == (pytest.approx(ref_dy, abs=1e-9), pytest.approx(ref_dx, abs=1e-9))
    assert value == pytest.approx(ref_value, rel=1e-9)
    assert (dy, dx) != pytest.approx(newton_peak(maps, 5)[1:3], abs=1e-6)


def test_parabola_peak_by_hand():
    from dcfkit.numerics.response import parabola_peak  # only this test

    r = np.zeros((8, 10), np.float32)
    r[6, 2], r[5, 2], r[7, 2] = 1.0, 0.5, 0.7  # rows: a parabola through 0.5, 1, 0.7
    r[6, 1], r[6, 3] = 0.2, 0.6
    dy, dx = parabola_peak(r)
    assert dy == pytest.approx(6 + 0.5 * (0.7 - 0.5) / (2 - 0.7 - 0.5) - 8)  # 6.125 > 4: wrapped
    assert dx == pytest.approx(2 + 0.5 * (0.6 - 0.2) / (2 - 0.6 - 0.2))
    flat = np.zeros((5, 5), np.float32)
    flat[0, 0] = 1.0
    assert parabola_peak(flat) == (0.0, 0.0)


def every_step(r, iterations):
    """resp_newton's loop on one map, all ``iterations`` steps taken: (y, x) as angles."""
    h, w = r.shape
    ky, kx = _signed_frequencies(h), _signed_frequencies(w)
    flat = int(np.argmax(r.T))
    row, col = flat % h, flat // h
    y = 2 * np.pi * (((row + (h - 1) // 2) % h) - (h - 1) // 2) / h
    x = 2 * np.pi * (((col + (w - 1) // 2) % w) - (w - 1) // 2) / w
    y0, x0 = y, x
    spectrum = np.fft.fft2(r.astype(np.float64))
    moments = lambda y, x: peak_kernels.moments(spectrum, np.exp(1j * ky * y), np.exp(1j * kx * x),  # noqa: E731
                                                ky.astype(float), kx.astype(float))
    for _ in range(iterations):
        m = moments(y, x)
        gy, gx, ival = -m[1].imag, -m[2].imag, 1j * m[0]
        hyy, hxx, hxy = (-m[3] + ival).real, (-m[4] + ival).real, (-m[5]).real
        det = hyy * hxx - hxy * hxy
        with np.errstate(divide="ignore", invalid="ignore"):
            y, x = y - (hxx * gy - hxy * gx) / det, x - (hyy * gx - hxy * gy) / det
    value = moments(y, x)[0].real / (h * w)
    return (y, x) if value >= r[row, col] else (y0, x0)  # a step that lost: the grid maximum


@pytest.mark.parametrize("iterations", [5, 50, 51])
def test_newton_peak_stops_at_a_cycle_with_the_result_of_every_step(iterations):
    """BACF takes 50 steps; they reach a fixed point or a cycle of a few last-bit values within
    about ten. newton_peak stops there and takes the point the remaining steps would end on:
    the same bits as taking them all, whatever the parity of the steps left."""
    rng = np.random.default_rng(iterations)
    for trial in range(20):
        n = 24 + trial % 7
        r = cosine_peak_map(n, n, *rng.uniform(-3, 3, 2)) + 0.05 * rng.standard_normal((n, n))
        r = r.astype(np.float32)
        _, dy, dx, _ = newton_peak(r[None], iterations)
        y, x = every_step(r, iterations)
        assert dy == (np.mod(y + np.pi, 2 * np.pi) - np.pi) / (2 * np.pi) * n
        assert dx == (np.mod(x + np.pi, 2 * np.pi) - np.pi) / (2 * np.pi) * n

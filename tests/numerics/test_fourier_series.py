"""Fourier series on the continuous domain against independent references: numerical
integration of the cubic kernel, direct DFT sums, and a brute-force search of a series'
maximum."""
import numpy as np
import pytest
from scipy.integrate import quad

from dcfkit.numerics import fourier_series as fs


def keys_kernel(x, a):
    x = abs(x)
    if x <= 1:
        return (a + 2) * x**3 - (a + 3) * x**2 + 1
    if x < 2:
        return a * x**3 - 5 * a * x**2 + 8 * a * x - 4 * a
    return 0.0


@pytest.mark.parametrize("a", [-0.75, -0.5])
def test_cubic_spline_coefficients_are_the_kernels_fourier_transform(a):
    for f in [0.0, 0.01, 0.13, 0.37, 0.5, 0.9]:
        numeric = quad(lambda x: keys_kernel(x, a) * np.cos(2 * np.pi * f * x), -2, 2, points=[-1, 0, 1], limit=200)[0]
        assert fs.cubic_spline_fourier(np.array([f]), a)[0] == pytest.approx(numeric, abs=1e-9)


def test_interpolation_coefficients_are_centred_and_scaled():
    c = fs.interp_fourier(7, -0.75, centering=True)
    k = np.arange(7) - 3
    assert np.allclose(np.abs(c), fs.cubic_spline_fourier(k / 7, -0.75) / 7)
    assert np.allclose(np.angle(c[4:]), -np.pi * k[4:] / 7)


def direct_dft(x, ky, kx):
    h, w = x.shape
    n, m = np.arange(h)[:, None], np.arange(w)[None, :]
    return np.array([[np.sum(x * np.exp(-2j * np.pi * (a * n / h + b * m / w))) for b in kx] for a in ky])


def test_centred_dft_of_odd_and_even_maps():
    rng = np.random.default_rng(0)
    odd = rng.standard_normal((5, 7))
    assert np.allclose(fs.centred_dft(odd), direct_dft(odd, np.arange(5) - 2, np.arange(7) - 3))
    even = rng.standard_normal((4, 6))
    out = fs.centred_dft(even)
    assert out.shape == (5, 7)
    # the frequencies -N/2 .. N/2 - 1 of the DFT, then +N/2 as the conjugate mirror of -N/2
    assert np.allclose(out[:4, :6], direct_dft(even, np.arange(4) - 2, np.arange(6) - 3))
    assert np.allclose(out[4, :], np.conj(out[0, ::-1]))


def test_half_and_full_spectra_round_trip():
    x = np.random.default_rng(1).standard_normal((2, 5, 7))
    xf = fs.centred_dft(x)
    assert np.allclose(fs.full(fs.half(xf)), xf)


def test_sampling_evaluates_the_series_on_its_grid():
    rng = np.random.default_rng(2)
    xf = fs.centred_dft(rng.standard_normal((5, 7)))
    ky, kx = np.arange(5) - 2, np.arange(7) - 3
    n, m = 3, 5
    value = np.sum(xf * np.exp(2j * np.pi * (ky[:, None] * n / 5 + kx[None, :] * m / 7))).real
    assert fs.sample(xf)[n, m] == pytest.approx(value)


def gaussian_series(h, w, y0, x0, sigma):
    """Fourier coefficients of a periodic Gaussian bump at (y0, x0) cells on an (h, w) grid."""
    ky, kx = (np.arange(h) - (h - 1) // 2)[:, None], (np.arange(w) - (w - 1) // 2)[None, :]
    return (np.exp(-2 * np.pi**2 * sigma**2 * (ky**2 / h**2 + kx**2 / w**2))
            * np.exp(-2j * np.pi * (ky * y0 / h + kx * x0 / w)))


def brute_force_peak(xf, factor=40):
    h, w = xf.shape
    ys, xs = np.arange(h * factor) / factor, np.arange(w * factor) / factor
    ky, kx = (np.arange(h) - (h - 1) // 2), (np.arange(w) - (w - 1) // 2)
    left, right = np.exp(2j * np.pi * ys[:, None] * ky[None] / h), np.exp(2j * np.pi * kx[:, None] * xs[None] / w)
    values = (left @ xf @ right).real
    i, j = np.unravel_index(np.argmax(values), values.shape)
    return ys[i], xs[j]


@pytest.mark.parametrize("y0, x0", [(2.3, -4.6), (-7.45, 3.2), (0.5, 0.5)])
def test_newton_finds_the_maximum_of_a_shifted_gaussian(y0, x0):
    xf = gaussian_series(31, 29, y0, x0, sigma=2.5)
    dy, dx, best = fs.newton_maximum(xf[None], 5)
    assert best == 0
    assert dy == pytest.approx(y0, abs=1e-4) and dx == pytest.approx(x0, abs=1e-4)
    by, bx = brute_force_peak(xf)
    assert abs(((by + 15.5) % 31) - 15.5 - dy) <= 1 / 40 and abs(((bx + 14.5) % 29) - 14.5 - dx) <= 1 / 40


def test_newton_picks_the_scale_with_the_highest_maximum():
    low, high = 0.5 * gaussian_series(21, 21, 1.2, 0.3, 2.0), gaussian_series(21, 21, -3.3, 2.7, 2.0)
    dy, dx, best = fs.newton_maximum(np.stack([low, high]), 5)
    assert best == 1 and dy == pytest.approx(-3.3, abs=1e-4) and dx == pytest.approx(2.7, abs=1e-4)


def test_shift_moves_the_series():
    xf = gaussian_series(15, 15, 0.0, 0.0, 1.5)
    moved = fs.full(fs.shift(fs.half(xf), 2 * np.pi * 2.5 / 15, 2 * np.pi * -1.25 / 15))
    dy, dx, _ = fs.newton_maximum(moved[None], 5)
    # shift_sample multiplies by e^{i k d}: the bump moves by -d
    assert dy == pytest.approx(-2.5, abs=1e-4) and dx == pytest.approx(1.25, abs=1e-4)

"""FFT backends against numpy.fft; they must not touch or alias their inputs."""
import numpy as np
import pytest

from dcfkit.numerics.fft import make_fft, multiply


@pytest.mark.parametrize("backend", ["scipy", "pyfftw"])
@pytest.mark.parametrize("shape", [(3, 6, 5), (2, 8, 8)])
def test_round_trip_matches_numpy_and_leaves_inputs_alone(backend, shape):
    fft = make_fft(backend)
    x = np.random.default_rng(0).standard_normal(shape).astype(np.float32)
    x_before = x.copy()
    for _ in range(2):  # the second call reuses pyfftw's cached plans
        xf = fft.rfft2(x)
        xf_before = xf.copy()
        back = fft.irfft2(xf, shape[1:])
        assert np.array_equal(x, x_before) and np.array_equal(xf, xf_before)
        assert xf.dtype == np.complex64 and back.dtype == np.float32
        np.testing.assert_allclose(xf, np.fft.rfft2(x.astype(np.float64)), atol=1e-4)
        np.testing.assert_allclose(back, x, atol=1e-5)
    assert not np.shares_memory(fft.rfft2(x), fft.rfft2(x))  # results are not the plan's buffer


def test_multiply_rounds_each_product():
    """fft.multiply: (ar br - ai bi) + i(ar bi + ai br) with every product rounded to the array's
    precision, broadcast; by hand and against float64 products rounded the same way."""
    assert multiply(np.array([1 + 2j], np.complex64), np.array([3 + 4j], np.complex64)).tolist() == [-5 + 10j]
    rng = np.random.default_rng(4)
    a = (rng.standard_normal((3, 4, 5)) + 1j * rng.standard_normal((3, 4, 5))).astype(np.complex64)
    b = (rng.standard_normal((4, 5)) + 1j * rng.standard_normal((4, 5))).astype(np.complex64)
    out = multiply(a, b)
    assert out.dtype == np.complex64 and out.shape == (3, 4, 5)
    f32 = np.float32
    re = (a.real.astype(f32) * b.real).astype(f32) - (a.imag * b.imag).astype(f32)
    im = (a.real * b.imag).astype(f32) + (a.imag * b.real).astype(f32)
    assert np.array_equal(out.real, re) and np.array_equal(out.imag, im)
    np.testing.assert_allclose(out, a.astype(np.complex128) * b, rtol=1e-5, atol=1e-6)


def test_whole_spectra_keep_a_complex_map_whole():
    """tracker.spectra full (FullSpectra): rfft2 gives the whole spectrum and irfft2 the complex map."""
    fft = make_fft("scipy", full=True)
    assert fft.full and not make_fft("scipy").full and not make_fft("pyfftw").full
    x = np.random.default_rng(1).standard_normal((2, 6, 8)) + 1j * np.random.default_rng(2).standard_normal((2, 6, 8))
    xf = fft.rfft2(x)
    np.testing.assert_allclose(xf, np.fft.fft2(x), rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(fft.irfft2(xf, (6, 8)), x, atol=1e-12)


def bits(a: np.ndarray) -> np.ndarray:
    """The array's bytes: equal bits, signed zeros and NaN payloads included."""
    return np.ascontiguousarray(a).view(np.uint8)


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
@pytest.mark.parametrize("shape, rows, spectrum_rows", [
    ((3, 50, 50), slice(17, 34), 50), ((2, 37, 53), slice(0, 5), 37), ((4, 31, 48), slice(30, 31), 31),
    ((1, 8, 9), slice(0, 8), 8), ((2, 12, 10), slice(5, 5), 12), ((2, 89, 67), slice(10, 50), 89),
    ((2, 63, 89), slice(1, 40), 63), ((2, 30, 20), slice(0, 29), 30), ((2, 20, 16), slice(3, 11), 14),
    ((2, 20, 16), slice(3, 11), 26)])
def test_scipys_transforms_of_a_band_of_rows_are_the_whole_transforms_bit_for_bit(dtype, shape, rows, spectrum_rows):
    """rfft2_rows of a map +0 outside ``rows`` is its rfft2, and irfft2_rows is irfft2 on those
    rows and +0 elsewhere, to the bit: strided inputs, odd sizes, an empty band, a spectrum of
    other height (cropped or padded), and sizes whose 1/(H W) in double is not pocketfft's (89 x 67)."""
    fft = make_fft("scipy")
    rng = np.random.default_rng(shape[1])
    x = np.zeros((shape[0], shape[1], 2 * shape[2]), dtype)[..., ::2]  # strided
    x[:, rows] = rng.standard_normal(x[:, rows].shape)
    assert np.array_equal(bits(fft.rfft2_rows(x, rows)), bits(fft.rfft2(x)))  # an empty band: transformed whole
    spectrum = fft.rfft2(rng.standard_normal((shape[0], spectrum_rows, shape[2])).astype(dtype))
    whole = fft.irfft2(spectrum, shape[1:])
    band = fft.irfft2_rows(spectrum, shape[1:], rows)
    expected = np.zeros_like(whole)
    expected[:, rows] = whole[:, rows]
    assert band.dtype == whole.dtype and np.array_equal(bits(band), bits(expected))


@pytest.mark.parametrize("backend, full", [("pyfftw", False), ("scipy", True)])
def test_other_backends_transform_a_band_whole_and_zero_the_rows_outside_it(backend, full):
    fft = make_fft(backend, full=full)
    spectrum = fft.rfft2(np.random.default_rng(1).standard_normal((2, 12, 10)).astype(np.float32))
    band = fft.irfft2_rows(spectrum, (12, 10), slice(3, 7))
    whole = fft.irfft2(spectrum, (12, 10))
    assert np.array_equal(band[:, 3:7], whole[:, 3:7]) and not band[:, :3].any() and not band[:, 7:].any()
    assert np.array_equal(fft.rfft2_rows(band, slice(3, 7)), fft.rfft2(band))

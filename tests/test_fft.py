"""FFT backends against numpy.fft; they must not touch or alias their inputs."""
import numpy as np
import pytest

from dcfkit.fft import make_fft


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

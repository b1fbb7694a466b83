"""fDSST's scale filter (ECO's): the interpolated response against the continuous function it
samples, and a zoom found on a textured image."""
import cv2
import numpy as np
import pytest

from dcfkit.components.scale.fdsst import FDSST, resize_spectrum


def test_resizing_a_spectrum_samples_the_same_trigonometric_polynomial_finer():
    n, m = 17, 33
    f = lambda t: np.cos(2 * np.pi * t) + 0.5 * np.sin(2 * np.pi * 3 * t) + 0.2  # noqa: E731
    coarse = f(np.arange(n) / n)
    fine = np.fft.ifft(resize_spectrum(np.fft.fft(coarse), m)).real
    assert np.allclose(fine, f(np.arange(m) / m))


def textured(size, seed=0):
    rng = np.random.default_rng(seed)
    small = rng.integers(0, 256, (size // 8, size // 8, 3), np.uint8)
    return cv2.GaussianBlur(cv2.resize(small, (size, size), interpolation=cv2.INTER_CUBIC), (5, 5), 1.0)


@pytest.mark.parametrize("zoom", [1.06, 0.95])
def test_a_zoom_about_the_target_is_found(zoom):
    image = textured(400)
    centre, target = np.array([199.5, 199.5]), np.array([60.0, 80.0])
    scale = FDSST()
    scale.init(image, centre, target, 1.0, (0.1, 10.0))
    # the scene enlarged by `zoom` about the centre: the target now looks `zoom` times larger
    warp = np.array([[zoom, 0, (1 - zoom) * 199.5], [0, zoom, (1 - zoom) * 199.5]])
    zoomed = cv2.warpAffine(image, warp, (400, 400), flags=cv2.INTER_LINEAR, borderMode=cv2.BORDER_REFLECT)
    assert scale.update(zoomed, centre, 1.0) == pytest.approx(zoom, abs=0.015)


def test_a_uniform_target_keeps_a_finite_scale():
    # a flat response has no parabola maximum (poly[0] == 0 gave NaN and a crash next frame)
    image = np.full((200, 200, 3), 128, np.uint8)
    centre = np.array([99.5, 99.5])
    scale = FDSST()
    scale.init(image, centre, np.array([30.0, 40.0]), 1.0, (0.1, 10.0))
    new = scale.update(image, centre, 1.0)
    assert np.isfinite(new) and new in scale.interp_factors
    assert np.isfinite(scale.update(image, centre, new))

"""Gray: the authors' MATLAB conversion (get_colorspace's rgb2gray) and OpenCV's."""
import numpy as np
import pytest

from dcfkit.components.features.gray import Gray

# The authors' MATLAB detail this option reproduces, against an independent reference (the
# line worked out by hand or re-run in numpy, a brute-force loop, a dense solve). file.m:line
# cites ../shared/reference/DR2Track/DR2Track1 unless STRCF's (../shared/reference/STRCF) is named.
# --------------------------------------------------------------------------------------------
# the authors' MATLAB: gray: get_colorspace's rgb2gray
# --------------------------------------------------------------------------------------------


@pytest.mark.parametrize("bgr", [(30, 200, 90), (255, 0, 0), (0, 0, 255), (13, 77, 251)])
def test_gray_matlab_conversion_of_a_uniform_patch(bgr):
    # get_colorspace.m:5,10: rgb2gray(single(im)/255) - 0.5, rgb2gray = 0.298936 R + 0.587043 G + 0.114021 B
    b, g, r = bgr
    patch = np.empty((8, 12, 3), np.uint8)
    patch[:] = bgr  # dcfkit's images are BGR
    expected = (0.298936 * r + 0.587043 * g + 0.114021 * b) / 255 - 0.5
    got = Gray(Gray.Params(conversion="matlab")).extract(patch, 4)
    assert got.shape == (1, 2, 3)
    np.testing.assert_allclose(got, expected, atol=2e-7)


def test_gray_opencv_conversion_rounds_to_whole_levels():
    patch = np.full((8, 8, 3), (30, 200, 90), np.uint8)
    got = Gray().extract(patch, 4)
    np.testing.assert_allclose(got, round(0.299 * 90 + 0.587 * 200 + 0.114 * 30) / 255 - 0.5, atol=2e-7)


def test_gray_csr_conversion_is_matlabs_uint8_arithmetic():
    # get_csr_features: single((gray_patch / 255) - 0.5) of a uint8 patch. uint8 / 255 rounds to 0
    # (levels 0..127) or 1 (128..255); uint8(0) - 0.5 rounds to -1 and saturates at 0, uint8(1) - 0.5
    # rounds to 1: the channel is 1 where the level is at least 128, else 0
    levels = np.array([[0, 127, 128, 255]], np.uint8)
    patch = np.repeat(levels[..., None], 3, axis=2)  # gray pixels: every conversion gives the level
    out = Gray(Gray.Params(conversion="csr")).extract(patch, 1)
    np.testing.assert_array_equal(out[0], [[0, 0, 1, 1]])


def test_gray_matlab_bicubic_pooling_resizes_the_uint8_gray_map():
    # get_csr_features: imresize(rgb2gray(im), out_size) of the uint8 patch, then / 255 - 0.5
    import cv2  # only this test

    from dcfkit.numerics.imresize import imresize

    rng = np.random.default_rng(3)
    patch = rng.integers(0, 256, (24, 20, 3), dtype=np.uint8)
    out = Gray(Gray.Params(pooling="matlab_bicubic")).extract(patch, 4)
    cells = imresize(cv2.cvtColor(patch, cv2.COLOR_BGR2GRAY), (6, 5)).astype(np.float32)
    np.testing.assert_allclose(out[0], cells / 255 - 0.5, atol=1e-6)
    binary = Gray(Gray.Params(conversion="csr", pooling="matlab_bicubic")).extract(patch, 4)
    np.testing.assert_array_equal(binary[0], (cells >= 128).astype(np.float32))

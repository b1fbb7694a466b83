"""MATLAB's imresize against its definition written out pixel by pixel."""
import math

import numpy as np
import pytest

from dcfkit.numerics.imresize import _along, contributions, imresize


def keys_cubic(x):
    x = abs(x)
    if x <= 1:
        return 1.5 * x**3 - 2.5 * x**2 + 1
    return -0.5 * x**3 + 2.5 * x**2 - 4 * x + 2 if x <= 2 else 0.0


def triangle(x):
    return max(0.0, 1 - abs(x))


def one_axis(values, n_out, bilinear):
    """MATLAB's imresize along one axis, one output pixel at a time: u = x/s + (1 - 1/s)/2, the
    kernel stretched by 1/s when shrinking (bicubic only), the weights normalised, the source
    mirrored beyond its ends."""
    n_in = len(values)
    s = n_out / n_in
    stretch = s < 1 and not bilinear
    kernel = triangle if bilinear else keys_cubic
    width = 2 if bilinear else (4 / s if stretch else 4)
    out = []
    for x in range(1, n_out + 1):
        u = x / s + 0.5 * (1 - 1 / s)
        taps = range(math.floor(u - width / 2), math.floor(u - width / 2) + math.ceil(width) + 2)
        w = [s * kernel(s * (u - j)) if stretch else kernel(u - j) for j in taps]
        total = sum(w)
        acc = 0.0
        for j, wj in zip(taps, w):
            k = (j - 1) % (2 * n_in)  # 1-based j mirrored: 1..n, n..1
            acc += wj / total * values[k if k < n_in else 2 * n_in - 1 - k]
        out.append(acc)
    return out


@pytest.mark.parametrize("shape, out, bilinear", [((17, 23), (6, 9), False), ((9, 7), (20, 15), False),
                                                   ((30, 30), (11, 11), False), ((13, 19), (22, 22), True),
                                                   ((31, 27), (10, 12), True)])
def test_imresize_is_its_definition(shape, out, bilinear):
    rng = np.random.default_rng(sum(shape))
    x = rng.random(shape)
    # MATLAB resizes the axis that shrinks most first
    first = 0 if out[0] / shape[0] <= out[1] / shape[1] else 1
    mid = np.apply_along_axis(lambda v: one_axis(v, out[first], bilinear), first, x)
    expected = np.apply_along_axis(lambda v: one_axis(v, out[1 - first], bilinear), 1 - first, mid)
    np.testing.assert_allclose(imresize(x, out, bilinear=bilinear), expected, rtol=0, atol=1e-12)


def test_uint8_is_rounded_after_each_axis_and_a_same_size_resize_is_a_copy():
    rng = np.random.default_rng(0)
    x = rng.integers(0, 256, (21, 18, 3), dtype=np.uint8)
    got = imresize(x, (8, 7))
    assert got.dtype == np.uint8
    mid = np.clip(np.floor(np.apply_along_axis(lambda v: one_axis(v, 8, False), 0, x.astype(float)) + 0.5), 0, 255)
    expected = np.clip(np.floor(np.apply_along_axis(lambda v: one_axis(v, 7, False), 1, mid) + 0.5), 0, 255)
    np.testing.assert_array_equal(got, expected)
    same = imresize(x, (21, 18))
    np.testing.assert_array_equal(same, x)
    assert same is not x


@pytest.mark.parametrize("dtype", [np.uint8, np.float32, np.float64])
@pytest.mark.parametrize("shape, out", [((97, 61, 3), (31, 20)), ((40, 52), (57, 33))])
def test_each_axis_sums_its_taps_in_order_bit_for_bit(dtype, shape, out):
    """The compiled sums round as the whole-array tap passes do (imresizemex's order): a product,
    then a sum, tap by tap, so boxes stay the same whichever way the sum is written."""
    rng = np.random.default_rng(len(shape))
    x = (rng.integers(0, 256, shape) if dtype == np.uint8 else rng.random(shape) * 255).astype(dtype)
    for axis in (0, 1):
        index, weights = contributions(shape[axis], out[axis])
        a = np.moveaxis(x, axis, 0)
        lead = (-1,) + (1,) * (a.ndim - 1)
        expected = weights[:, 0].reshape(lead) * a[index[:, 0]]
        for j in range(1, index.shape[1]):
            expected += weights[:, j].reshape(lead) * a[index[:, j]]
        got = _along(x, axis, out[axis], bilinear=False)
        assert got.dtype == np.float64
        np.testing.assert_array_equal(got, np.moveaxis(expected, 0, axis))

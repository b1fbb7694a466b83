"""Patch cropping with replicated borders, against a brute-force index clip."""
import cv2
import numpy as np
import pytest

from dcfkit.numerics.patches import (
    box_to_centre_size,
    centre_size_to_box,
    crop,
    resize_auto,
    round_half_away,
    sample,
    whole_pixel_crop,
    whole_pixel_sample,
)


def brute_crop(image, centre, region):
    rh, rw = int(round(region[0])), int(round(region[1]))
    y0 = int(np.floor(centre[0] - (rh - 1) / 2 + 0.5))
    x0 = int(np.floor(centre[1] - (rw - 1) / 2 + 0.5))
    out = np.zeros((rh, rw) + image.shape[2:], image.dtype)
    for i in range(rh):
        for j in range(rw):
            out[i, j] = image[min(max(y0 + i, 0), image.shape[0] - 1), min(max(x0 + j, 0), image.shape[1] - 1)]
    return out


@pytest.mark.parametrize("centre,region", [
    ((10, 12), (6, 8)), ((0, 0), (9, 7)), ((19, 29), (12, 15)), ((10, 15), (40, 50)),
    ((-30, 5), (8, 8)), ((50, 80), (10, 6)), ((5.4, 7.6), (5, 5)),
])
def test_crop_matches_brute_force(centre, region):
    image = np.random.default_rng(0).integers(0, 255, (20, 30, 3), dtype=np.uint8)
    np.testing.assert_array_equal(crop(image, centre, region), brute_crop(image, centre, region))


def test_box_centre_round_trip():
    box = (3.0, 4.5, 10.0, 7.0)
    centre, size = box_to_centre_size(box)
    assert tuple(centre) == (4.5 + 3.0, 3.0 + 4.5)
    assert centre_size_to_box(centre, size) == box


def reference_sample(image, centre, region, out):
    """Crop the whole region (edges replicated), average k x k blocks, resample bilinearly."""
    oh, ow = out
    k = int(min(region[0] / oh, region[1] / ow))
    ch, cw = (int(np.ceil(region[0] / k)) + 2) * k, (int(np.ceil(region[1] / k)) + 2) * k
    small = cv2.resize(brute_crop(image, centre, (ch, cw)), (cw // k, ch // k), interpolation=cv2.INTER_AREA)
    y0 = int(np.floor(centre[0] - (ch - 1) / 2 + 0.5))
    x0 = int(np.floor(centre[1] - (cw - 1) / 2 + 0.5))
    sy, sx = region[0] / oh, region[1] / ow
    warp = np.array([[sx / k, 0.0, (centre[1] - (ow - 1) / 2 * sx - x0 - (k - 1) / 2) / k],
                     [0.0, sy / k, (centre[0] - (oh - 1) / 2 * sy - y0 - (k - 1) / 2) / k]])
    return cv2.warpAffine(small, warp, (ow, oh), flags=cv2.INTER_LINEAR | cv2.WARP_INVERSE_MAP,
                          borderMode=cv2.BORDER_REPLICATE)


@pytest.mark.parametrize("seed", range(40))
def test_shrinking_sample_equals_cropping_the_whole_region_first(seed):
    # regions inside, across edges and corners, far beyond the image and wholly off it
    rng = np.random.default_rng(seed)
    image = rng.integers(0, 255, (int(rng.integers(20, 70)), int(rng.integers(20, 90)), 3), dtype=np.uint8)
    out = (int(rng.integers(4, 12)), int(rng.integers(4, 12)))
    k = int(rng.integers(2, 9))
    region = (out[0] * k * rng.uniform(1, 1.9), out[1] * k * rng.uniform(1, 1.9))
    centre = (rng.uniform(-1.5, 2.5) * image.shape[0], rng.uniform(-1.5, 2.5) * image.shape[1])
    np.testing.assert_array_equal(sample(image, centre, region, out), reference_sample(image, centre, region, out))


# The authors' MATLAB detail this option reproduces, against an independent reference (the
# line worked out by hand or re-run in numpy, a brute-force loop, a dense solve). file.m:line
# cites ../shared/reference/DR2Track/DR2Track1 unless STRCF's (../shared/reference/STRCF) is named.
# --------------------------------------------------------------------------------------------
# the authors' MATLAB: patches: MATLAB's round, get_pixels' crop, mexResize 'auto'
# --------------------------------------------------------------------------------------------

@pytest.mark.parametrize("x, expected", [
    (0.5, 1), (1.5, 2), (2.5, 3), (-0.5, -1), (-2.5, -3),   # halves away from zero (numpy: 0, 2, 2, -0, -2)
    (2.4999, 2), (-2.5001, -3), (0.0, 0), (7.0, 7), (-7.2, -7),
])
def test_round_half_away_is_matlab_round(x, expected):
    assert round_half_away(x) == expected
    assert np.array_equal(round_half_away(np.array([x, -x])), np.array([expected, -expected]))


def get_pixels_indices(image_shape, centre, size):
    """0-based row and column indices of get_pixels.m:16-24 for a 0-based centre: in MATLAB's
    1-based pixels pos = centre + 1, xs = floor(pos(2)) + (1:w) - floor(w/2), clamped to [1, W]."""
    pos = np.asarray(centre, float) + 1
    h, w = size
    ys = np.floor(pos[0]) + np.arange(1, h + 1) - np.floor(h / 2)
    xs = np.floor(pos[1]) + np.arange(1, w + 1) - np.floor(w / 2)
    ys = np.clip(ys, 1, image_shape[0])
    xs = np.clip(xs, 1, image_shape[1])
    return ys.astype(int) - 1, xs.astype(int) - 1


@pytest.mark.parametrize("centre, size", [
    ((10.0, 15.0), (6, 8)),      # even sizes, whole-pixel centre
    ((10.7, 15.2), (5, 7)),      # odd sizes, centre floored
    ((1.3, 15.5), (9, 4)),       # over the top border
    ((18.6, 15.0), (8, 5)),      # over the bottom border (image rows 0..19)
    ((10.2, 0.4), (4, 9)),       # over the left border
    ((10.0, 28.9), (3, 10)),     # over the right border (columns 0..29)
    ((-5.5, 40.2), (4, 4)),      # wholly beyond the top-right corner: the corner pixel replicated
    ((10.0, 15.0), (30, 41)),    # larger than the image on every side
])
@pytest.mark.parametrize("channels", [3, 0])
def test_whole_pixel_crop_is_get_pixels(centre, size, channels):
    rng = np.random.default_rng(0)
    image = rng.integers(0, 256, (20, 30, channels) if channels else (20, 30), dtype=np.uint8)
    ys, xs = get_pixels_indices(image.shape, centre, size)
    expected = image[np.ix_(ys, xs)]
    got = whole_pixel_crop(image, centre, size)
    assert got.shape == expected.shape
    assert np.array_equal(got, expected)


def test_whole_pixel_crop_hand_case():
    # centre (10, 15), 0-based = pos (11, 16) 1-based; ys = 11 + (1:6) - 3 = 9..14, xs = 16 + (1:8) - 4 = 13..20
    # (1-based): 0-based rows 8..13 and columns 12..19 (the pixel floor(centre) is at index h//2 - 1)
    image = np.arange(20 * 30, dtype=np.int32).reshape(20, 30)
    assert np.array_equal(whole_pixel_crop(image, (10.0, 15.0), (6, 8)), image[8:14, 12:20])


# mexResize.cpp:46-52 picks the interpolation from the new width. On a square patch (the search
# patches of STRCF and DR²Track: round(sz * scale) with a square sz) its old height and width are
# equal, so these cases do not depend on which of the two it compares with (see the xfail below).
@pytest.mark.parametrize("old, new, interpolation", [
    ((30, 30), (20, 20), cv2.INTER_AREA),     # shrinking
    ((30, 30), (40, 40), cv2.INTER_LINEAR),   # zooming
    ((30, 30), (45, 25), cv2.INTER_AREA),     # the height grows, the width shrinks: area
    ((30, 30), (12, 31), cv2.INTER_LINEAR),   # the height shrinks a lot, the width grows by one: linear
    ((30, 30), (50, 30), cv2.INTER_AREA),     # the same width is not larger: area
])
def test_resize_auto_on_square_patches(old, new, interpolation):
    patch = np.random.default_rng(1).integers(0, 256, (*old, 3), dtype=np.uint8)
    expected = cv2.resize(patch, (new[1], new[0]), interpolation=interpolation)
    other = cv2.resize(patch, (new[1], new[0]),
                       interpolation=cv2.INTER_LINEAR if interpolation == cv2.INTER_AREA else cv2.INTER_AREA)
    assert not np.array_equal(expected, other)  # the case tells the two interpolations apart
    assert np.array_equal(resize_auto(patch, new), expected)


@pytest.mark.parametrize("old, new", [((40, 10), (20, 15)), ((10, 20), (15, 20)), ((10, 40), (30, 20)),
                                      ((30, 12), (20, 16))])
def test_resize_auto_compares_the_new_width_with_the_old_height_as_the_compiled_mex(old, new):
    """mexResize.cpp:34-49 builds newSize = Size(s.height, s.width) (new width, new height) and
    tests newSize.width > oldSize.height, its comment assuming a transposed Mat; MxArray::toMat
    (MxArray.cpp:348-373, transpose=true by default, MxArray.hpp:322) returns the image
    untransposed, so oldSize.height is the old number of rows. Compiled under Octave from the
    shipped sources (STRCF/external_libs/mexResize, identical to DR2Track1/utils/mexResize.cpp):
    [40 10] -> [20 15] gives cv2's INTER_AREA and [10 20] -> [15 20] INTER_LINEAR, bit for bit."""
    patch = np.random.default_rng(2).integers(0, 256, (*old, 3), dtype=np.uint8)
    interpolation = cv2.INTER_LINEAR if new[1] > old[0] else cv2.INTER_AREA
    assert np.array_equal(resize_auto(patch, new), cv2.resize(patch, (new[1], new[0]), interpolation=interpolation))


@pytest.mark.parametrize("region, crop", [
    ((12.5, 12.5), (13, 13)),   # round half away from zero (numpy would give 12)
    ((0.4, 0.3), (2, 2)),       # get_pixels.m:8-13: a side below 1 (after rounding: 0) becomes 2
    ((7.5, 3.49), (8, 3)),
    ((0.5, 9.6), (1, 10)),      # round(0.5) = 1 is not below 1
])
def test_whole_pixel_sample_rounds_the_region(region, crop):
    """The crop of round(region) pixels; resizing to that same size is a copy, which isolates the crop."""
    rng = np.random.default_rng(3)
    image = rng.integers(0, 256, (20, 30, 3), dtype=np.uint8)
    centre = (9.6, 14.2)
    ys, xs = get_pixels_indices(image.shape, centre, crop)
    assert np.array_equal(whole_pixel_sample(image, centre, region, crop), image[np.ix_(ys, xs)])


@pytest.mark.parametrize("out, interpolation", [((24, 24), cv2.INTER_LINEAR),   # 24 > 17: zoom
                                                 ((30, 12), cv2.INTER_AREA)])    # 12 < 17 (a larger area)
def test_whole_pixel_sample_resizes_the_crop(out, interpolation):
    rng = np.random.default_rng(4)
    image = rng.integers(0, 256, (40, 50, 3), dtype=np.uint8)
    centre = (20.5, 2.7)  # over the left border
    ys, xs = get_pixels_indices(image.shape, centre, (17, 17))  # round(16.5) = 17
    expected = cv2.resize(image[np.ix_(ys, xs)], (out[1], out[0]), interpolation=interpolation)
    assert np.array_equal(whole_pixel_sample(image, centre, (16.5, 16.5), out), expected)

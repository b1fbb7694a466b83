"""Patch cropping with replicated borders, against a brute-force index clip."""
import cv2
import numpy as np
import pytest

from dcfkit.numerics.patches import box_to_centre_size, centre_size_to_box, crop, sample


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

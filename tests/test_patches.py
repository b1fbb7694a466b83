"""Patch cropping with replicated borders, against a brute-force index clip."""
import numpy as np
import pytest

from dcfkit.patches import box_to_centre_size, centre_size_to_box, crop


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

"""The mask kind's contract, and csr_segmentation on hand-built two-colour images."""
import cv2
import numpy as np
import pytest

import dcfkit
from dcfkit.components.base import Target
from dcfkit.components.masks import CSRSegmentation, Mask, box_mask
from dcfkit.components.masks.segmentation import (bilinear, bins, foreground_histogram, hsv255, linear_taps, on_grid,
                                                  posterior, regularised)
from dcfkit.contracts import ContractViolation
from dcfkit.errors import ConfigError, RegistryError
from dcfkit.registry import Registry

BLUE, RED = (200, 60, 30), (30, 30, 220)  # BGR


def disk_scene(radius=20, centre=(120, 140)):
    """A red disk on a blue background, 240 x 320 BGR; the disk's box, 0-based (x, y, w, h)."""
    image = np.empty((240, 320, 3), np.uint8)
    image[:] = BLUE
    cv2.circle(image, (centre[1], centre[0]), radius, RED, -1)
    side = 2 * radius + 1
    return image, (centre[1] - radius, centre[0] - radius, side, side)


def start(mask, shape=(40, 40), target_cells=(10.25, 10.25)):
    mask.reset()
    mask.start(Target((240, 320), shape, target_cells, 4, 1.0, 1.0))
    return mask


def test_the_red_disk_is_the_mask_not_its_box():
    image, (x, y, w, h) = disk_scene()
    centre = np.array([y + (h - 1) / 2, x + (w - 1) / 2])
    mask = start(CSRSegmentation())
    for frame in range(2):  # the first frame keeps the mask in the box; the second needs no box
        m = mask.make(image, centre, np.array([h, w], float), np.array([164.0, 164.0]), (40, 40))
        assert m.dtype == bool and m.shape == (40, 40)
        yy, xx = np.mgrid[0:40, 0:40]
        d = np.hypot(yy - 19.5, xx - 19.5)  # cells from the middle; the disk's radius is 5 cells
        assert m[d <= 4].all(), frame
        assert not m[d >= 7].any(), frame  # the box's corners (7 cells out) and the background
        assert 60 <= m.sum() <= 140


def test_a_gray_sequence_takes_the_box_mask():
    image, (x, y, w, h) = disk_scene()
    gray = cv2.cvtColor(cv2.cvtColor(image, cv2.COLOR_BGR2GRAY), cv2.COLOR_GRAY2BGR)
    mask = start(CSRSegmentation())
    m = mask.make(gray, np.array([120.0, 140.0]), np.array([41.0, 41.0]), np.array([164.0, 164.0]), (40, 40))
    np.testing.assert_array_equal(m, box_mask((40, 40), (10.25, 10.25)))


def test_box_mask_by_hand():
    # floor(3.6) + 1 = 4 rows from 1-based floor((10 - 3) / 2) = 3; 5 columns from floor((12 - 4) / 2) = 4
    expected = np.zeros((10, 12), bool)
    expected[2:6, 3:8] = True
    np.testing.assert_array_equal(box_mask((10, 12), (3.6, 4.2)), expected)


def test_the_posterior_of_two_colours():
    patch = np.empty((40, 60, 3), np.uint8)
    patch[:, :30], patch[:, 30:] = RED, BLUE
    hist_fg = np.zeros(16**3)
    hist_fg[bins(np.array(RED, np.uint8), 16)] = 1
    hist_bg = np.zeros(16**3)
    hist_bg[bins(np.array(BLUE, np.uint8), 16)] = 1
    q = posterior(lambda r, c: patch[np.ix_(r, c)], (40, 60), hist_fg, hist_bg, np.array([40.0, 60.0]), 16)
    assert q.shape == (25, 38)  # segment.cpp's working size: (59, 39) shrunk to about 1000 pixels
    assert (q[:, :14] > 0.9).all() and (q[:, 24:] < 0.1).all()


@pytest.mark.parametrize("keep", [((0, 90), (0, 70)), ((10, 90), (0, 55)), ((30, 40), (20, 30)), ((5, 5), (0, 70))])
def test_on_grid_is_the_full_size_resize_masked_binarised_and_sampled(keep):
    rng = np.random.default_rng(4)
    q = cv2.GaussianBlur(rng.random((23, 31)), (5, 5), 2)
    full = cv2.resize(q, (70, 90))  # the mex's resize back to the patch (w, h) = (70, 90)
    inside = np.zeros_like(full)
    (r0, r1), (c0, c1) = keep
    inside[r0:r1, c0:c1] = 1
    soft = (full * inside).astype(np.float32)
    peak = soft.max() if soft.max() > 0 else 1
    hard = soft / peak > 0.5
    rows, cols = [int((i + 0.5) * 90 / 20) for i in range(20)], [int((j + 0.5) * 70 / 16) for j in range(16)]
    np.testing.assert_array_equal(on_grid(q, (90, 70), keep, (20, 16), 0.5), hard[np.ix_(rows, cols)])


def test_bilinear_reads_what_opencv_resizes():
    rng = np.random.default_rng(2)
    image = rng.random((37, 53))
    taps = linear_taps(37, 11), linear_taps(53, 16)
    np.testing.assert_allclose(bilinear(lambda r, c: image[np.ix_(r, c)], *taps),
                               cv2.resize(image, (16, 11)), atol=1e-12)
    colour = rng.integers(0, 256, (37, 53, 3), dtype=np.uint8)
    ours = np.rint(bilinear(lambda r, c: colour[np.ix_(r, c)].astype(float), *taps))
    assert np.abs(ours - cv2.resize(colour, (16, 11))).max() <= 1  # OpenCV's 8-bit fixed point: within a level


def test_the_mrf_removes_isolated_pixels():
    rng = np.random.default_rng(0)
    truth = np.zeros((30, 30))
    truth[8:22, 8:22] = 1
    noisy = np.where(rng.random(truth.shape) < 0.1, 1 - truth, truth)  # 10% of the pixels flipped
    q = regularised(np.clip(noisy, 0.2, 0.8), np.full(truth.shape, 0.5))
    assert ((noisy > 0.5) != truth).sum() > 50
    assert ((q > 0.5) != truth).sum() < 15


def test_the_foreground_histogram_weights_the_middle():
    pixels = np.zeros((5, 5, 3), np.uint8)
    pixels[2, 2] = RED  # one red pixel in the middle of a black box
    hist = foreground_histogram(pixels, (0, 0, 4, 4), 16)
    assert hist.sum() == pytest.approx(1)
    # Epanechnikov weights: 1 - d at the middle, the others less (d > 0), the corners 0
    k = 1 / (0.5 * 4 * 1.4142 + 1)
    d = ((np.arange(5)[:, None] - 2.0) * k) ** 2 + ((np.arange(5)[None, :] - 2.0) * k) ** 2
    weights = np.where(d <= 1, 1 - d, 0)
    assert hist[bins(np.array(RED, np.uint8), 16)] == pytest.approx(1 / weights.sum())


class _WrongShape(Mask):
    name = "wrong_shape"

    def make(self, image, centre, target, region, shape):
        return np.ones((shape[0] + 1, shape[1]), bool)


class _NoMake(Mask):
    name = "no_make"


def test_the_mask_contract():
    registry = Registry()
    registry.register(_WrongShape)
    mask = registry.build("mask", {"name": "wrong_shape"}, "test.yaml: mask")
    with pytest.raises(ContractViolation, match=r"make\(\) returned shape \(5, 4\), expected \(4, 4\)"):
        mask.make(np.zeros((8, 8, 3), np.uint8), np.zeros(2), np.ones(2), np.ones(2), (4, 4))
    with pytest.raises(RegistryError, match=r"does not implement make"):
        registry.register(_NoMake)


def test_a_mask_needs_a_solver_with_a_spatial_term_and_configs_without_one_are_unchanged():
    assert "mask" not in dcfkit.load_config("strcf") and "channel_weights" not in dcfkit.load_config("strcf")
    assert dcfkit.load_tracker("strcf").mask is None
    with pytest.raises(ConfigError, match="solver 'kernel_ridge' has no spatial term.*mask"):
        dcfkit.load_tracker("kcf", overrides={"mask": {"name": "csr_segmentation"}})


@pytest.mark.parametrize("rgb, hsv", [
    ((255, 0, 0), (0, 255, 255)),        # red: h 0
    ((0, 255, 0), (85, 255, 255)),       # green: h 1/3 of 255
    ((0, 0, 255), (170, 255, 255)),      # blue: h 2/3
    ((255, 0, 255), (212, 255, 255)),    # magenta: red ties blue, red wins: 1/6 (0 - 255)/255 + 1 = 5/6 -> 212.5 -> 212 (even)
    ((77, 77, 77), (0, 0, 77)),          # gray: no hue, no saturation
    ((200, 100, 50), (14, 191, 200)),    # h = 1/6 (100 - 50) / 150 = 1/18 -> 14.17; s = 1 - 50/200 = 0.75 -> 191.25
])
def test_hsv_is_rgb2hsv_times_255_rounded_to_even(rgb, hsv):
    bgr = np.array([[rgb[::-1]]], np.uint8)
    np.testing.assert_array_equal(hsv255(bgr)[0, 0], hsv)


def test_an_unseen_colour_discards_the_frame_as_the_authors_nan_does():
    image, (x, y, w, h) = disk_scene()
    image[5:15, 5:15] = (0, 255, 0)  # a green square far from the box: in neither histogram, inside the patch
    centre = np.array([y + (h - 1) / 2, x + (w - 1) / 2])
    args = (image, centre, np.array([h, w], float), np.array([240.0, 300.0]), (40, 40))
    neutral = start(CSRSegmentation()).make(*args)
    discard = start(CSRSegmentation(CSRSegmentation.Params(unseen_colour="discard"))).make(*args)
    np.testing.assert_array_equal(discard, box_mask((40, 40), (10.25, 10.25)))
    assert not np.array_equal(neutral, discard)

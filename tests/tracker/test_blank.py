"""The blank-frame test (``tracker.blank_std``) against the standard deviation of every pixel."""
from types import SimpleNamespace

import cv2
import numpy as np
import pytest

from dcfkit.tracker.checks import blank


def everywhere(pixels, limit):
    """The definition: the RMS over channels of each channel's population standard deviation of
    all ``pixels``, if below ``limit``."""
    std = float(np.sqrt(np.mean(np.square(cv2.meanStdDev(pixels)[1]))))
    return std if std < limit else None


def images(rng):
    """Frames a subset of rows sees wrongly: natural-like, low-contrast around the limit, flat
    with outliers on rows the subset skips, gray, a row, a column."""
    yield rng.integers(0, 256, (90, 160, 3), dtype=np.uint8)
    for spread in (0, 1, 2, 3, 4, 6):
        yield (100 + rng.integers(0, spread + 1, (72, 128, 3))).astype(np.uint8)
    flat = np.full((72, 128, 3), 80, np.uint8)
    flat[1::16] = 255  # none of these rows is one of every sixteenth
    yield flat
    sparse = np.full((72, 128), 30, np.uint8)
    sparse[rng.integers(0, 72, 40), rng.integers(0, 128, 40)] = 200
    yield sparse
    yield rng.integers(0, 3, (1, 301, 3), dtype=np.uint8)
    yield rng.integers(0, 3, (257, 1), dtype=np.uint8)
    yield np.full((5, 7, 3), 9, np.uint8)


@pytest.mark.parametrize("limit", [0.0, 0.3, 1.0, 1.5, 4.0, 40.0, np.inf])
def test_blank_is_the_standard_deviation_of_every_pixel(limit):
    """Whatever a sixteenth of the rows says, the answer is that of all of them: the same
    standard deviation when it is below the limit, None when not (and with limit 0, off)."""
    tracker = SimpleNamespace(params=SimpleNamespace(blank_std=limit))
    rng = np.random.default_rng(int(limit) if np.isfinite(limit) else 99)
    for k, pixels in enumerate(images(rng)):
        expected = everywhere(pixels, limit) if limit > 0 else None
        assert blank(tracker, pixels) == expected, (k, pixels.shape)


def test_a_frame_the_subset_sees_flat_is_judged_on_all_its_pixels():
    """Outliers only where the subset does not look: the subset is flat, all of them are not."""
    flat = np.full((64, 64, 3), 50, np.uint8)
    flat[2::16, 3::4] = 90
    tracker = SimpleNamespace(params=SimpleNamespace(blank_std=1.0))
    assert float(cv2.meanStdDev(flat[::16])[1].max()) == 0
    assert blank(tracker, flat) is None
    flat[2::16, 3::4] = 53  # varies by less than the limit: blank
    assert blank(tracker, flat) == pytest.approx(float(np.std(flat[..., 0], dtype=np.float64)))

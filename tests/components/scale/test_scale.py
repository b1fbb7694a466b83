"""Scale estimators recover a known zoom."""
import cv2
import numpy as np
import pytest

from dcfkit.components.scale.base import scale_limits
from dcfkit.components.scale.dsst import DSST
from dcfkit.components.scale.pyramid import Pyramid


def zoomed(image, centre, factor):
    """``image`` magnified by ``factor`` about ``centre`` (y, x)."""
    cy, cx = centre
    m = np.float32([[factor, 0, cx - factor * cx], [0, factor, cy - factor * cy]])
    return cv2.warpAffine(image, m, image.shape[1::-1], flags=cv2.INTER_LINEAR, borderMode=cv2.BORDER_REFLECT)


@pytest.mark.parametrize("steps", [-4, -3, -2, 0, 2, 3, 4])
def test_dsst_recovers_a_zoom(steps):
    """One frame resolves the zoom to a step (its scale response is broad: neighbouring steps
    differ by ~0.1%); repeated frames, each starting from the last estimate, settle on it."""
    rng = np.random.default_rng(0)
    noise = cv2.GaussianBlur(rng.random((240, 320, 3)).astype(np.float32), (0, 0), 1.5)
    image = ((noise - noise.min()) / np.ptp(noise) * 255).astype(np.uint8)
    centre, target = np.array([120.0, 160.0]), np.array([40.0, 56.0])
    dsst = DSST()
    dsst.init(image, centre, target, 1.0, (0.1, 10.0))
    step = dsst.params.step
    frame = zoomed(image, centre, step**steps)
    first = np.log(dsst.update(frame, centre, 1.0)) / np.log(step)
    assert abs(first - steps) <= 1 + 1e-9 and np.sign(round(first)) == np.sign(steps)
    scale = step**first
    for _ in range(4):
        scale = dsst.update(frame, centre, scale)
    assert np.log(scale) / np.log(step) == pytest.approx(steps, abs=1e-6)


def test_pyramid_factors_and_limits():
    pyramid = Pyramid(Pyramid.Params(n_scales=5, step=1.02))
    np.testing.assert_allclose(pyramid.search_factors(), 1.02 ** np.arange(-2, 3))
    pyramid.init(None, np.zeros(2), np.array([10.0, 20.0]), 1.0, (0.5, 2.0))
    assert pyramid.update(None, np.zeros(2), 3.0) == 2.0 and pyramid.update(None, np.zeros(2), 0.1) == 0.5
    lo, hi = scale_limits(np.array([10.0, 20.0]), np.array([100.0, 100.0]), (360, 480))
    assert lo == pytest.approx(0.05) and hi == pytest.approx(24.0)
    # the search region keeps >= 5 px on its shorter side; the target fits on both axes
    lo, hi = scale_limits(np.array([40.0, 10.0]), np.array([100.0, 20.0]), (720, 1280))
    assert lo == pytest.approx(0.25) and hi == pytest.approx(18.0)


def test_dsst_model_update_keeps_the_size_while_the_appearance_changes():
    """The scale model is a running average of the scale samples (``learning_rate``), so it
    follows a target whose appearance changes: here the texture of the target and its
    surroundings (1.5x its box) turns gradually into another over 30 frames at a constant
    size, and the estimated size stays the true one on every frame. A model that keeps the
    first frame's appearance (learning rate ~0) matches the new texture at wrong scales."""
    centre, target = np.array([120.0, 160.0]), np.array([40.0, 56.0])
    region = np.zeros((240, 320, 1), np.float32)
    h, w = (1.5 * target).astype(int)
    region[120 - h // 2: 120 + h // 2, 160 - w // 2: 160 + w // 2] = 1

    def steps_off(seed, learning_rate):
        """How many scale steps the estimated scale is off (the true one stays 1), per frame."""
        rng = np.random.default_rng(seed)
        first, last = (cv2.GaussianBlur(rng.random((240, 320, 3)).astype(np.float32), (0, 0), 1.5) for _ in "ab")
        first, last = ((x - x.min()) / np.ptp(x) * 255 for x in (first, last))
        dsst = DSST(DSST.Params(learning_rate=learning_rate))
        dsst.init(first.astype(np.uint8), centre, target, 1.0, (0.1, 10.0))
        scale, estimates = 1.0, []
        for k in range(1, 31):
            a = region * k / 30
            scale = dsst.update(((1 - a) * first + a * last).astype(np.uint8), centre, scale)
            estimates.append(scale)
        return np.abs(np.log(estimates)) / np.log(dsst.params.step)

    adapting = np.array([steps_off(seed, DSST.Params().learning_rate) for seed in range(3)])
    frozen = np.array([steps_off(seed, 1e-9) for seed in range(3)])
    assert adapting.max() < 0.5, adapting.max(axis=1)  # not one step off on any frame
    assert (frozen >= 1 - 1e-6).mean() > 0.15, frozen.max(axis=1)  # the scene needs the update

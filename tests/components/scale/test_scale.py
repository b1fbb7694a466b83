"""Scale estimators recover a known zoom."""
import cv2
import numpy as np
import pytest

from dcfkit.components.base import Target
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


def test_limits_rounded_inwards_to_whole_powers_of_the_step():
    """The authors' rule: min 1.03^ceil(log(0.05)/log(1.03)) = 1.03^-101 (log ratio -101.35),
    max 1.03^floor(log(24)/log(1.03)) = 1.03^107 (107.51): each within one step inside."""
    lo, hi = scale_limits(np.array([10.0, 20.0]), np.array([100.0, 100.0]), (360, 480), step=1.03)
    assert lo == 1.03 ** -101 and hi == 1.03 ** 107
    assert 0.05 <= lo < 0.05 * 1.03 and 24.0 / 1.03 < hi <= 24.0
    lo, hi = scale_limits(np.array([10.0, 20.0]), np.array([100.0, 100.0]), (360, 480), initial=30.0, step=1.03)
    assert hi == 30.0  # a target larger than the image at its start keeps its size, as without a step


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


# The authors' MATLAB detail this option reproduces, against an independent reference (the
# line worked out by hand or re-run in numpy, a brute-force loop, a dense solve). file.m:line
# cites ../shared/reference/DR2Track/DR2Track1 unless STRCF's (../shared/reference/STRCF) is named.
# --------------------------------------------------------------------------------------------
# the authors' MATLAB: DSST: init_scale.m's model size and window, shift_sample_scale.m
# --------------------------------------------------------------------------------------------

def make_dsst(**params):
    return DSST(DSST.Params(**params))


def stub_samples(dsst, calls, rows=3):
    """_samples returning identifiable columns: the k-th call's scale i is filled with 100 k + i + 1
    (windowed as the real one: times window[i])."""
    def fake(image, centre, scale, which=None, windowed=True):
        which = list(range(len(dsst.factors))) if which is None else list(which)
        calls.append((scale, which, windowed))
        tag = 100 * (len(calls) - 1)
        cols = np.array([tag + i + 1 for i in which], float)
        if windowed:
            cols = cols * dsst.window[which]
        return np.tile(cols, (rows, 1))
    return fake


@pytest.mark.parametrize("target, model", [
    ((40.0, 30.0), (26, 19)),     # 1200 > 512: floor((40, 30) * sqrt(512/1200) = (26.13, 19.60))
    ((20.7, 24.2), (20, 24)),     # 500.94 <= 512: floor
    ((100.0, 14.0), (60, 8)),     # 1400: floor((60.47, 8.47))
    # fhog needs 2 cells: a side under 8 px is raised to 8 (theirs: floor((92.38, 5.54)) = (92, 5),
    # and at least 2 px: (2, 300)); a 7-px-wide target's scale samples failed in fhog before
    ((100.0, 6.0), (92, 8)),
    ((1.5, 300.0), (8, 300)),
])
def test_dsst_model_size_image_target_is_init_scale(monkeypatch, target, model):
    # init_scale.m:16-23 with scale_model_factor = 1 and scale_model_max_area = 512, from the image target
    dsst = make_dsst(model_size="image_target")
    monkeypatch.setattr(dsst, "_samples", lambda *a, **k: np.ones((3, 33)))
    scale = 2.5  # base_target * scale is the target in image pixels
    dsst.init(np.zeros((50, 50, 3), np.uint8), np.array([25.0, 25.0]), np.array(target) / scale, scale, (0.1, 10))
    assert tuple(int(v) for v in dsst.model_size) == model


@pytest.mark.parametrize("template, side", [
    (300.0, 22),   # floor(300 * sqrt(512 / 300²)) = floor(22.63)
    (23.0, 22),    # 529 > 512: shrunk to floor(22.63)
    (22.0, 22),    # 484 <= 512: the template itself
    (15.0, 15),    # a target of about 4 px: floor(15), not 22
    (12.5, 12),
    (6.0, 8),      # at least 2 cells, which fhog needs
    (None, 22),    # no CSR-DCF template: floor(sqrt(512))
])
def test_dsst_model_size_square_is_csr_scale_model_sz(monkeypatch, template, side):
    # create_csr_tracker.m:112-117: floor(template_size * min(1, sqrt(512 / prod(template_size))))
    dsst = make_dsst(model_size="square")
    monkeypatch.setattr(dsst, "_samples", lambda *a, **k: np.ones((3, 33)))
    dsst.start(Target((50, 50), (10, 10), (2.0, 2.0), 4, 1.0, 1.0, template))
    dsst.init(np.zeros((50, 50, 3), np.uint8), np.array([25.0, 25.0]), np.array([5.0, 4.0]), 1.0, (0.1, 10))
    assert tuple(int(v) for v in dsst.model_size) == (side, side)


def test_dsst_hann_window_has_zero_ends(monkeypatch):
    # init_scale.m:12: hann(33) = 0.5 (1 - cos(2π (0:32)/32)) (MATLAB's symmetric window)
    dsst = make_dsst(window="hann")
    monkeypatch.setattr(dsst, "_samples", lambda *a, **k: np.ones((3, 33)))
    dsst.init(np.zeros((50, 50, 3), np.uint8), np.array([25.0, 25.0]), np.array([10.0, 10.0]), 1.0, (0.1, 10))
    k = np.arange(33)
    np.testing.assert_allclose(dsst.window, 0.5 * (1 - np.cos(2 * np.pi * k / 32)), atol=1e-15)
    assert dsst.window[0] == dsst.window[-1] == 0 and dsst.window[16] == 1 and dsst.window[8] == pytest.approx(0.5)


def shift_sample_scale_reference(xs, recovered_scale, scale_window, fresh):
    """shift_sample_scale.m:2-69 in MATLAB's column order (scale 1 the largest), 1-based indices:
    ``fresh(j)`` is the unwindowed sample of scale column j at the new scale."""
    n = xs.shape[1]
    out = np.zeros_like(xs)
    shift_pos = recovered_scale - int(np.ceil(n / 2))
    win = np.concatenate([[np.nan], scale_window])  # win[j], xs1[:, j], out1[:, j]: MATLAB's 1-based j
    xs1 = np.concatenate([np.full((xs.shape[0], 1), np.nan), xs], axis=1)
    out1 = np.concatenate([np.full((xs.shape[0], 1), np.nan), out], axis=1)
    if shift_pos == 0:
        return xs.copy()
    if shift_pos > 0:
        for j in range(1, n - shift_pos + 1):
            out1[:, j] = xs1[:, j + shift_pos] / (win[j + shift_pos] + 1e-5) * win[j]
        for i in range(1, shift_pos + 1):
            j = n - shift_pos + i
            out1[:, j] = fresh(j) * win[j]                      # line 36: windowed
    else:
        for j in range(1, n + shift_pos + 1):
            out1[:, j - shift_pos] = xs1[:, j] / (win[j] + 1e-5) * win[j - shift_pos]
        for i in range(1, -shift_pos + 1):
            out1[:, i] = fresh(i)                                # lines 67-68: windowed, then overwritten
    return out1[:, 1:]


@pytest.mark.parametrize("shift_pos", [2, -3, 0])
def test_dsst_model_update_shift_is_shift_sample_scale(monkeypatch, shift_pos):
    n = 33
    dsst = make_dsst(window="hann", model_update="shift")
    calls = []
    monkeypatch.setattr(dsst, "_samples", stub_samples(dsst, calls))
    dsst.init(np.zeros((50, 50, 3), np.uint8), np.array([25.0, 25.0]), np.array([10.0, 10.0]), 1.0, (0.01, 100))
    # MATLAB's scaleFactors = step^(ceil(n/2) - (1:n)) run from large to small (init_scale.m:15);
    # dcfkit's from small to large: MATLAB column j is dcfkit's scale n - j.
    assert dsst.factors[0] < 1 < dsst.factors[-1]
    recovered = int(np.ceil(n / 2)) + shift_pos   # MATLAB's recovered_scale
    best = n - recovered                           # dcfkit's index of that scale
    # make the scale filter's response a delta at ``best``: num[0] = F(δ_best) (den + λ) / xsf[0]
    xs_search = np.tile((100 + np.arange(n) + 1.0) * dsst.window, (3, 1))  # the search call's (2nd) samples
    xsf = np.fft.fft(xs_search, axis=1)
    assert np.abs(xsf[0]).min() > 1e-9
    dsst.den = np.ones(n)
    dsst.num = np.zeros_like(xsf)
    dsst.num[0] = np.fft.fft(np.eye(n)[best]) * (dsst.den + dsst.params.lam) / xsf[0]
    learnt = []
    monkeypatch.setattr(dsst, "_learn", learnt.append)
    calls.clear()
    calls.append(None)  # so the search call is the 2nd (tag 100), fresh samples the 3rd (tag 200)
    new_scale = dsst.update(np.zeros((50, 50, 3), np.uint8), np.array([25.0, 25.0]), 1.0)
    assert new_scale == pytest.approx(dsst.factors[best])
    got = np.fft.ifft(learnt[0], axis=1).real
    def fresh(j):  # MATLAB column j = dcfkit's scale n - j, unwindowed, from the third call (tag 200)
        return np.full(3, 200 + (n - j) + 1.0)

    expected = shift_sample_scale_reference(xs_search[:, ::-1], recovered, dsst.window[::-1], fresh)[:, ::-1]
    np.testing.assert_allclose(got, expected, rtol=1e-9, atol=1e-9)
    if shift_pos:
        # the missing scales extracted at the NEW scale: MATLAB columns beyond the shift, i.e. dcfkit's
        # scales n - j for j = n - shift_pos + 1..n (shift_pos > 0) or j = 1..-shift_pos (< 0)
        (scale, which, _), = calls[2:]
        assert scale == pytest.approx(new_scale)
        columns = range(n - shift_pos + 1, n + 1) if shift_pos > 0 else range(1, -shift_pos + 1)
        assert sorted(which) == sorted(n - j for j in columns)
    else:
        assert len(calls) == 2  # nothing extracted

"""ARCF's and AutoTrack's new parts, each against an independent reference: the authors' filter
updates (ARCF's tracker_HOGCN.m, AutoTrack's AutoTrack_optimized.m) re-run in numpy on full
complex spectra, as MATLAB computes them, a hand-computed response variation, and the tracker's
handling of what adaptive components return. Paths are to ../shared/reference/{ARCF,AutoTrack}.
"""
import pathlib

import numpy as np
import pytest

import dcfkit
from dcfkit.components.labels.base import Detection, gaussian_label
from dcfkit.components.regularizers import GlobalVariation, LocalVariation, response_variation, target_mask
from dcfkit.components.solvers import ADMMArcf, ADMMAutoTrack, AutoTrackParams, admm
from dcfkit.components.solvers.arcf import ARCFParams
from dcfkit.components.solvers.autotrack import full_spectrum
from dcfkit.datasets.synthetic import make_sequence
from dcfkit.errors import TrackingError
from dcfkit.numerics.fft import make_fft
from dcfkit.numerics.response import response as linear_response

FFT = make_fft("scipy")
AUTOTRACK = str(pathlib.Path(__file__).parents[3] / "configs" / "autotrack.yaml")
rng = np.random.default_rng(7)


def features(shape, channels=3):
    return rng.standard_normal((channels, *shape)).astype(np.float32)


def half(x):
    return np.fft.rfft2(x).astype(np.complex64)


def real_response(g_full, z):
    """real(ifft2(Σ conj(g) ⊙ ẑ)): the response as the authors' code computes it under Octave."""
    return np.real(np.fft.ifft2((np.conj(g_full) * np.fft.fft2(z)).sum(0)))


# --------------------------------------------------------------------------------------------
# ARCF: tracker_HOGCN.m's ADMM, lines 306-341, on full spectra
# --------------------------------------------------------------------------------------------

def arcf_update(model, yf, m_prev, mask, lam, gamma_a, iterations=5):
    """The authors' g/h/l loop, transcribed: model (C, H, W) complex full spectrum, yf (H, W),
    m_prev the spatial map used as a spectrum, mask the crop (small_filter_sz box)."""
    T = yf.size
    g = h = l = np.zeros_like(model)
    mu = 1.0
    s_xx = (np.conj(model) * model).sum(0)
    for _ in range(iterations):
        a = mu / (gamma_a + 1)
        b = s_xx + T * a
        s_lx = (np.conj(model) * l).sum(0)
        s_hx = (np.conj(model) * h).sum(0)
        g = (1 / (1 + gamma_a)) * (((1 / (T * a)) * yf * model + (gamma_a / a) * m_prev * model - (1 / a) * l
                                    + (mu / a) * h)
                                   - model * ((1 / (T * a)) * s_xx * yf + (gamma_a / a) * s_xx * m_prev
                                              - (1 / a) * s_lx + (mu / a) * s_hx) / b)
        spatial = (T / (mu * T + lam)) * np.fft.ifft2(mu * g + l) * mask
        h = np.fft.fft2(spatial)
        l = l + mu * (g - h)
        mu = min(10 * mu, 10000)
    return g


def test_arcf_solver_gives_the_response_of_the_authors_complex_filter():
    shape, lam, gamma_a, lr = (12, 10), 0.01, 0.71, 0.0192
    mask = target_mask(shape, (5.0, 4.0), "authors")
    w2 = np.where(mask, lam, np.inf).astype(np.float32)
    y = gaussian_label(shape, 1.2)
    x1, x2, z = features(shape), features(shape), features(shape)
    detected = rng.random(shape).astype(np.float32)  # the frame-2 response, circular layout

    solver = ADMMArcf(ARCFParams(aberrance=gamma_a, learning_rate=lr))
    hf1 = solver.train(half(x1), half(y), w2, 0.0, FFT)
    solver.observe(Detection(detected, tuple(np.unravel_index(detected.argmax(), shape)), (5.0, 4.0)))
    hf2 = solver.train(half(x2), half(y), w2, 0.0, FFT)

    yf, model1 = np.fft.fft2(y), np.fft.fft2(x1)
    g1 = arcf_update(model1, yf, np.zeros(shape), mask, lam, gamma_a)
    m_prev = np.fft.fftshift(real_response(g1, x1))
    m_curr = np.fft.fftshift(detected)
    move = np.subtract(np.unravel_index(m_curr.argmax(), shape), np.unravel_index(m_prev.argmax(), shape))
    m_prev = np.roll(m_prev, tuple(move), axis=(0, 1))  # circshift by the peak's move
    model2 = (1 - lr) * model1 + lr * np.fft.fft2(x2)
    g2 = arcf_update(model2, yf, m_prev, mask, lam, gamma_a)

    assert np.abs(np.fft.ifft2(g2).imag).max() > 1e-3  # theirs is a complex filter: the check has teeth
    for hf, g in ((hf1, g1), (hf2, g2)):
        ours = linear_response(hf, half(z), shape, FFT)
        expected = real_response(g, z)
        np.testing.assert_allclose(ours, expected, atol=2e-3 * np.abs(expected).max())


def test_arcf_without_aberrance_is_bacf():
    shape = (10, 12)
    w2 = np.where(target_mask(shape, (4.0, 5.0)), 0.01, np.inf).astype(np.float32)
    y, x = half(gaussian_label(shape, 1.0)), half(features(shape))
    arcf = ADMMArcf(ARCFParams(aberrance=0.0, iterations=2, learning_rate=0.013))
    bacf = dcfkit.components.solvers.ADMMBacf()
    np.testing.assert_allclose(arcf.train(x, y, w2, 0.0, FFT), bacf.train(x, y, w2, 0.0, FFT), rtol=1e-5, atol=1e-6)


# --------------------------------------------------------------------------------------------
# AutoTrack: AutoTrack_optimized.m's ADMM with the mu-step, lines 246-280, on full spectra
# --------------------------------------------------------------------------------------------

def autotrack_update(xf, yf, g_pre, w, mu, ref_mu, epsilon, theta_step, iterations=4):
    T = yf.size
    g = h = l = np.zeros_like(xf)
    gamma = 1.0
    s_xx = (np.conj(xf) * xf).sum(0)
    sgx_pre = xf * (np.conj(xf) * g_pre).sum(0)
    for it in range(1, iterations + 1):
        b = s_xx + T * (gamma + mu)
        s_hx = (np.conj(xf) * h).sum(0)
        s_lx = (np.conj(xf) * l).sum(0)
        g = ((1 / (T * (gamma + mu))) * yf * xf - (1 / (gamma + mu)) * l + (gamma / (gamma + mu)) * h
             + (mu / (gamma + mu)) * g_pre
             - ((1 / (T * (gamma + mu))) * xf * (s_xx * yf) + (mu / (gamma + mu)) * sgx_pre
                - (1 / (gamma + mu)) * xf * s_lx + (gamma / (gamma + mu)) * xf * s_hx) / b)
        h = np.fft.fft2(T / (w ** 2 + gamma * T) * np.fft.ifft2(gamma * (g + l)))
        if theta_step and it < iterations:
            mu = ref_mu - np.linalg.norm(g[-1] - g_pre[-1], 2) ** 2 / (2 * epsilon)
        l = l + gamma * (g - h)
        gamma = min(10 * gamma, 10000)
    return g


def test_full_spectrum_rebuilds_fft2_from_the_half():
    for shape in ((6, 8), (7, 9), (5, 4)):
        x = rng.standard_normal(shape)
        np.testing.assert_allclose(full_spectrum(np.fft.rfft2(x), shape[1]), np.fft.fft2(x), atol=1e-9)


@pytest.mark.parametrize("epsilon", [1.0, 3e4])
def test_autotrack_solver_matches_the_authors_loop_with_the_theta_step(epsilon):
    shape, zeta, ref_mu = (10, 12), 13.0, 11.5
    w = np.where(target_mask(shape, (4.0, 5.0), "authors"), 1e-3, 1e5)
    y = np.fft.fft2(gaussian_label(shape, 1.0))
    frames = [features(shape, 4) for _ in range(3)]
    solver = ADMMAutoTrack(AutoTrackParams(iterations=4, h_step="authors", epsilon=epsilon, gamma_max=10000,
                                           theta_first=zeta))
    ours = [solver.train(half(x), half(np.fft.ifft2(y).real), (w ** 2).astype(np.float32), theta, FFT)
            for x, theta in zip(frames, (0.0, zeta, ref_mu))]
    g_pre = np.zeros((4, *shape), complex)
    # AutoTrack_optimized.m:232-235: mu = 0 on frame 1, zeta on every later one; ref_mu only in the mu-step
    for i, (x, mu, step) in enumerate(zip(frames, (0.0, zeta, zeta), (False, False, True))):
        g_pre = autotrack_update(np.fft.fft2(x), y, g_pre, w, mu, ref_mu, epsilon, step)
        expected = np.fft.rfft2(np.fft.ifft2(g_pre).real)
        np.testing.assert_allclose(ours[i], expected, atol=2e-3 * np.abs(expected).max(), err_msg=f"frame {i + 1}")


def test_the_theta_step_is_the_one_admm_runs_between_iterations():
    shape = (8, 8)
    w2 = np.full(shape, 1e-6, np.float32)
    x, y = half(features(shape)), half(gaussian_label(shape, 1.0))
    prev = half(features(shape))
    p = AutoTrackParams(iterations=3)
    seen = []
    admm(x, y, w2, 5.0, prev, p, FFT, theta_step=lambda v: seen.append(v.copy()) or 2.0)
    assert len(seen) == 2  # after every iteration but the last
    fixed, _ = admm(x, y, w2, 5.0, prev, p, FFT)
    stepped, _ = admm(x, y, w2, 5.0, prev, p, FFT, theta_step=lambda v: 2.0)
    assert not np.allclose(fixed, stepped)


# --------------------------------------------------------------------------------------------
# AutoTrack's regularizers
# --------------------------------------------------------------------------------------------

def test_response_variation_by_hand():
    before = np.array([[4.0, 1.0, 2.0], [1.0, 1.0, 1.0], [2.0, 1.0, 0.5]], np.float32)
    now = np.roll(before, (1, 2), axis=(0, 1)) * 1.5  # moved by (1, 2) cells and 50 % higher
    # the peaks at sub-cell offsets (1.4, 2.9) and (0.3, 0.8): floor brings both back to the origin
    variation = response_variation((before, (0.3, 0.8)), Detection(now, (1, 2), (1.0, 1.0), (1.4, 2.9)))
    np.testing.assert_allclose(variation, np.full((3, 3), 0.5), rtol=1e-6)


def detection(response, offset=(0.0, 0.0)):
    return Detection(np.asarray(response, np.float32), (0, 0), (3.0, 3.0), offset)


def test_local_variation_changes_w_inside_the_box_only_from_the_second_detection():
    reg = LocalVariation(LocalVariation.Params(inside=1e-3, outside=1e5, delta=0.2))
    reg.reset()
    shape = (9, 9)
    w2 = reg.weights_squared(shape, (3.0, 3.0))
    mask = target_mask(shape, (3.0, 3.0), "authors")
    first = rng.random(shape) + 0.5
    assert reg.adapt(w2, detection(first)) is w2
    second = first * (1 + rng.random(shape))
    new = reg.adapt(w2, detection(second))
    expected = (0.2 * np.log(np.fft.fftshift(np.abs((second - first) / first)) + 1)) ** 2
    np.testing.assert_allclose(new[mask], expected[mask], rtol=1e-5)
    assert np.array_equal(new[~mask], w2[~mask])


def test_global_variation_lowers_theta_as_the_response_varies_and_holds_on_occlusion():
    reg = GlobalVariation(GlobalVariation.Params(theta=13.0, nu=0.2, occlusion=0.3, norm_scale=1e4))
    reg.reset()
    base = rng.random((20, 20)) + 1.0
    assert reg.weight(None) == 13.0 and reg.weight(detection(base)) == 13.0
    varied = base * 1.5  # Π = 0.5 everywhere: ‖Π‖₂ = 0.5 * 20 (a rank-one matrix)
    eta = 10.0 / 1e4
    assert reg.weight(detection(varied)) == pytest.approx(13.0 / (1 + np.log(0.2 * eta + 1)))
    occluded = varied * 1e4  # Π ≈ 1e4: η ≈ 20 >= 0.3
    assert reg.weight(detection(occluded)) == np.inf


def test_an_occlusion_keeps_the_filter_and_the_tracker_goes_on():
    seq = make_sequence(n_frames=6, seed=3)
    frames, boxes = seq.frames, seq.ground_truth
    tracker = dcfkit.load_tracker(AUTOTRACK)
    tracker.init(frames[0], boxes[0])
    tracker.update(frames[1])
    held = tracker.hf
    tracker.temporal.weight = lambda d: np.inf
    tracker.update(frames[2])
    assert tracker.hf is held
    tracker.temporal.weight = lambda d: 13.0
    tracker.update(frames[3])
    assert tracker.hf is not held


@pytest.mark.parametrize("value, message", [(-1.0, r"expected \[0, 1e\+10\] or inf"),
                                            (np.nan, r"expected \[0, 1e\+10\] or inf")])
def test_a_temporal_weight_out_of_range_is_a_tracking_error_naming_the_frame(value, message):
    seq = make_sequence(n_frames=3, seed=1)
    frames, boxes = seq.frames, seq.ground_truth
    tracker = dcfkit.load_tracker(AUTOTRACK)
    tracker.init(frames[0], boxes[0])
    tracker.temporal.weight.original = lambda d: value  # the hook as the tracker calls it: checked
    with pytest.raises(TrackingError, match=rf"^frame 2: regularizer 'global_variation' \(from dcfkit\): weight\(\) "
                                            rf"returned {value!r}, {message}"):
        tracker.update(frames[1])


def test_a_spatial_adapt_of_the_wrong_shape_is_a_tracking_error():
    seq = make_sequence(n_frames=3, seed=1)
    frames, boxes = seq.frames, seq.ground_truth
    tracker = dcfkit.load_tracker(AUTOTRACK)
    tracker.init(frames[0], boxes[0])
    tracker.spatial.adapt.original = lambda w2, d: w2[:-1]
    with pytest.raises(TrackingError, match=r"^frame 2: regularizer 'local_variation' \(from dcfkit\): adapt\(\) "
                                            r"returned shape \(\d+, \d+\), expected \(\d+, \d+\)"):
        tracker.update(frames[1])


def test_inf_on_the_first_frame_is_refused():
    seq = make_sequence(n_frames=2, seed=1)
    frames, boxes = seq.frames, seq.ground_truth
    tracker = dcfkit.load_tracker(AUTOTRACK)
    tracker.temporal.weight = lambda d: np.inf
    with pytest.raises(TrackingError, match="frame 1: .*inf on the first frame"):
        tracker.init(frames[0], boxes[0])

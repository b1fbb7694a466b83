"""CSR-DCF's hooks in the tracker: the mask reaches the solver as w², channel weights weight
the response, its geometry (padded square template, small-target cells, fixed σ)."""
import numpy as np
import pytest

import dcfkit
from dcfkit.config.tracker_params import TrackerParams
from dcfkit.datasets.synthetic import make_sequence
from dcfkit.tracker.geometry import geometry, label_sigma


@pytest.fixture(scope="module")
def sequence():
    return make_sequence(n_frames=40, seed=5)


def test_csrdcf_trains_inside_its_mask_and_weights_its_channels(sequence):
    tracker = dcfkit.load_tracker("csrdcf")
    seen = []
    train = tracker.solver.train
    tracker.solver.train = lambda xf, yf, w2, theta, fft: (seen.append(w2), train(xf, yf, w2, theta, fft))[1]
    tracker.init(sequence.frames[0], sequence.ground_truth[0])
    for frame in sequence.frames[1:10]:
        tracker.update(frame)
    inside = [np.isfinite(w2) for w2 in seen]
    assert len(seen) == 10 and all(0 < m.sum() < m.size / 2 for m in inside)  # a mask, not the whole grid
    h = tracker.fft.irfft2(tracker.solver.frame_filter, tracker.geometry.filter_size)
    assert np.abs(h[:, ~inside[-1]]).max() < 1e-5 * np.abs(h).max()  # the frame's filter is zero outside it
    w = tracker.channel_weights.weights
    assert w.shape == (18 + 1 + 10,) and w.sum() == pytest.approx(1) and w.std() > 0
    assert tracker.channel_weights.discrimination is not None


def test_the_padded_square_template_by_hand():
    p = TrackerParams(search_area_scale=4, search_area_shape="padded_square", min_image_sample_size=64,
                      max_image_sample_size=200**2, cell_size=4, cell_area=400, output_sigma=1)
    # 30 x 60 (h, w): sqrt = 42.43, floor(30 + 127.28) = 157, floor(60 + 127.28) = 187: side 172
    g, scale = geometry(p, np.array([30.0, 60.0]))
    assert g.cell_size == 4  # ceil(1800 / 400) = 5, at most 4
    assert g.filter_size == (43, 43) and scale == 1.0  # floor(172 / 4); 172 < 200: not rescaled
    assert label_sigma(p, g) == 1.0
    # 60 x 100: side mean(floor(60 + 232.38), floor(100 + 232.38)) = 312, rescaled by 200/312 to 200 px
    g, scale = geometry(p, np.array([60.0, 100.0]))
    assert g.filter_size == (50, 50) and scale == pytest.approx(312 / 200)
    np.testing.assert_allclose(g.target_cells, np.array([60.0, 100.0]) * 200 / 312 / 4)
    # a 15 x 20 target: ceil(300 / 400) = 1 pixel per cell
    g, _ = geometry(p, np.array([15.0, 20.0]))
    assert g.cell_size == 1 and g.filter_size[0] == int(np.mean(np.floor(np.array([15, 20]) + 3 * np.sqrt(300))))


def test_csr_moves_from_the_exact_centre_and_reports_the_box_at_the_old_scale(sequence):
    # track_csr_tracker: c = tracker.c + d although the patch is cut around floor(c), and
    # region = [c - currentScaleFactor * base_target_sz / 2, ...] before the scale update
    tracker = dcfkit.load_tracker("csrdcf")
    tracker.init(sequence.frames[0], sequence.ground_truth[0])
    peaks, find = [], tracker._peak
    tracker._peak = lambda maps, samples: peaks.append(find(maps, samples)) or peaks[-1]
    for frame in sequence.frames[1:6]:
        before, scale = tracker.position.copy(), tracker.scale
        box = tracker.update(frame)
        _, dy, dx = peaks[-1]
        step = tracker.geometry.cell_size * scale
        np.testing.assert_allclose(tracker.position, before + np.array([dy, dx]) * step)
        assert box[2:] == pytest.approx(tuple(tracker.geometry.base_target[::-1] * scale))

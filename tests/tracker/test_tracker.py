"""Whole trackers: every shipped config on a generated sequence, bad input, determinism."""
import cv2
import numpy as np
import pytest

import dcfkit
from dcfkit.analysis.metrics import score_sequence
from dcfkit.components.features.base import Feature
from dcfkit.components.labels.base import Detection, Label, gaussian_label
from dcfkit.components.labels.distractors import authors_distractors
from dcfkit.contracts import checked
from dcfkit.datasets.synthetic import make_sequence
from dcfkit.errors import ConfigError, InputError, TrackingError
from dcfkit.numerics.patches import round_half_away
from dcfkit.numerics.response import shift_spectrum
from dcfkit.tracker.geometry import reported_box

CONFIGS = ["strcf", "bacf", "dr2track", "kcf", "dsst", "csrdcf", "configs/ablations/dr2track_no_dr.yaml",
           "configs/ablations/dr2track_no_ma.yaml"]


@pytest.fixture(scope="module")
def sequence():
    return make_sequence(n_frames=60, seed=3)


def run(tracker, frames, box):
    tracker.init(frames[0], box)
    return [tuple(box)] + [tracker.update(f) for f in frames[1:]]


@pytest.mark.parametrize("config", CONFIGS)
def test_shipped_config_tracks_the_synthetic_sequence(config, sequence, request):
    path = request.config.rootpath / config if config.endswith(".yaml") else config
    boxes = run(dcfkit.load_tracker(path), sequence.frames, sequence.ground_truth[0])
    scores = score_sequence(boxes, sequence.ground_truth)
    assert scores["precision"] >= 0.95
    assert scores["auc"] >= 0.6


@pytest.mark.parametrize("config", ["dr2track", "ablations/dr2track_paper"])
def test_tracking_is_deterministic_and_exposes_diagnostics(sequence, config):
    a = run(dcfkit.load_tracker(config), sequence.frames[:15], sequence.ground_truth[0])
    tracker = dcfkit.load_tracker(config)
    b = run(tracker, sequence.frames[:15], sequence.ground_truth[0])
    assert a == b
    assert tracker.last_response.shape == tracker.geometry.filter_size
    peak = np.unravel_index(tracker.last_response.argmax(), tracker.last_response.shape)
    centre = np.array(tracker.geometry.filter_size) // 2  # centred layout: offset 0 in the middle
    assert np.abs(np.array(peak) - centre).max() <= 4  # (not near a corner, as the raw layout would be)
    assert tracker.last_distractors.ndim == 2 and tracker.last_distractors.shape[1] == 2
    assert 0 < len(tracker.last_distractors) <= 30

    # last_search_box maps the response onto the image: its peak is the tracked centre, and
    # every repressed distractor (x, y) falls on (within a cell of) a local maximum of the map
    # (label.selection local_maxima; the authors' lookup, in the shipped config, also takes the
    # rows x columns of equal values: tests/components/labels/test_labels.py checks it by hand)
    R = tracker.last_response
    H, W = R.shape
    sx, sy, sw, sh = tracker.last_search_box
    cell = np.array([sh / H, sw / W])
    assert np.allclose(cell, tracker.params.cell_size * tracker.scale, rtol=0.05)
    search_centre = np.array([sy + (sh - 1) / 2, sx + (sw - 1) / 2])

    def to_cell(y, x):
        return np.round((np.array([y, x]) - search_centre) / cell).astype(int) + [H // 2, W // 2]

    x, y, w, h = tracker.box
    assert np.abs(to_cell(y + (h - 1) / 2, x + (w - 1) / 2) - peak).max() <= 1
    padded = np.pad(R, 1, mode="wrap")
    is_max = R >= np.max([padded[1 + a:1 + a + H, 1 + b:1 + b + W] for a in (-1, 0, 1) for b in (-1, 0, 1)], axis=0)
    if tracker.label.params.selection == "authors":
        return
    for dx_, dy_ in tracker.last_distractors:
        r, c = to_cell(dy_, dx_)
        near = is_max[np.ix_(np.arange(r - 1, r + 2) % H, np.arange(c - 1, c + 2) % W)]
        assert near.any(), (r, c)


def test_overrides_reach_the_components():
    tracker = dcfkit.load_tracker("dr2track", label__mu=0.4, overrides={"solver.iterations": 2})
    assert tracker.label.params.mu == 0.4 and tracker.solver.params.iterations == 2


def test_grayscale_frames_are_tracked(sequence):
    import cv2

    gray = [cv2.cvtColor(f, cv2.COLOR_BGR2GRAY) for f in sequence.frames[:20]]
    boxes = run(dcfkit.load_tracker("dr2track"), gray, sequence.ground_truth[0])
    scores = score_sequence(boxes, sequence.ground_truth[:20])
    assert scores["precision"] >= 0.9


@pytest.mark.parametrize("box,match", [
    ((10, 10, 0, 20), "non-positive size"),
    ((10, 10, 20, -3), "non-positive size"),
    ((900, 10, 20, 20), "outside the 480x360 image"),
    ((10, 10, 0.5, 20), "under a pixel wide or tall"),
    ((10, 10, 20, 3601), "more than 10 times as wide or as tall as the 480x360 image"),
    ((1, 2, 3), "4 finite numbers"),
    ((np.nan, 2, 3, 4), "4 finite numbers"),
])
def test_bad_initial_box_is_a_clear_error(box, match, sequence):
    with pytest.raises(InputError, match=match):
        dcfkit.load_tracker("strcf").init(sequence.frames[0], box)


def test_bad_frames_are_clear_errors_naming_the_frame(sequence):
    tracker = dcfkit.load_tracker("strcf")
    with pytest.raises(TrackingError, match="before init"):
        tracker.update(sequence.frames[0])
    with pytest.raises(InputError, match="frame 1: expected a uint8 image"):
        tracker.init(sequence.frames[0].astype(np.float32), (10, 10, 20, 20))
    tracker.init(sequence.frames[0], sequence.ground_truth[0])
    with pytest.raises(InputError, match="frame 2: the image is empty"):
        tracker.update(np.zeros((0, 0, 3), np.uint8))
    with pytest.raises(InputError, match=r"frame 3: expected an HxW or HxWx3 image, got shape \(10, 10, 4\)"):
        tracker.update(np.zeros((10, 10, 4), np.uint8))
    with pytest.raises(InputError, match="frame 4: expected a numpy image"):
        tracker.update(None)


def test_a_frame_of_another_size_is_refused(sequence):
    tracker = dcfkit.load_tracker("strcf")
    tracker.init(sequence.frames[0], sequence.ground_truth[0])
    before = tracker.box
    with pytest.raises(InputError, match=r"frame 2: the image is 2x2, but the sequence's first frame was 480x360"):
        tracker.update(sequence.frames[1][:2, :2])  # used to snap the box to the corner for good
    assert tracker.box == before
    assert np.hypot(*np.subtract(tracker.update(sequence.frames[2])[:2], sequence.ground_truth[2][:2])) < 5


@pytest.mark.parametrize("box", [(-600, 100, 1000, 40), (100, -500, 40, 800)], ids=["wide", "tall"])
def test_a_box_longer_than_the_image_keeps_its_size(box, sequence):
    tracker = dcfkit.load_tracker("strcf")
    tracker.init(sequence.frames[0], box)  # the scale limit used to shrink it: 1000x40 -> 480x19.2
    np.testing.assert_allclose(tracker.box, box)


def test_initial_box_errors_say_what_is_wrong(sequence):
    tracker = dcfkit.load_tracker("strcf")
    for box in [(True, True, True, True), (10 + 1j, 10, 20, 20), ("10", "10", "20", "20")]:
        with pytest.raises(InputError, match="must be 4 numbers"):
            tracker.init(sequence.frames[0], box)
    flat = np.full_like(sequence.frames[0], 90)
    flat[300:, 400:] = sequence.frames[0][300:, 400:]  # texture far from the box
    with pytest.raises(InputError, match=r"blank.*the box centre \(x=-18, y=-18\) is outside the 480x360 image"):
        tracker.init(flat, (-40, -40, 45, 45))  # said only "blank" before


def test_labels_stay_finite_for_a_vanishing_sigma():
    from dcfkit.components.labels.base import gaussian_label
    from dcfkit.components.scale.dsst import DSST

    g = gaussian_label((8, 8), 1e-300)  # σ² underflows to 0: used to give NaN at the peak
    assert g[0, 0] == 1 and g.sum() == 1
    dsst = DSST(DSST.Params(sigma_factor=1e-300))
    image = make_sequence(n_frames=2).frames[0]
    dsst.init(image, np.array([180.0, 200.0]), np.array([22.0, 36.0]), 1.0, (0.1, 10.0))
    assert np.all(np.isfinite(dsst.label_f))


def sliding(image, n, dx, dy):
    """``n`` frames of ``image`` moved by (dx, dy) px per frame, the image edge repeated."""
    import cv2

    return [cv2.warpAffine(image, np.float32([[1, 0, dx * k], [0, 1, dy * k]]), image.shape[1::-1],
                           borderMode=cv2.BORDER_REPLICATE) for k in range(n)]


def centres(boxes):
    boxes = np.asarray(boxes, float)
    return boxes[:, :2] + (boxes[:, 2:] - 1) / 2


@pytest.mark.parametrize("config", ["strcf", "bacf", "dr2track", "kcf", "dsst"])
@pytest.mark.parametrize("box", [(200, 150, 5, 4), (0, 0, 480, 360), (470, 350, 30, 30)],
                         ids=["tiny", "whole-image", "partly-outside"])
def test_extreme_boxes_follow_the_image_content(config, box, sequence):
    """A 5x4 box, the whole image and a box mostly off the image, on a frame sliding by
    (-2, -1.5) px a frame: the boxes stay finite, keep their size within a fifth (the content
    does not change scale), and end near where the content under them went: within a third
    of its 22.5 px journey, which a box left in place would miss. (The partly-outside box
    starts with its centre off the image, clamped onto it, so only the end is checked.)"""
    velocity = np.array([-2.0, -1.5])
    # the tracking, not the reported box's rounding (BACF's floors a 5x4 box to 4x3 at scale 0.99)
    tracker = dcfkit.load_tracker(config, overrides={"tracker.box_output": "exact"})
    boxes = np.array(run(tracker, sliding(sequence.frames[0], 10, *velocity), box))
    assert np.all(np.isfinite(boxes))
    assert np.all((boxes[:, 2:] > 0.8 * np.array(box[2:])) & (boxes[:, 2:] < 1.25 * np.array(box[2:])))
    if box[2] < 10 and config in ("kcf", "dsst"):
        return  # their papers' search area (2.5 and 2 times the box, 4-px cells, no upsampling) is 4x4 cells here
    travel = 9 * velocity
    assert np.hypot(*(centres(boxes)[-1] - centres([box])[0] - travel)) < np.hypot(*travel) / 3


def test_target_leaving_the_image_is_followed_to_the_edge_and_kept_on_the_image():
    """The content slides out to the left at 8 px a frame (the image edge repeated) until none
    of it is left. While the target's centre is on the image the box moves with it; after
    that the boxes stay finite with a positive size and the tracked centre on the image."""
    box = (20, 150, 30, 20)
    frames = sliding(make_sequence(n_frames=1, seed=1).frames[0], 61, -8, 0)
    tracker = dcfkit.load_tracker("dr2track")
    tracker.init(frames[0], box)
    boxes, positions = [box], [tracker.position.copy()]
    for frame in frames[1:]:
        boxes.append(tracker.update(frame))
        positions.append(tracker.position.copy())
    expected = centres([box]) + np.outer(np.arange(len(frames)), [-8, 0])
    visible = expected[:, 0] >= 0  # frames 1-5
    assert visible.sum() == 5 and np.abs(centres(boxes)[visible] - expected[visible]).max() < 2
    assert np.all(np.isfinite(boxes)) and all(b[2] > 0 and b[3] > 0 for b in boxes)
    positions = np.array(positions)  # (y, x)
    assert np.all((positions >= 0) & (positions <= np.array(frames[0].shape[:2]) - 1))


def test_pyfftw_backend_tracks_like_scipy(sequence):
    frames, box = sequence.frames[:30], sequence.ground_truth[0]
    reference = np.array(run(dcfkit.load_tracker("dr2track"), frames, box))
    boxes = np.array(run(dcfkit.load_tracker("dr2track", overrides={"tracker.fft_backend": "pyfftw"}), frames, box))
    assert np.abs(boxes - reference).max() < 0.5  # the two FFT libraries differ in the last bits only


@pytest.mark.parametrize("config", ["strcf", "bacf", "dr2track", "kcf", "dsst"])
def test_dropped_black_frames_are_held_and_not_learnt(config, sequence):
    frames = list(sequence.frames[:30])
    frames[10] = frames[11] = np.zeros_like(frames[10])
    tracker = dcfkit.load_tracker(config)
    boxes = run(tracker, frames, sequence.ground_truth[0])
    assert tracker.held_frames == [11, 12]  # 1-based frame numbers
    assert boxes[10] == boxes[11] == boxes[9]  # held where frame 10 left it
    assert tracker.last_response is not None  # the frames after were tracked again
    assert score_sequence(boxes, sequence.ground_truth[:30])["precision"] >= 0.95
    # off: the black frames are tracked like any other, and the box moves
    tracker = dcfkit.load_tracker(config, overrides={"tracker.blank_std": 0})
    boxes = run(tracker, frames, sequence.ground_truth[0])
    assert tracker.held_frames == []
    if config != "kcf":  # KCF's one feature, fHOG, is 0 on a black frame: a flat response, the box stays
        assert boxes[10] != boxes[9]


def test_a_held_frame_leaves_the_filter_and_scale_unchanged(sequence):
    tracker = dcfkit.load_tracker("dr2track")
    run(tracker, sequence.frames[:5], sequence.ground_truth[0])
    hf, scale, position = tracker.hf.copy(), tracker.scale, tracker.position.copy()
    tracker.update(np.zeros_like(sequence.frames[5]))
    assert np.array_equal(tracker.hf, hf) and tracker.scale == scale and np.array_equal(tracker.position, position)


@pytest.mark.parametrize("config,level", [("strcf", 90), ("eco_hc", 0)])  # the discrete and the continuous loop
def test_blank_first_frame_is_a_clear_error_and_changes_nothing(sequence, config, level):
    blank, box = np.full_like(sequence.frames[0], level), sequence.ground_truth[0]
    fresh = dcfkit.load_tracker(config)
    with pytest.raises(InputError, match=r"frame 1: the search area around the initial box is blank"):
        fresh.init(blank, box)
    with pytest.raises(TrackingError, match="before init"):
        fresh.update(sequence.frames[1])
    # a tracker that was tracking goes on as if the failed init had not happened
    tracking, reference = dcfkit.load_tracker(config), dcfkit.load_tracker(config)
    run(tracking, sequence.frames[:5], box)
    run(reference, sequence.frames[:5], box)
    with pytest.raises(InputError):
        tracking.init(blank, (box[0], box[1], box[2] * 2, box[3] * 2))
    assert [tracking.update(f) for f in sequence.frames[5:8]] == [reference.update(f) for f in sequence.frames[5:8]]


class _BadLabel(Label):
    name = "bad_label"

    def __init__(self, make):
        super().__init__()
        self.make = make


@pytest.mark.parametrize("make, frame, match", [
    (lambda g, d: g, 1, r"returned a ndarray, expected a tuple \(y, offsets\)"),
    (lambda g, d: (np.zeros((g.shape[0], g.shape[1] + 1)), np.zeros((0, 2))), 1,
     r"returned y of shape \(\d+, \d+\), expected \(\d+, \d+\)"),
    (lambda g, d: (g * (np.nan if d is not None else 1), np.zeros((0, 2))), 2, r"returned y: NaN or infinite values"),
    (lambda g, d: (g, np.zeros(4)), 1, r"returned offsets of shape \(4,\), expected \(N, 2\)"),
    (lambda g, d: (g.__setitem__((1, 1), 0), g)[1:] * 2, 1,
     r"raised ValueError: assignment destination is read-only \(at .*test_tracker.py:\d+\)"),
])
def test_a_label_returning_the_wrong_thing_is_named_with_the_frame(make, frame, match, sequence):
    tracker = dcfkit.load_tracker("strcf")
    tracker.label = checked(_BadLabel(make), "tests", Label.contract.hooks())
    with pytest.raises(TrackingError, match=rf"^frame {frame}: label 'bad_label' \(from tests\): make\(\) " + match):
        run(tracker, sequence.frames[:4], sequence.ground_truth[0])


class _BadFeature(Feature):
    name = "bad_feature"

    def __init__(self, extract):
        super().__init__()
        self.extract = extract

    def channels(self):
        return 2


@pytest.mark.parametrize("extract, match", [
    (lambda p, c: np.zeros((2, p.shape[0] // c, p.shape[1] // c + 1), np.float32),
     r"returned shape \(2, \d+, \d+\), expected \(2, \d+, \d+\)"),
    (lambda p, c: [0.0], r"returned a list, expected a numpy array of real floats"),
    (lambda p, c: np.full((2, p.shape[0] // c, p.shape[1] // c), np.inf, np.float32),
     r"returned NaN or infinite values"),
    (lambda p, c: p.reshape(-1, 7), r"raised ValueError: cannot reshape"),
])
def test_a_feature_returning_the_wrong_thing_is_named_with_the_frame(extract, match, sequence):
    tracker = dcfkit.load_tracker("strcf")
    tracker.features.append(checked(_BadFeature(extract), "tests", Feature.contract.hooks()))
    with pytest.raises(TrackingError, match=r"^frame 1: feature 'bad_feature' \(from tests\): extract\(\) " + match):
        tracker.init(sequence.frames[0], sequence.ground_truth[0])


@pytest.mark.parametrize("config, scale, cells, sigma, rows, cols", [
    # 40x30 box: search square 5·√1200 = 173.2 px. STRCF: area 30000 within [150², 200²], so scale 1,
    # 43 cells of 4 px, target 7.5x10 cells (floored 7x10): σ = √70 / 16, box rows 18-24, cols 16-25
    ("strcf", 1.0, 43, np.sqrt(70) / 16, (18, 25), (16, 26)),
    # DR²Track: the sample is 200², scale √(30000/40000), 50 cells, target 8.66x11.5 cells (8x11):
    # σ = √88 · 0.058, box rows 21-28; its 11 columns placed as the authors' init_regwindow puts
    # an odd box, from ceil((50 - 11) / 2) = 20: cols 20-30
    ("dr2track", np.sqrt(0.75), 50, np.sqrt(88) * 0.058, (21, 29), (20, 31)),
])
def test_first_frame_geometry_label_and_window_hand_computed(config, scale, cells, sigma, rows, cols, sequence):
    tracker = dcfkit.load_tracker(config)
    tracker.init(sequence.frames[0], (100.0, 80.0, 40.0, 30.0))
    assert tracker.scale == pytest.approx(scale) and tracker.geometry.filter_size == (cells, cells)
    np.testing.assert_allclose(tracker.base_label, gaussian_label((cells, cells), sigma), atol=1e-7)
    inside = np.zeros((cells, cells), bool)
    inside[rows[0]:rows[1], cols[0]:cols[1]] = True
    np.testing.assert_allclose(tracker.w2, np.where(inside, 1e-6, 1e10), rtol=1e-6)


@pytest.mark.parametrize("config, step", [("strcf", 1.01), ("dr2track", 1.03), ("kcf", None)])
def test_scale_limits_step_powers_rounds_the_exact_limits_by_the_estimators_step(config, step, sequence):
    """tracker.scale_limits: step_powers is the exact limits rounded inwards to powers of the scale
    estimator's step (the pyramid's 1.01, the DSST's 1.03); a fixed scale has no step to round by."""
    limits = {}
    for rule in ("exact", "step_powers"):
        tracker = dcfkit.load_tracker(config, tracker__scale_limits=rule, tracker__clamp_position=True)
        tracker.init(sequence.frames[0], sequence.ground_truth[0])
        limits[rule] = tracker.limits
    lo, hi = limits["exact"]
    if step is None:
        assert limits["step_powers"] == limits["exact"]
        return
    assert limits["step_powers"] == (step ** np.ceil(np.log(lo) / np.log(step)),
                                     step ** np.floor(np.log(hi) / np.log(step)))
    assert lo <= limits["step_powers"][0] < lo * step and hi / step < limits["step_powers"][1] <= hi


class _RecordingScale:
    """Stands in for the scale estimator: keeps the scale and records where it was asked to look."""

    def __init__(self):
        self.centres = []

    def search_factors(self):
        return np.ones(1)

    def update(self, image, centre, scale):
        self.centres.append(np.array(centre, float))
        return scale


def test_the_scale_is_estimated_at_the_new_position_not_the_search_centre(sequence):
    tracker = dcfkit.load_tracker("dr2track")
    tracker.init(sequence.frames[0], sequence.ground_truth[0])
    recorder = tracker.scale_estimator = _RecordingScale()
    for frame in sequence.frames[1:6]:
        centre = tracker.search.centre()
        tracker.update(frame)
        np.testing.assert_array_equal(recorder.centres[-1], tracker.position)  # Algorithm 1: at p^t
    assert np.abs(centre - tracker.position).max() > 1  # the target moved off the search centre


def test_training_on_the_shifted_detection_sample_moves_it_to_the_new_position(sequence):
    """training_sample: shift trains on the detection sample translated by p^t - centre; it must
    line up with the sample taken at p^t better than the opposite translation does."""
    tracker = dcfkit.load_tracker("strcf", overrides={"tracker.training_sample": "shift", "scale.n_scales": 1})
    frames = sequence.frames
    tracker.init(frames[0], sequence.ground_truth[0])
    trained = []
    original = tracker.solver.train
    tracker.solver.train = lambda xf, *rest: (trained.append(xf), original(xf, *rest))[1]
    for frame in frames[1:4]:
        tracker.update(frame)
    centre, frame = tracker.search.centre(), frames[4]
    tracker.update(frame)
    size, step = tracker.geometry.filter_size, tracker.params.cell_size * tracker.scale
    moved = (tracker.position - centre) / step
    assert np.abs(moved).max() > 0.5  # at least half a cell
    at_position = tracker.fft.irfft2(tracker._sample(frame, tracker.position, tracker.scale), size)
    detection = tracker._sample(frame, centre, tracker.scale)

    def agreement(xf):
        x = tracker.fft.irfft2(xf, size)
        return float(np.sum(x * at_position) / np.sqrt(np.sum(x * x) * np.sum(at_position * at_position)))

    used = agreement(trained[-1])
    assert used > agreement(shift_spectrum(detection, -moved[0], -moved[1], size))
    assert used > agreement(detection)  # and better than not moving it at all


def test_the_strongest_repressed_peak_is_the_look_alike_when_it_is_in_view(sequence):
    """Eq. (3) in the loop: while the synthetic sequence's look-alike is inside the search area,
    the highest background maximum that DR²Track represses is, most of the time, on it (the
    paper's orientation; the authors' code, and the shipped config, repress its mirror image)."""
    tracker = dcfkit.load_tracker("ablations/dr2track_paper")
    tracker.init(sequence.frames[0], sequence.ground_truth[0])
    on_it = in_view = 0
    for frame, twin in zip(sequence.frames[1:], sequence.distractor[1:]):
        tracker.update(frame)
        centre = twin[:2] + (twin[2:] - 1) / 2
        x, y, w, h = tracker.last_search_box
        if x <= centre[0] <= x + w and y <= centre[1] <= y + h:
            in_view += 1
            on_it += np.linalg.norm(tracker.last_distractors[0] - centre) < twin[3] / 2
    assert in_view >= 10 and on_it >= 0.7 * in_view


# The authors' MATLAB detail this option reproduces, against an independent reference (the
# line worked out by hand or re-run in numpy, a brute-force loop, a dense solve). file.m:line
# cites ../shared/reference/DR2Track/DR2Track1 unless STRCF's (../shared/reference/STRCF) is named.
# --------------------------------------------------------------------------------------------
# the authors' MATLAB: tracker: init_position, box_output, clamp_position, translation
# --------------------------------------------------------------------------------------------

def texture(shape, seed=0, blur=1.5):
    rng = np.random.default_rng(seed)
    return cv2.GaussianBlur((rng.random(shape) * 255).astype(np.uint8), (0, 0), blur)


@pytest.mark.parametrize("box, position, size", [
    # tracker.m:10-11 with run_DR2Track.m:90-91: 1-based pos = floor([y x] + floor([h w]/2)),
    # target_sz = floor([h w]). Box (10.6, 20.3, 31.7, 21.4) is 1-based (11.6, 21.3, ...):
    # pos = floor([21.3 + 10, 11.6 + 15]) = [31, 26] -> 0-based (30, 25); size (21, 31)
    ((10.6, 20.3, 31.7, 21.4), (30, 25), (21, 31)),
    # (0, 0, 20, 15) -> 1-based (1, 1): pos = floor([1 + 7, 1 + 10]) = [8, 11] -> (7, 10) (exact: (7, 9.5))
    ((0.0, 0.0, 20.0, 15.0), (7, 10), (15, 20)),
    ((40.2, 35.9, 27.0, 33.0), (51, 53), (33, 27)),  # floor([36.9 + 16, 41.2 + 13]) - 1 = (51, 53)
])
def test_init_position_whole_pixel(box, position, size):
    image = texture((120, 160, 3))
    tracker = dcfkit.load_tracker("strcf", overrides={"tracker.init_position": "whole_pixel"})
    tracker.init(image, box)
    assert tuple(tracker.position) == position
    np.testing.assert_allclose(tracker.geometry.base_target * tracker.scale, size, rtol=1e-12)


@pytest.mark.parametrize("output, box, expected", [
    # tracker.m:43-45 (DR²Track): target_sz = round(base_target_sz * scale), rect = [pos - sz/2, sz]
    # (1-based pos = 0-based + 1, and the 1-based x becomes 0-based by -1: the same x = cx - w/2).
    # box (11.5, 20.3, 30, 36.5): centre (20.3 + 17.75, 11.5 + 14.5) = (38.05, 26); round(36.5) = 37
    ("half_size", (11.5, 20.3, 30.0, 36.5), (26 - 15, 38.05 - 18.5, 30, 37)),
    # STRCF's report_tracking_result.m:4: round([pos - (sz - 1)/2, sz]), 1-based: x = round(27 - 14.5)
    # = round(12.5) = 13 -> 0-based 12; y = round(39.05 - 17.75) = round(21.3) = 21 -> 20; h = 37
    ("rounded", (11.5, 20.3, 30.0, 36.5), (12, 20, 30, 37)),
    # centre (20.3 + 14.7, 10.6 + 15.35) = (35, 25.95): x = round(26.95 - 15.35) = round(11.6) = 12 -> 11,
    # y = round(36 - 14.7) = round(21.3) = 21 -> 20, w = round(31.7) = 32, h = round(30.4) = 30
    ("rounded", (10.6, 20.3, 31.7, 30.4), (11, 20, 32, 30)),
    # x = -0.5: 1-based 0.5 rounds to 1 -> 0-based 0 (rounding the 0-based -0.5 would give -1)
    ("rounded", (-0.5, 20.3, 30.0, 36.5), (0, 20, 30, 37)),
    ("exact", (11.5, 20.3, 30.0, 36.5), (11.5, 20.3, 30.0, 36.5)),
])
def test_box_output(output, box, expected):
    # a target area between 22500/25 and 40000/25 px²: currentScaleFactor = 1, the size is the box's
    image = texture((120, 160, 3))
    tracker = dcfkit.load_tracker("strcf", overrides={"tracker.box_output": output})
    tracker.init(image, box)
    assert tracker.scale == 1.0
    np.testing.assert_allclose(tracker.box, expected, atol=1e-9)


@pytest.mark.parametrize("convention, expected", [
    ("floor_half", (20.0, 10.0, 1.0, 1.0)),   # floor(0.3), floor(0.4) = 0 -> 1; x = 20 - floor(1 / 2)
    ("half_size", (19.5, 9.5, 1.0, 1.0)),     # round(0.3), round(0.4) = 0 -> 1; x = 20 - 1 / 2
    ("rounded", (20.0, 10.0, 1.0, 1.0)),      # x = round(20 - (0.3 - 1) / 2 + 1) - 1 = 20; w = round(0.3) -> 1
    ("exact", (20.35, 10.3, 0.3, 0.4)),       # not rounded: the size itself, positive
])
def test_a_rounded_box_keeps_a_pixel_below_a_pixel(convention, expected):
    """A target smaller than a pixel (centre (y, x) = (10, 20), size (h, w) = (0.4, 0.3)) is
    reported with at least one pixel, never the empty box the authors' floor or round gives."""
    box = reported_box(np.array([10.0, 20.0]), np.array([0.4, 0.3]), convention)
    np.testing.assert_allclose(box, expected, atol=1e-12)


def sliding_frames(n, step, width=160):
    """A textured scene sliding left by ``step`` pixels a frame (the target moves with it)."""
    world = texture((120, width + step * n, 3), seed=3)
    return [np.ascontiguousarray(world[:, step * t: step * t + width]) for t in range(n)]


@pytest.mark.parametrize("clamp", [False, True])
def test_clamp_position_false_lets_the_target_leave_the_image(clamp):
    frames = sliding_frames(7, 4)
    tracker = dcfkit.load_tracker("strcf", overrides={"tracker.clamp_position": clamp})
    tracker.init(frames[0], (5.0, 50.0, 30.0, 30.0))  # centre x = 19.5, then 15.5, 11.5, ... -4.5
    for frame in frames[1:]:
        tracker.update(frame)
    truth = 19.5 - 4 * 6
    if clamp:
        assert tracker.position[1] == 0.0  # held on the image
    else:
        assert tracker.position[1] < 0 and abs(tracker.position[1] - truth) < 1.0


@pytest.mark.parametrize("translation", ["whole_pixel", "exact"])
def test_translation_whole_pixel_moves_by_whole_pixels(translation):
    frames = sliding_frames(5, 3)
    tracker = dcfkit.load_tracker("strcf", overrides={"tracker.translation": translation, "tracker.sampling": "subpixel"})
    tracker.init(frames[0], (60.3, 40.6, 30.0, 30.0))  # centre (55.1, 74.8): not a whole pixel
    moves = []
    for frame in frames[1:]:
        before = tracker.position.copy()  # STRCF's fixed search: the search centre is the last position
        tracker.update(frame)
        moves.append(tracker.position - before)
    moves = np.array(moves)
    fractional = np.abs(moves - np.round(moves))
    assert np.abs(moves[:, 1]).min() > 2  # it tracks the slide
    if translation == "whole_pixel":  # run_detection.m:27: translation_vec = round(disp * cell * scale)
        assert fractional.max() < 1e-9
    else:
        assert fractional.max() > 1e-3


def test_shift_mode_gives_the_label_the_newton_peak_and_trains_at_the_clamped_position(monkeypatch):
    # tracker.m:69 centres the distractor map with round(-[disp_row, disp_col]), resp_newton's peak,
    # not the rounded pixel move over the new scale (they round apart, e.g. 2.45 cells -> 10 px -> 2.5)
    import dcfkit.tracker.tracker as tracker_module

    frames = sliding_frames(6, 5)  # 5 px = 1.67 cells of 3 px: sub-cell peaks
    tracker = dcfkit.load_tracker("reference/dr2track", overrides={"tracker.clamp_position": True})
    peaks, offsets, shifts = [], [], []
    find_peak, make_label, shift = tracker._peak, tracker.label.make, tracker_module.shift_spectrum
    monkeypatch.setattr(tracker, "_peak", lambda maps, samples: peaks.append(find_peak(maps, samples)) or peaks[-1])
    monkeypatch.setattr(tracker.label, "make", lambda g, d: (d and offsets.append(d.offset)) or make_label(g, d))
    monkeypatch.setattr(tracker_module, "shift_spectrum",
                        lambda xf, dy, dx, shape, full=False: shifts.append((dy, dx)) or shift(xf, dy, dx, shape, full))
    tracker.init(frames[0], (5.0, 40.6, 30.0, 30.0))  # centre x 19.5 -> -5.5: clamped at 0 at the end
    for frame in frames[1:]:
        centre = round_half_away(tracker._clamp(tracker.search.centre(), frame.shape))
        tracker.update(frame)
        expected = (tracker.position - centre) / (tracker.geometry.cell_size * tracker.scale)
        np.testing.assert_allclose(shifts[-1], expected, rtol=0, atol=1e-12)
    assert [tuple(o) for o in offsets] == [(dy, dx) for _, dy, dx in peaks]
    assert any(abs(dy - round(dy)) > 0.05 or abs(dx - round(dx)) > 0.05 for _, dy, dx in peaks)
    assert tracker.position[1] == 0.0  # the last move was clamped


def test_authors_exclusion_box_as_tall_as_the_map_does_not_wrap():
    # a target of 10 rows in a 10-row map: tracker.m's Bys = floor(5 - 5):... starts at 0 (MATLAB
    # would fail on index 0); the box must cover every row, not wrap to the last one alone
    h, w = 10, 16
    centred = np.zeros((h, w), np.float32)
    centred[5, 8] = 1.0     # the peak, in the middle
    centred[2, 5] = 0.5     # inside the exclusion box's columns (floor(8 - 1.5) - 1 = 5 ... 9): excluded
    centred[7, 1] = 0.4     # outside it: distractors
    centred[2, 14] = 0.3
    detection = Detection(np.roll(centred, (-(h // 2), -(w // 2)), axis=(0, 1)), (0, 0), (10.0, 3.0), (0.0, 0.0))
    offsets, values = authors_distractors(detection, top_n=30)
    assert sorted(map(tuple, offsets.tolist())) == [(-3, 6), (2, -7)]
    np.testing.assert_allclose(sorted(values), [0.3, 0.4])


def test_dr2track_computes_its_first_search_area_from_the_annotations_own_size():
    """The authors' DR²Track: search_area = prod(wsize * search_area_scale) with wsize before its
    floor, target_sz = floor(wsize) (tracker.m); BACF, STRCF and AutoTrack use the floored size.
    A fractional box (VOT's bag: 145.96 x 132.47) parted from their code on frame 3 without it."""
    from dcfkit.tracker.geometry import geometry

    preset = dcfkit.load_tracker("reference/dr2track")
    assert preset.params.init_area == "given"
    p = preset.params
    given, floored = np.array([132.47, 145.96]), np.array([132.0, 145.0])
    area = float(np.prod(given * p.search_area_scale))  # above the sample size: the scale is its root
    assert area > p.max_image_sample_size
    g, scale = geometry(p, floored, given)
    assert scale == pytest.approx(np.sqrt(area / p.max_image_sample_size))
    np.testing.assert_allclose(g.base_target, floored / scale)  # the sizes stay the floored ones
    _, floored_scale = geometry(p, floored)
    assert floored_scale == pytest.approx(np.sqrt(float(np.prod(floored * p.search_area_scale)) / p.max_image_sample_size))
    seq = make_sequence(n_frames=2, size=(480, 640), target=(132, 145), seed=3)
    box = seq.ground_truth[0] + [0, 0, 0.96, 0.47]
    for init_area, expected in (("given", scale), ("floored", floored_scale)):
        tracker = dcfkit.load_tracker("reference/dr2track", overrides={"tracker.init_area": init_area})
        tracker.init(seq.frames[0], box)
        assert tracker.scale == pytest.approx(expected)


@pytest.mark.parametrize("config", ["autotrack", "bacf", "kcf"])
def test_whole_spectra_need_a_solver_that_takes_them(config):
    with pytest.raises(ConfigError, match=r"tracker\.spectra 'full'.*solver '\w+' works on half spectra"):
        dcfkit.load_tracker(config, overrides={"tracker.spectra": "full"})


def test_whole_spectra_keep_the_complex_filter_of_dr2tracks_code():
    """reference/dr2track (spectra full): the shifted training sample and the filter are complex, as
    in the authors' code; their imaginary part is small, so the boxes stay near the half-spectra ones."""
    seq = make_sequence(n_frames=10, size=(120, 160), target=(16, 20), seed=3)
    full, half = dcfkit.load_tracker("reference/dr2track"), dcfkit.load_tracker("reference/dr2track",
                                                                 overrides={"tracker.spectra": "half"})
    for t in (full, half):
        t.init(seq.frames[0], seq.ground_truth[0])
    boxes = [(full.update(f), half.update(f)) for f in seq.frames[1:]]
    h, w = full.geometry.filter_size
    assert full.hf.shape[-2:] == (h, w) and half.hf.shape[-2:] == (h, w // 2 + 1)
    filt = np.fft.ifft2(full.hf)
    assert np.abs(filt.imag).max() > 1e-4 * np.abs(filt.real).max()
    np.testing.assert_allclose([b for b, _ in boxes], [b for _, b in boxes], atol=1.0)



@pytest.mark.parametrize("config, overrides, match", [
    ("csrdcf", {"tracker.sampling": "subpixel"},
     "tracker.search_area_shape 'padded_square' .* tracker.sampling 'subpixel' would ignore"),
    ("reference/csrdcf", {"tracker.search_area_shape": "square"},
     "tracker.resize 'matlab_bicubic' .* search_area_shape 'square' it would be ignored"),
    ("reference/csrdcf", {"tracker.sampling": "subpixel", "tracker.resize": "matlab_bicubic"},
     "tracker.search_area_shape 'padded_square'"),
])
def test_padded_square_and_resize_need_whole_pixel_sampling(config, overrides, match, request):
    with pytest.raises(ConfigError, match=match):
        dcfkit.load_tracker(request.config.rootpath / f"configs/{config}.yaml", overrides=overrides)

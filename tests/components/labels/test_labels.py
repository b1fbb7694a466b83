"""Label generators: Eq. (1)'s Gaussian and Eq. (3)'s distractor repression."""
import collections
import itertools

import numpy as np
import pytest

import dcfkit
from dcfkit.components.labels.base import Detection, Label, gaussian_label
from dcfkit.components.labels.distractors import DistractorRepressed, authors_distractors
from dcfkit.components.labels.gaussian import Gaussian
from dcfkit.components.regularizers import target_mask
from dcfkit.datasets.synthetic import make_sequence
from dcfkit.errors import ConfigError
from dcfkit.numerics.maxima import local_maxima, regional_maxima
from dcfkit.numerics.patches import round_half_away
from dcfkit.params import parse_params


def test_gaussian_label_peaks_at_origin_and_is_symmetric():
    g = gaussian_label((10, 9), sigma=1.5)
    assert g[0, 0] == pytest.approx(1.0)
    assert g.argmax() == 0
    assert g[1, 0] == pytest.approx(np.exp(-0.5 / 1.5**2))
    assert g[1, 0] == pytest.approx(g[-1, 0]) and g[0, 2] == pytest.approx(g[0, -2])


def response_with_peaks(shape, peaks):
    r = np.zeros(shape, np.float32)
    for (y, x), v in peaks.items():
        r[y, x] = v
    return r


def test_repressed_label_hand_computed_subtractive():
    # target peak at (10, 12) of a 20x24 map, distractors at offsets (+6, 0), (0, -8), one inside the target area
    r = response_with_peaks((20, 24), {(10, 12): 2.0, (16, 12): 1.0, (10, 4): 0.5, (11, 13): 1.5})
    det = Detection(r, (10, 12), target_cells=(4.0, 4.0))
    g = gaussian_label((20, 24), 2.0)
    label = DistractorRepressed(DistractorRepressed.Params(top_n=30, mu=0.25, variant="subtractive"))
    y, offsets = label.make(g, det)
    assert sorted(map(tuple, offsets.tolist())) == [(0, -8), (6, 0)]
    expected = g.copy()
    expected[6, 0] -= 0.25 * 1.0 / 2.0       # the [η] shift puts the offset (6, 0) at label index (6, 0)
    expected[0, -8] -= 0.25 * 0.5 / 2.0
    np.testing.assert_allclose(y, expected, atol=1e-7)


def test_repressed_label_multiplicative_and_top_n():
    r = response_with_peaks((20, 20), {(0, 0): 1.0, (7, 0): 0.9, (0, 7): 0.6, (-7 % 20, -7 % 20): 0.3})
    det = Detection(r, (0, 0), target_cells=(3.0, 3.0))
    g = gaussian_label((20, 20), 4.0)
    label = DistractorRepressed(DistractorRepressed.Params(top_n=2, mu=0.5, variant="multiplicative"))
    y, offsets = label.make(g, det)
    assert offsets.tolist() == [[7, 0], [0, 7]]  # the two strongest, strongest first
    expected = g.copy()
    expected[7, 0] *= 1 - 0.5 * 0.9
    expected[0, 7] *= 1 - 0.5 * 0.6
    np.testing.assert_allclose(y, expected, atol=1e-7)


def test_without_detection_or_with_flat_response_the_label_is_the_gaussian():
    g = gaussian_label((8, 8), 1.0)
    label = DistractorRepressed()
    assert np.array_equal(label.make(g, None)[0], g)
    flat = Detection(np.zeros((8, 8), np.float32), (0, 0), (2.0, 2.0))
    assert np.array_equal(label.make(g, flat)[0], g)
    assert np.array_equal(Gaussian().make(g, flat)[0], g)


def test_exclusion_zone_and_wrapped_offsets_of_the_distractors():
    """P^T of Eq. (3) keeps maxima more than half a target size from the peak, measuring circular
    offsets: a peak near the map's edge has its neighbours across the edge."""
    r = np.zeros((20, 20), np.float32)
    r[18, 1] = 1.0  # the target's peak; target 4x6 cells: excluded if |dy| <= 2 and |dx| <= 3
    r[0, 1] = 0.9   # dy = +2 across the edge: inside the zone
    r[18, 4] = 0.8  # dx = +3: inside
    r[18, 17] = 0.6  # dx = -4 across the edge: a distractor
    r[15, 1] = 0.5  # dy = -3: a distractor
    r[5, 10] = 0.3  # dy = -13 = +7 circularly, dx = +9
    det = Detection(r, (18, 1), (4.0, 6.0))
    offsets, values = DistractorRepressed().distractors(det)
    assert offsets.tolist() == [[0, -4], [-3, 0], [7, 9]]
    np.testing.assert_allclose(values, [0.6, 0.5, 0.3])


@pytest.mark.parametrize("values, message", [
    ({"mu": 1e300}, r"label: mu must be in \[0, 1e\+06\], got 1e\+300"),                        # y = g - μR̃ was -inf in float32
    ({"neighbourhood": 10**6 + 1}, r"label: neighbourhood must be in \[3, 101\], got 1000001"),  # a wrap-padded 10^6-wide copy
])
def test_repression_values_beyond_float32_or_memory_are_refused(values, message):
    with pytest.raises(ConfigError, match=message):
        parse_params(DistractorRepressed.Params, values, "label")


def test_the_widest_neighbourhood_works_on_a_map_smaller_than_it():
    """101 cells on an 8x8 circular map: every cell is in every other's neighbourhood, so the one
    maximum is the map's."""
    r = np.zeros((8, 8), np.float32)
    r[2, 3], r[6, 6] = 1.0, 0.5
    rows, cols = local_maxima(r, 101)
    assert (rows.tolist(), cols.tolist()) == ([2], [3])


def test_init_resets_the_label_before_the_first_frame_of_a_target():
    """The tracker calls reset() on every init: a label keeping per-target state starts afresh."""
    calls = []

    class Recording(Label):
        name = "recording"

        def reset(self):
            calls.append("reset")

        def make(self, g, detection):
            calls.append("first" if detection is None else "later")
            return g, np.zeros((0, 2), int)

    seq = make_sequence(n_frames=3, seed=2)
    tracker = dcfkit.load_tracker("strcf", overrides={"scale.n_scales": 1})
    tracker.label = Recording()
    for _ in range(2):
        tracker.init(seq.frames[0], seq.ground_truth[0])
        tracker.update(seq.frames[1])
    assert calls == ["reset", "first", "later"] * 2


# The authors' MATLAB detail this option reproduces, against an independent reference (the
# line worked out by hand or re-run in numpy, a brute-force loop, a dense solve). file.m:line
# cites ../shared/reference/DR2Track/DR2Track1 unless STRCF's (../shared/reference/STRCF) is named.
# --------------------------------------------------------------------------------------------
# the authors' MATLAB: DR²Track's distractor selection: imregionalmax, its exclusion box, find(bg == value)
# --------------------------------------------------------------------------------------------

# A hand-built 12x12 map in the frame tracker.m works in after its two circshifts (lines 67-69):
# the detection at index (6, 6) = floor(size/2) (0-based). target_cells (5.5, 3.9): reg_sz = (5, 3).
#   target box (init_regwindow, w = 1e-3 inside): rows 4..8, columns 5..7   (0-based)
#   exclusion box (tracker.m:73-75): Bys = floor(6 - 2.5):floor(6 + 2.5) = 3:8, Bxs = floor(6 - 1.5):
#   floor(6 + 1.5) = 4:7 (1-based): rows 2..7, columns 3..6 (0-based).
# Values are multiples of 1/16 (exact in float32); the background 1/16 borders higher pixels, so it
# is not a regional maximum.
H = W = 12
CENTRE = 6
TARGET_CELLS = (5.5, 3.9)
PEAKS = {
    (6, 6): 1.0,                       # the detection: inside the exclusion box
    (9, 9): 0.75, (9, 10): 0.75,       # B: a two-pixel plateau, one component
    (1, 2): 0.5,                       # A
    (2, 9): 0.5,                       # C: A's value again: find() returns rows {1, 2} and columns {2, 9}
    (8, 7): 7 / 16,                    # F: a component (row 8 is outside the exclusion box) but inside the
                                       #    target box, where bg_response = R * 1e-8 never equals 7/16
    (4, 1): 0.375,                     # D
    (1, 5): 0.25, (2, 5): 0.25,        # G: a plateau across the exclusion box's edge ((2, 5) is inside it,
                                       #    outside the target box): its outside part is a component, and
                                       #    find() returns both pixels
    (5, 4): 0.625,                     # E: inside the exclusion box but outside the target box: not a
                                       #    component, never looked up
}


def centred_map(peaks, background=1 / 16):
    m = np.full((H, W), background, np.float32)
    for p, v in peaks.items():
        m[p] = v
    return m


def expected_label(g, repressed, mu, mirrored=False):
    """y(row, col) = -beta * value (tracker.m:93) at centred (row, col), i.e. at the label's circular
    offset (row - 6, col - 6) (tracker.m:71 and :98 shift y by floor(size/2) and back); with
    ``mirrored`` the result turned by 180° about the origin, by explicit index negation."""
    y = g.copy()
    for (row, col), value in repressed:
        y[(row - CENTRE) % H, (col - CENTRE) % W] = -mu * value
    if mirrored:
        y = np.array([[y[(-i) % H, (-j) % W] for j in range(W)] for i in range(H)], np.float32)
    return y


# (top_n, repressed in order): tracker.m:79-95, local_max sorted descending = 0.75, 0.5, 0.5, 7/16,
# 0.375, 0.25 (E and the detection are in the exclusion box)
ALL_REPRESSED = ([((9, 9), 0.75), ((9, 10), 0.75)]
                 + [((r, c), 0.5) for r in (1, 2) for c in (2, 9)]   # the cross product of rows and columns
                 + [((4, 1), 0.375)]
                 + [((1, 5), 0.25), ((2, 5), 0.25)])
CASES = {
    30: ALL_REPRESSED,
    4: ALL_REPRESSED[:6],   # 0.75, 0.5, 0.5, 7/16: F takes the fourth place (and represses nothing)
    1: ALL_REPRESSED[:2],
}


def detection_for(centred, offset, scale=4.0):
    """The circular response R whose normalised, double-circshifted version is ``centred``:
    tracker.m:67-69 shift by floor(size/2) and by round(-disp): R = circshift(C, -(6 - round(disp)))."""
    ry, rx = (int(round_half_away(v)) for v in offset)
    response = np.roll(centred * np.float32(scale), (-(CENTRE - ry), -(CENTRE - rx)), axis=(0, 1))
    peak = np.unravel_index(int(np.argmax(response)), response.shape)
    return Detection(response.astype(np.float32), (int(peak[0]), int(peak[1])), TARGET_CELLS, offset)


@pytest.mark.parametrize("top_n", sorted(CASES))
@pytest.mark.parametrize("mirrored", [False, True])
def test_authors_label_hand_built_map(top_n, mirrored):
    # offset (2.5, -1.5): MATLAB's round gives (3, -2) (numpy's round would give (2, -2))
    det = detection_for(centred_map(PEAKS), (2.5, -1.5))
    g = np.random.default_rng(6).uniform(0.1, 1.0, (H, W)).astype(np.float32)
    label = DistractorRepressed(DistractorRepressed.Params(top_n=top_n, mu=0.25, variant="overwrite",
                                                           selection="authors", mirrored=mirrored))
    y, offsets = label.make(g, det)
    repressed = CASES[top_n]
    np.testing.assert_array_equal(y, expected_label(g, repressed, 0.25, mirrored))
    sign = -1 if mirrored else 1
    assert {tuple(o) for o in offsets.tolist()} == {(sign * (r - CENTRE), sign * (c - CENTRE))
                                                    for (r, c), _ in repressed}


def test_authors_distractors_values_and_offsets():
    det = detection_for(centred_map(PEAKS), (2.5, -1.5))
    offsets, values = authors_distractors(det, 30)
    got = collections.Counter((tuple(o), float(v)) for o, v in zip(offsets.tolist(), values))
    expected = collections.Counter(((r - CENTRE, c - CENTRE), v) for (r, c), v in ALL_REPRESSED)
    expected.update({((r - CENTRE, c - CENTRE), 0.5): 1 for r in (1, 2) for c in (2, 9)})  # looked up twice
    assert got == expected
    assert np.all(np.diff(values) <= 0)  # highest first


@pytest.mark.parametrize("pixel, in_box", [
    ((2, 4), True), ((7, 3), True), ((4, 3), True), ((2, 6), True),     # the exclusion box's edges, inside
    ((1, 4), False), ((8, 3), False), ((5, 2), False), ((3, 7), False),  # just outside each edge
])
def test_authors_exclusion_box_edges(pixel, in_box):
    """One maximum (0.5) at an edge of the exclusion box (rows 2..7, columns 3..6), outside the target
    box, and two far away, (10, 0) and (0, 10), so that there are always two components or more: it
    is repressed exactly when it is outside the exclusion box."""
    det = detection_for(centred_map({(6, 6): 1.0, (10, 0): 0.3125, (0, 10): 0.1875, pixel: 0.5}), (0.0, 0.0))
    g = np.random.default_rng(10).uniform(0.1, 1.0, (H, W)).astype(np.float32)
    label = DistractorRepressed(DistractorRepressed.Params(top_n=30, mu=0.25, variant="overwrite",
                                                           selection="authors"))
    y, _ = label.make(g, det)
    repressed = [((10, 0), 0.3125), ((0, 10), 0.1875)] + ([] if in_box else [(pixel, 0.5)])
    np.testing.assert_array_equal(y, expected_label(g, repressed, 0.25))


def test_authors_label_one_component_means_none():
    """One regional maximum outside the exclusion box: tracker.m:77 keeps local_max = [max 0] = [1 0];
    the detection (value 1) is in the target box, where bg_response = R * 1e-8 is not 1, and no pixel
    is 0: nothing is repressed, not even the clear distractor at (1, 2)."""
    det = detection_for(centred_map({(6, 6): 1.0, (1, 2): 0.5}), (0.0, 0.0))
    g = np.random.default_rng(7).uniform(0.1, 1.0, (H, W)).astype(np.float32)
    label = DistractorRepressed(DistractorRepressed.Params(top_n=30, mu=0.25, variant="overwrite",
                                                           selection="authors"))
    y, offsets = label.make(g, det)
    np.testing.assert_array_equal(y, g)
    assert offsets.shape == (0, 2)


def test_authors_label_fallback_finds_the_maximum_and_exact_zeros():
    """The global maximum (1.0 after normalising) at (1, 2), outside the target box, is the only
    component outside the exclusion box (the 0.75 at the middle is inside it): local_max = [1 0].
    find(bg_response == 1) is (1, 2); find(bg_response == 0) the two exact zeros (1, 6) and (6, 1),
    whose rows x columns {1, 6} x {1, 6} include the middle (6, 6) itself: y there becomes -0.25 * 0."""
    det = detection_for(centred_map({(6, 6): 0.75, (1, 2): 1.0, (1, 6): 0.0, (6, 1): 0.0}), (0.0, 0.0))
    g = np.random.default_rng(8).uniform(0.1, 1.0, (H, W)).astype(np.float32)
    label = DistractorRepressed(DistractorRepressed.Params(top_n=30, mu=0.25, variant="overwrite",
                                                           selection="authors"))
    y, _ = label.make(g, det)
    repressed = [((1, 2), 1.0)] + [((r, c), 0.0) for r in (1, 6) for c in (1, 6)]
    np.testing.assert_array_equal(y, expected_label(g, repressed, 0.25))
    assert y[0, 0] == 0  # the label's peak, overwritten
    # top_n = 1: only the first of [1 0] is looked up
    label1 = DistractorRepressed(DistractorRepressed.Params(top_n=1, mu=0.25, variant="overwrite",
                                                            selection="authors"))
    np.testing.assert_array_equal(label1.make(g, det)[0], expected_label(g, repressed[:1], 0.25))


def authors_distractors_brute(rn, target_cells, top_n):
    """tracker.m:70-93 read line by line on the centred, normalised map ``rn``: imregionalmax (tested
    against a flood fill in tests/numerics/test_maxima.py), the
    exclusion box cleared, bwconncomp's components by their first pixel in column-major order, the
    ``top_n`` highest values (or [max 0] with one component at most), and for each value every row
    of a pixel outside the target box that holds it with every such column, one pixel at a time."""
    import scipy.ndimage

    h, w = rn.shape
    maxima = regional_maxima(rn)
    reg = np.floor(target_cells)
    for row, col in itertools.product(range(h), range(w)):
        if (np.floor(h / 2 - reg[0] / 2) <= row + 1 <= np.floor(h / 2 + reg[0] / 2)
                and np.floor(w / 2 - reg[1] / 2) <= col + 1 <= np.floor(w / 2 + reg[1] / 2)):
            maxima[row, col] = False
    labels, count = scipy.ndimage.label(maxima, structure=np.ones((3, 3)))
    first = {}
    for col, row in itertools.product(range(w), range(h)):
        if labels[row, col]:
            first.setdefault(labels[row, col], rn[row, col])
    wanted = [rn.max(), 0.0] if count <= 1 else sorted(first.values(), reverse=True)
    outside = ~target_mask((h, w), target_cells, "authors")
    found = []
    for value in wanted[:top_n]:
        rows = sorted({r for r, c in itertools.product(range(h), range(w)) if outside[r, c] and rn[r, c] == value})
        cols = sorted({c for r, c in itertools.product(range(h), range(w)) if outside[r, c] and rn[r, c] == value})
        found += [((r - h // 2, c - w // 2), float(value)) for r in rows for c in cols]
    return found


@pytest.mark.parametrize("seed", range(12))
def test_authors_distractors_match_the_lines_of_tracker_m(seed):
    """Quantised random maps (plateaus, one value at several places, exact zeros) of odd and even
    sizes and target sizes: the same distractors, in the same order, as the line-by-line reading."""
    rng = np.random.default_rng(seed)
    h, w = rng.integers(7, 30, 2)
    centred = (rng.integers(0, [3, 8, 40][seed % 3], (h, w)) / 8).astype(np.float32)
    centred[h // 2, w // 2] = centred.max() + 1
    target_cells = tuple(rng.uniform(1, [h / 2, w / 2]))
    response = np.roll(centred, (-(h // 2), -(w // 2)), axis=(0, 1))
    det = Detection(response, (0, 0), target_cells, (0.0, 0.0))
    top_n = int(rng.integers(1, 40))
    offsets, values = authors_distractors(det, top_n)
    expected = authors_distractors_brute(centred / centred.max(), target_cells, top_n)
    assert [(tuple(o), float(v)) for o, v in zip(offsets.tolist(), values)] == expected

"""Search strategies (Eqs. 13-14) and spatial regularizers (the window w of Eqs. 1, 2 and 10), hand-computed."""
import numpy as np
import pytest

from dcfkit.components.regularizers import BoxWindow, Crop, SmoothWindow, target_mask
from dcfkit.components.search.strategies import LastPosition, MotionAware


def test_motion_aware_search_centres_on_the_last_position_plus_the_last_displacement():
    search = MotionAware()
    search.reset(np.array([10.0, 20.0]))
    np.testing.assert_array_equal(search.centre(), [10.0, 20.0])  # V¹ = 0 (Algorithm 1)
    search.observe(np.array([13.0, 18.0]))  # V = p^t - p^{t-1} = (3, -2)  (Eq. 13)
    np.testing.assert_array_equal(search.centre(), [16.0, 16.0])  # p^t + V^t  (Eq. 14)
    search.observe(np.array([14.0, 18.0]))
    np.testing.assert_array_equal(search.centre(), [15.0, 18.0])
    half = MotionAware(MotionAware.Params(gain=0.5))
    half.reset(np.array([0.0, 0.0]))
    half.observe(np.array([4.0, -2.0]))
    np.testing.assert_array_equal(half.centre(), [6.0, -3.0])


def test_fixed_search_centres_on_the_last_position():
    search = LastPosition()
    search.reset(np.array([10.0, 20.0]))
    search.observe(np.array([13.0, 18.0]))
    np.testing.assert_array_equal(search.centre(), [13.0, 18.0])


@pytest.mark.parametrize("shape, cells, rows, cols", [
    ((7, 8), (3.6, 2.2), [2, 3, 4], [3, 4]),     # floored to 3x2, symmetric about (6/2, 7/2)
    ((8, 7), (3.0, 3.9), [2, 3, 4], [2, 3, 4]),  # 8 rows, 3 cells: half a cell towards the start
    ((5, 5), (0.4, 9.0), [2], [0, 1, 2, 3, 4]),  # at least one cell, at most the grid
])
def test_box_window_and_crop_cover_the_target_cells_centred_on_the_patch(shape, cells, rows, cols):
    inside = np.zeros(shape, bool)
    inside[np.ix_(rows, cols)] = True
    w2 = BoxWindow(BoxWindow.Params(inside=0.5, outside=10.0)).weights_squared(shape, cells)
    np.testing.assert_array_equal(w2, np.where(inside, 0.25, 100.0).astype(np.float32))
    crop = Crop(Crop.Params(lam=0.01)).weights_squared(shape, cells)
    np.testing.assert_array_equal(crop, np.where(inside, np.float32(0.01), np.inf).astype(np.float32))


def test_smooth_window_is_minimum_at_the_centre_and_edge_at_the_box_border():
    window = SmoothWindow(SmoothWindow.Params(minimum=0.1, edge=3.0, power=2.0))
    w2 = window.weights_squared((9, 9), (4.0, 4.0))  # centre (4, 4); box border 2 cells away
    assert w2[4, 4] == pytest.approx(0.1 ** 2)
    assert w2[4, 6] == pytest.approx(3.0 ** 2) and w2[2, 4] == pytest.approx(3.0 ** 2)
    assert w2[6, 6] == pytest.approx((0.1 + 2.9 * 2) ** 2)
    assert w2.dtype == np.float32


# The authors' MATLAB detail this option reproduces, against an independent reference (the
# line worked out by hand or re-run in numpy, a brute-force loop, a dense solve). file.m:line
# cites ../shared/reference/DR2Track/DR2Track1 unless STRCF's (../shared/reference/STRCF) is named.
# --------------------------------------------------------------------------------------------
# the authors' MATLAB: the regularization window's box: init_regwindow.m
# --------------------------------------------------------------------------------------------

def init_regwindow_rows(n, target):
    """init_regwindow.m:9-13 for one axis, 0-based: center = floor((n+1)/2) + mod(n+1, 2),
    range = [0, r-1] - floor(r/2), r = floor(target) (tracker.m's reg_sz, init_size.m:14)."""
    r = int(np.floor(target))
    center = (n + 1) // 2 + (n + 1) % 2
    first, last = center + 0 - r // 2, center + (r - 1) - r // 2
    return list(range(first - 1, last))


@pytest.mark.parametrize("shape, target", [
    ((12, 12), (3.0, 3.7)), ((12, 12), (4.2, 4.9)), ((11, 11), (3.5, 3.0)), ((11, 11), (4.0, 4.5)),
    ((12, 11), (5.9, 5.1)), ((50, 49), (9.3, 10.0)), ((8, 7), (1.0, 1.0)),
])
def test_target_mask_authors_is_init_regwindow(shape, target):
    rows = init_regwindow_rows(shape[0], target[0])
    cols = init_regwindow_rows(shape[1], target[1])
    expected = np.zeros(shape, bool)
    expected[np.ix_(rows, cols)] = True
    assert np.array_equal(target_mask(shape, target, "authors"), expected)


@pytest.mark.parametrize("n, target, centred, authors", [
    (12, 3.0, [4, 5, 6], [5, 6, 7]),     # even patch, odd box: the two differ (middle 5.5: lower / upper)
    (12, 4.0, [4, 5, 6, 7], [4, 5, 6, 7]),
    (11, 3.0, [4, 5, 6], [4, 5, 6]),
    (11, 4.0, [3, 4, 5, 6], [3, 4, 5, 6]),
    (9, 0.4, [4], [4]),                   # at least one cell
])
def test_target_mask_hand_cases(n, target, centred, authors):
    for placement, rows in (("centred", centred), ("authors", authors)):
        mask = target_mask((n, 1), (target, 1.0), placement)
        assert np.flatnonzero(mask[:, 0]).tolist() == rows, placement

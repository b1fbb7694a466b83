"""The options that reproduce details of the authors' MATLAB (DR²Track's DR2Track1 release and
STRCF), each against an independent reference: the MATLAB line it mirrors worked out by hand or
re-run in numpy, a brute-force loop, or a dense solve. Citations file.m:line are to
../shared/reference/DR2Track/DR2Track1 (implementation/, utils/, feature/) unless STRCF's
(../shared/reference/STRCF) is named. MATLAB indices are 1-based and its arrays column-major;
where that matters the reference below works in MATLAB's indices and converts at the end.
"""
import collections
import itertools
import platform

import cv2
import numpy as np
import pytest

import dcfkit
from dcfkit.components.features.fhog import fhog
from dcfkit.components.features.gray import Gray
from dcfkit.components.labels.base import Detection
from dcfkit.components.labels.distractors import DistractorRepressed, authors_distractors, regional_maxima
from dcfkit.components.regularizers import target_mask
from dcfkit.components.scale.dsst import DSST
from dcfkit.components.solvers import ADMMParams, admm
from dcfkit.numerics.fft import make_fft
from dcfkit.numerics.patches import resize_auto, round_half_away, whole_pixel_crop, whole_pixel_sample
from dcfkit.numerics.response import _signed_frequencies, newton_peak, shift_spectrum, subpixel_peak

X86_ONLY = pytest.mark.skipif(platform.machine().lower() not in ("x86_64", "amd64"),
                              reason="the processor's own SSE estimates need x86-64")


# --------------------------------------------------------------------------------------------
# 1. patches: MATLAB's round, get_pixels' crop, mexResize 'auto'
# --------------------------------------------------------------------------------------------

@pytest.mark.parametrize("x, expected", [
    (0.5, 1), (1.5, 2), (2.5, 3), (-0.5, -1), (-2.5, -3),   # halves away from zero (numpy: 0, 2, 2, -0, -2)
    (2.4999, 2), (-2.5001, -3), (0.0, 0), (7.0, 7), (-7.2, -7),
])
def test_round_half_away_is_matlab_round(x, expected):
    assert round_half_away(x) == expected
    assert np.array_equal(round_half_away(np.array([x, -x])), np.array([expected, -expected]))


def get_pixels_indices(image_shape, centre, size):
    """0-based row and column indices of get_pixels.m:16-24 for a 0-based centre: in MATLAB's
    1-based pixels pos = centre + 1, xs = floor(pos(2)) + (1:w) - floor(w/2), clamped to [1, W]."""
    pos = np.asarray(centre, float) + 1
    h, w = size
    ys = np.floor(pos[0]) + np.arange(1, h + 1) - np.floor(h / 2)
    xs = np.floor(pos[1]) + np.arange(1, w + 1) - np.floor(w / 2)
    ys = np.clip(ys, 1, image_shape[0])
    xs = np.clip(xs, 1, image_shape[1])
    return ys.astype(int) - 1, xs.astype(int) - 1


@pytest.mark.parametrize("centre, size", [
    ((10.0, 15.0), (6, 8)),      # even sizes, whole-pixel centre
    ((10.7, 15.2), (5, 7)),      # odd sizes, centre floored
    ((1.3, 15.5), (9, 4)),       # over the top border
    ((18.6, 15.0), (8, 5)),      # over the bottom border (image rows 0..19)
    ((10.2, 0.4), (4, 9)),       # over the left border
    ((10.0, 28.9), (3, 10)),     # over the right border (columns 0..29)
    ((-5.5, 40.2), (4, 4)),      # wholly beyond the top-right corner: the corner pixel replicated
    ((10.0, 15.0), (30, 41)),    # larger than the image on every side
])
@pytest.mark.parametrize("channels", [3, 0])
def test_whole_pixel_crop_is_get_pixels(centre, size, channels):
    rng = np.random.default_rng(0)
    image = rng.integers(0, 256, (20, 30, channels) if channels else (20, 30), dtype=np.uint8)
    ys, xs = get_pixels_indices(image.shape, centre, size)
    expected = image[np.ix_(ys, xs)]
    got = whole_pixel_crop(image, centre, size)
    assert got.shape == expected.shape
    assert np.array_equal(got, expected)


def test_whole_pixel_crop_hand_case():
    # centre (10, 15), 0-based = pos (11, 16) 1-based; ys = 11 + (1:6) - 3 = 9..14, xs = 16 + (1:8) - 4 = 13..20
    # (1-based): 0-based rows 8..13 and columns 12..19 (the pixel floor(centre) is at index h//2 - 1)
    image = np.arange(20 * 30, dtype=np.int32).reshape(20, 30)
    assert np.array_equal(whole_pixel_crop(image, (10.0, 15.0), (6, 8)), image[8:14, 12:20])


# mexResize.cpp:46-52 picks the interpolation from the new width. On a square patch (the search
# patches of STRCF and DR²Track: round(sz * scale) with a square sz) its old height and width are
# equal, so these cases do not depend on which of the two it compares with (see the xfail below).
@pytest.mark.parametrize("old, new, interpolation", [
    ((30, 30), (20, 20), cv2.INTER_AREA),     # shrinking
    ((30, 30), (40, 40), cv2.INTER_LINEAR),   # zooming
    ((30, 30), (45, 25), cv2.INTER_AREA),     # the height grows, the width shrinks: area
    ((30, 30), (12, 31), cv2.INTER_LINEAR),   # the height shrinks a lot, the width grows by one: linear
    ((30, 30), (50, 30), cv2.INTER_AREA),     # the same width is not larger: area
])
def test_resize_auto_on_square_patches(old, new, interpolation):
    patch = np.random.default_rng(1).integers(0, 256, (*old, 3), dtype=np.uint8)
    expected = cv2.resize(patch, (new[1], new[0]), interpolation=interpolation)
    other = cv2.resize(patch, (new[1], new[0]),
                       interpolation=cv2.INTER_LINEAR if interpolation == cv2.INTER_AREA else cv2.INTER_AREA)
    assert not np.array_equal(expected, other)  # the case tells the two interpolations apart
    assert np.array_equal(resize_auto(patch, new), expected)


@pytest.mark.parametrize("old, new", [((40, 10), (20, 15)), ((10, 20), (15, 20)), ((10, 40), (30, 20)),
                                      ((30, 12), (20, 16))])
def test_resize_auto_compares_the_new_width_with_the_old_height_as_the_compiled_mex(old, new):
    """mexResize.cpp:34-49 builds newSize = Size(s.height, s.width) (new width, new height) and
    tests newSize.width > oldSize.height, its comment assuming a transposed Mat; MxArray::toMat
    (MxArray.cpp:348-373, transpose=true by default, MxArray.hpp:322) returns the image
    untransposed, so oldSize.height is the old number of rows. Compiled under Octave from the
    shipped sources (STRCF/external_libs/mexResize, identical to DR2Track1/utils/mexResize.cpp):
    [40 10] -> [20 15] gives cv2's INTER_AREA and [10 20] -> [15 20] INTER_LINEAR, bit for bit."""
    patch = np.random.default_rng(2).integers(0, 256, (*old, 3), dtype=np.uint8)
    interpolation = cv2.INTER_LINEAR if new[1] > old[0] else cv2.INTER_AREA
    assert np.array_equal(resize_auto(patch, new), cv2.resize(patch, (new[1], new[0]), interpolation=interpolation))


@pytest.mark.parametrize("region, crop", [
    ((12.5, 12.5), (13, 13)),   # round half away from zero (numpy would give 12)
    ((0.4, 0.3), (2, 2)),       # get_pixels.m:8-13: a side below 1 (after rounding: 0) becomes 2
    ((7.5, 3.49), (8, 3)),
    ((0.5, 9.6), (1, 10)),      # round(0.5) = 1 is not below 1
])
def test_whole_pixel_sample_rounds_the_region(region, crop):
    """The crop of round(region) pixels; resizing to that same size is a copy, which isolates the crop."""
    rng = np.random.default_rng(3)
    image = rng.integers(0, 256, (20, 30, 3), dtype=np.uint8)
    centre = (9.6, 14.2)
    ys, xs = get_pixels_indices(image.shape, centre, crop)
    assert np.array_equal(whole_pixel_sample(image, centre, region, crop), image[np.ix_(ys, xs)])


@pytest.mark.parametrize("out, interpolation", [((24, 24), cv2.INTER_LINEAR),   # 24 > 17: zoom
                                                 ((30, 12), cv2.INTER_AREA)])    # 12 < 17 (a larger area)
def test_whole_pixel_sample_resizes_the_crop(out, interpolation):
    rng = np.random.default_rng(4)
    image = rng.integers(0, 256, (40, 50, 3), dtype=np.uint8)
    centre = (20.5, 2.7)  # over the left border
    ys, xs = get_pixels_indices(image.shape, centre, (17, 17))  # round(16.5) = 17
    expected = cv2.resize(image[np.ix_(ys, xs)], (out[1], out[0]), interpolation=interpolation)
    assert np.array_equal(whole_pixel_sample(image, centre, (16.5, 16.5), out), expected)


# --------------------------------------------------------------------------------------------
# 2. response: the authors' frequency grid, resp_newton, shift_sample
# --------------------------------------------------------------------------------------------

def matlab_k(n):
    """tracker.m:18: ky = circshift(-floor((n-1)/2):ceil((n-1)/2), [1, -floor((n-1)/2)]); a row
    vector, so the shift is along its columns: np.roll by -floor((n-1)/2)."""
    return np.roll(np.arange(-((n - 1) // 2), int(np.ceil((n - 1) / 2)) + 1), -((n - 1) // 2))


@pytest.mark.parametrize("n", [7, 8, 50, 1, 2])
def test_signed_frequencies_are_the_authors_grid(n):
    assert np.array_equal(_signed_frequencies(n), matlab_k(n))


def test_signed_frequencies_hand_values():
    assert _signed_frequencies(8).tolist() == [0, 1, 2, 3, 4, -3, -2, -1]   # Nyquist +4 (fftfreq: -4)
    assert _signed_frequencies(7).tolist() == [0, 1, 2, 3, -3, -2, -1]


def cosine_peak_map(h, w, dy, dx):
    """Σ_k cos(2πk(y - dy)/h)/k + cos(2πk(x - dx)/w)/k, k = 1..3: band-limited (so its own
    trigonometric interpolant), maximal, 2(1 + 1/2 + 1/3), at (dy, dx) only."""
    y = np.arange(h)[:, None]
    x = np.arange(w)[None, :]
    return sum(np.cos(2 * np.pi * k * (y - dy) / h) / k + np.cos(2 * np.pi * k * (x - dx) / w) / k
               for k in (1, 2, 3))


def ridge_map(y0, x0, n=16):
    """cos(2π(3(y-y0) + 4(x-x0))/n) + cos(2π(2(y-y0) + 3(x-x0))/n): band-limited; both cosines are 1
    only where 3Y + 4X ≡ 0 and 2Y + 3X ≡ 0 (mod n), a system of determinant 1, so (y0, x0) is the
    one maximum (2) on the torus. Its Hessian ∝ -[[13, 18], [18, 25]] (eigenvalues 38 and 0.03) is
    nearly flat along one direction, along which whole cells far from the peak stay high."""
    y = np.arange(n)[:, None] - y0
    x = np.arange(n)[None, :] - x0
    return np.cos(2 * np.pi * (3 * y + 4 * x) / n) + np.cos(2 * np.pi * (2 * y + 3 * x) / n)


def signed(i, n):
    return (i + n // 2) % n - n // 2


@pytest.mark.parametrize("shape", [(16, 15), (15, 16)])
@pytest.mark.parametrize("true_dy, true_dx", [(0.3, -0.2), (-2.4, 3.1), (5.45, -5.0)])
def test_newton_peak_finds_an_off_grid_peak(shape, true_dy, true_dx):
    r = cosine_peak_map(*shape, true_dy, true_dx).astype(np.float32)
    best, dy, dx, value = newton_peak(r[None])
    assert best == 0
    assert dy == pytest.approx(true_dy, abs=1e-4) and dx == pytest.approx(true_dx, abs=1e-4)
    assert value == pytest.approx(2 * (1 + 1 / 2 + 1 / 3), rel=1e-5)


def test_newton_peak_breaks_grid_ties_in_column_major_order():
    # resp_newton.m:3-4 takes max over rows, then over columns: of equal maxima the one in the
    # first column wins (row-major argmax would pick (0, 5), the first in reading order)
    r = np.zeros((8, 9), np.float32)
    r[0, 5] = r[3, 2] = r[6, 2] = 1.0
    best, dy, dx, value = newton_peak(r[None], iterations=0)
    assert (best, dy, dx, value) == (0, pytest.approx(3.0), pytest.approx(2.0), pytest.approx(1.0))
    # a tie in the same column: the lower row index
    r = np.zeros((8, 9), np.float32)
    r[6, 2] = r[2, 2] = 1.0
    assert newton_peak(r[None], iterations=0)[1:3] == (pytest.approx(2.0), pytest.approx(2.0))


def test_newton_peak_picks_the_map_with_the_highest_refined_value():
    """Map 0 peaks on the grid at 1.98; map 1 is the ridge map with its maximum 2 at (0.2, 0),
    whose highest sample is only 1.9754 (at (3, -2)): resp_newton compares the refined values."""
    r0 = 0.99 * (np.cos(2 * np.pi * np.arange(16)[:, None] / 16) + np.cos(2 * np.pi * np.arange(16)[None, :] / 16))
    r1 = ridge_map(0.2, 0.0)
    assert r0.max() > r1.max()  # by the grid, map 0 would win
    best, dy, dx, value = newton_peak(np.stack([r0, r1]).astype(np.float32))
    assert best == 1
    assert (dy, dx) == (pytest.approx(0.2, abs=1e-4), pytest.approx(0.0, abs=1e-4))
    assert value == pytest.approx(2.0, rel=1e-5)


def test_newton_peak_falls_back_to_the_grid_maximum():
    """r = cos(2πy/16) + f(x), f(x) = cos(θ(x - s)) + c cos(7θ(x - s)), θ = 2π/16, s = 0.2, c = -0.03.
    Its grid maximum is (0, 0) (checked), but along x f has a local MINIMUM at s (f''(s) = -θ² - 49cθ²
    > 0), and Newton's steps from x = 0 converge to it (the loop below, on the analytic f): the point
    (0, s) is a saddle of value 2 + c = 1.97, below the grid value r(0, 0) = 1.97134; resp_newton.m:53-55
    then keeps the grid maximum."""
    theta, s, c = 2 * np.pi / 16, 0.2, -0.03
    y = np.arange(16)[:, None]
    x = np.arange(16)[None, :]
    r = np.cos(2 * np.pi * y / 16) + np.cos(theta * (x - s)) + c * np.cos(7 * theta * (x - s))
    assert np.unravel_index(np.argmax(r), r.shape) == (0, 0)
    u = 0.0
    for _ in range(5):  # Newton on f alone (r is separable and cos(2πy/16) is stationary at y = 0)
        d1 = -theta * np.sin(theta * (u - s)) - 7 * c * theta * np.sin(7 * theta * (u - s))
        d2 = -theta**2 * np.cos(theta * (u - s)) - 49 * c * theta**2 * np.cos(7 * theta * (u - s))
        u -= d1 / d2
    assert u == pytest.approx(s, abs=1e-6) and 2 + c < r[0, 0]
    best, dy, dx, value = newton_peak(r[None].astype(np.float32))
    assert (best, dy, dx) == (0, 0.0, 0.0)
    assert value == pytest.approx(r[0, 0], rel=1e-6)


def test_newton_peak_may_leave_the_grid_maximum_cell_unlike_subpixel_peak():
    """The ridge map with its maximum at (0.2, 0): its highest sample (by 0.015) is (3, -2), 2.8 cells
    away. resp_newton's unbounded steps reach the true maximum; subpixel_peak stays within one cell."""
    r = ridge_map(0.2, 0.0).astype(np.float32)
    i, j = np.unravel_index(np.argmax(r), r.shape)
    grid = (signed(i, 16), signed(j, 16))
    assert grid == (3, -2)
    _, dy, dx, value = newton_peak(r[None])
    assert (dy, dx, value) == (pytest.approx(0.2, abs=1e-4), pytest.approx(0.0, abs=1e-4), pytest.approx(2.0))
    sy, sx, _ = subpixel_peak(r)
    assert abs(sy - grid[0]) <= 1 and abs(sx - grid[1]) <= 1


def resp_newton_sums(maps, iterations):
    """STRCF's resp_newton.m (implementation/resp_newton.m:3-60, the multi-scale version), with its
    matrix products exp_iky * R * exp_ikx written as double sums over the full spectrum R = fft2(r):
    S_ab = Σ_k,l ky^a kx^b R e^{i(ky y + kx x)}; grad = -imag(S_10, S_01); H_yy = real(-S_20 + i S_00)
    (their ival term, lines 34-36), H_xx = real(-S_02 + i S_00), H_xy = -real(S_11). Returns the scale
    (first maximum of the values, line 58), the signed displacement in cells (lines 59-60) and the value."""
    n_maps, h, w = maps.shape
    ky, kx = matlab_k(h)[:, None], matlab_k(w)[None, :]
    outcomes = []
    for r in maps.astype(np.float64):
        spectrum = np.fft.fft2(r)
        row = np.argmax(r, axis=0)  # lines 3-7: the first maximum of each column, then the first column
        col = int(np.argmax(r[row, np.arange(w)]))
        row = int(row[col])
        init = r[row, col]
        y0 = 2 * np.pi * (np.mod(row + (h - 1) // 2, h) - (h - 1) // 2) / h
        x0 = 2 * np.pi * (np.mod(col + (w - 1) // 2, w) - (w - 1) // 2) / w
        y, x = y0, x0

        def s(a, b):
            return np.sum(ky**a * kx**b * spectrum * np.exp(1j * (ky * y + kx * x)))

        for _ in range(iterations):
            gy, gx = -s(1, 0).imag, -s(0, 1).imag
            hyy, hxx, hxy = (-s(2, 0) + 1j * s(0, 0)).real, (-s(0, 2) + 1j * s(0, 0)).real, -s(1, 1).real
            det = hyy * hxx - hxy * hxy
            y, x = y - (hxx * gy - hxy * gx) / det, x - (hyy * gx - hxy * gy) / det
        value = s(0, 0).real / (h * w)
        if value < init:  # lines 53-56
            y, x, value = y0, x0, init
        outcomes.append((y, x, value))
    best = int(np.argmax([v for _, _, v in outcomes]))
    y, x, value = outcomes[best]
    return best, (np.mod(y + np.pi, 2 * np.pi) - np.pi) / (2 * np.pi) * h, \
        (np.mod(x + np.pi, 2 * np.pi) - np.pi) / (2 * np.pi) * w, value


@pytest.mark.parametrize("shape", [(10, 12), (8, 8), (9, 12), (12, 9)])
@pytest.mark.parametrize("iterations", [1, 2, 5])
def test_newton_peak_matches_resp_newton_on_maps_with_nyquist_content(shape, iterations):
    """Noisy peaked maps with an even side carry Nyquist content, where the authors' grid (Nyquist
    +n/2) makes the interpolant complex and their Hessian's extra i·S_00 term matters (before
    convergence: iterations 1 and 2)."""
    rng = np.random.default_rng(sum(shape) + iterations)
    h, w = shape
    maps = np.stack([cosine_peak_map(h, w, *rng.uniform(-2, 2, 2)) * a + 0.3 * rng.standard_normal(shape)
                     for a in (1.0, 1.1, 0.9)]).astype(np.float32)
    best, dy, dx, value = newton_peak(maps, iterations)
    ref_best, ref_dy, ref_dx, ref_value = resp_newton_sums(maps, iterations)
    assert best == ref_best
    assert (dy, dx) == (pytest.approx(ref_dy, abs=1e-9), pytest.approx(ref_dx, abs=1e-9))
    assert value == pytest.approx(ref_value, rel=1e-9)


@pytest.mark.parametrize("shape, dy, dx", [((8, 10), 0.3, -1.7), ((8, 9), -2.5, 0.6), ((7, 10), 1.25, 2.5)])
def test_shift_spectrum_uses_the_authors_nyquist(shape, dy, dx):
    """shift_sample.m: xf .* exp(1i*shift(1)*ky) .* exp(1i*shift(2)*kx), shift = 2π (dy, dx)/size,
    on the FULL spectrum with the authors' ky, kx (Nyquist +n/2); dcfkit keeps half spectra."""
    h, w = shape
    x = np.random.default_rng(5).standard_normal((2, h, w))
    ky = matlab_k(h)[:, None]
    kx = matlab_k(w)[None, :]
    full = np.fft.fft2(x) * np.exp(1j * 2 * np.pi * dy / h * ky) * np.exp(1j * 2 * np.pi * dx / w * kx)
    got = shift_spectrum(np.fft.rfft2(x).astype(np.complex64), dy, dx, shape)
    tol = 2e-5 * np.abs(full).max()
    np.testing.assert_allclose(got, full[..., : w // 2 + 1], atol=tol)
    if h % 2 == 0:  # numpy's fftfreq (Nyquist -h/2) gives another shift: the case tells them apart
        numpy_ky = (np.fft.fftfreq(h) * h)[:, None]
        other = np.fft.fft2(x) * np.exp(1j * 2 * np.pi * dy / h * numpy_ky) * np.exp(1j * 2 * np.pi * dx / w * kx)
        assert np.abs(other - full).max() > 100 * tol


# --------------------------------------------------------------------------------------------
# 3. the regularization window's box: init_regwindow.m
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


# --------------------------------------------------------------------------------------------
# 4. DR²Track's distractor selection: imregionalmax, its exclusion box, find(bg == value)
# --------------------------------------------------------------------------------------------

def imregionalmax_brute(r):
    """MATLAB's imregionalmax (8-connected, default conn for 2-D): every connected plateau of equal
    values whose neighbours outside it (inside the image; not circular) are all strictly lower."""
    h, w = r.shape
    out = np.zeros((h, w), bool)
    seen = np.zeros((h, w), bool)
    for start in itertools.product(range(h), range(w)):
        if seen[start]:
            continue
        plateau, queue, seen[start] = [], collections.deque([start]), True
        is_max = True
        while queue:
            p = queue.popleft()
            plateau.append(p)
            for dy, dx in itertools.product((-1, 0, 1), repeat=2):
                q = (p[0] + dy, p[1] + dx)
                if (dy, dx) == (0, 0) or not (0 <= q[0] < h and 0 <= q[1] < w):
                    continue
                if r[q] == r[start]:
                    if not seen[q]:
                        seen[q] = True
                        queue.append(q)
                elif r[q] > r[start]:
                    is_max = False
        for p in plateau:
            out[p] = is_max
    return out


@pytest.mark.parametrize("seed, shape, levels", [(0, (9, 11), 3), (1, (12, 12), 4), (2, (7, 16), 2),
                                                 (3, (10, 10), 6), (4, (13, 9), 3), (5, (6, 6), 1000)])
def test_regional_maxima_match_imregionalmax(seed, shape, levels):
    rng = np.random.default_rng(seed)
    r = (rng.integers(0, levels, shape) / levels).astype(np.float32)  # quantised: many plateaus
    expected = imregionalmax_brute(r)
    assert np.array_equal(regional_maxima(r), expected)


def test_regional_maxima_of_special_maps():
    flat = np.full((4, 5), 0.3, np.float32)
    assert regional_maxima(flat).all()  # one plateau with no outer neighbour: a maximum
    r = np.zeros((6, 6), np.float32)
    r[0:3, 0:3] = 1.0
    r[2, 2] = 2.0  # the plateau has a higher pixel inside its own neighbourhood: not a maximum
    expected = np.zeros((6, 6), bool)
    expected[2, 2] = True
    assert np.array_equal(regional_maxima(r), expected)
    r = np.zeros((5, 5), np.float32)
    r[0, 0] = r[0, 1] = r[1, 2] = 1.0  # a diagonal step joins (1, 2) to the plateau: 8-connected
    r[4, 4] = 0.5
    expected = (r > 0)
    assert np.array_equal(regional_maxima(r), expected)
    # a diagonal chain (1, 1), (2, 2), (3, 3) is one plateau; (3, 3) touches the higher (4, 4), so none
    # of it is a maximum, although (1, 1) only touches the plateau's (2, 2)
    r = np.zeros((6, 6), np.float32)
    r[1, 1] = r[2, 2] = r[3, 3] = 1.0
    r[4, 4] = 2.0
    expected = np.zeros((6, 6), bool)
    expected[4, 4] = True
    assert np.array_equal(regional_maxima(r), expected)


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


# --------------------------------------------------------------------------------------------
# 5. ADMM: run_training.m's h-step
# --------------------------------------------------------------------------------------------

def run_training_reference(xf, yf, w2, mu, g_pre, iterations, h_step, gamma=1.0, beta=10.0, gamma_max=10000.0):
    """run_training.m:2-32 on full spectra: the g-subproblem (lines 16-21 are its Sherman-Morrison
    closed form) as a dense per-frequency solve of
        (x xᴴ/T + (γ+μ) I) g = x conj(ŷ)/T + μ g_pre + γ h - l      (dcfkit's conj(ŷ); theirs: ŷ)
    then h = ifft2(γ(g + l)) .* T/(w² + γT) (line 24, 'authors') or ifft2(γg + l) .* T/(w² + γT)
    ('standard'), l += γ(g - h), γ = min(βγ, γ_max). Returns g (line 34: g_pre = g_f)."""
    c, h, w = xf.shape
    T = h * w
    X = np.moveaxis(xf, 0, -1)[..., :, None]          # (H, W, C, 1)
    A = X @ X.conj().swapaxes(-1, -2) / T             # x xᴴ / T
    g = np.zeros_like(xf)
    hf = np.zeros_like(xf)
    lf = np.zeros_like(xf)
    eye = np.eye(c)
    for _ in range(iterations):
        rhs = xf * yf.conj()[None] / T + mu * g_pre + gamma * hf - lf
        sol = np.linalg.solve(A + (gamma + mu) * eye, np.moveaxis(rhs, 0, -1)[..., None])
        g = np.moveaxis(sol[..., 0], -1, 0)
        spatial = np.fft.ifft2(gamma * (g + lf) if h_step == "authors" else gamma * g + lf)
        hf = np.fft.fft2(spatial * (T / (w2 + gamma * T)))
        lf = lf + gamma * (g - hf)
        gamma = min(beta * gamma, gamma_max)
    return g


@pytest.mark.parametrize("h_step", ["authors", "standard"])
@pytest.mark.parametrize("frame", [1, 2])
@pytest.mark.parametrize("window", ["moderate", "dr2track"])
def test_admm_h_step_matches_run_training(h_step, frame, window):
    """A box window w with moderate values (w² comparable to T = 48), where the two h-steps give
    clearly different filters, and DR²Track's own 1e-3 / 1e5, where they agree to ~1e-5: inside the
    box h ≈ g so the multiplier l = γ(g - h) is ~0 there, and outside it the h-step zeroes both."""
    rng = np.random.default_rng(9)
    C, h, w = 3, 6, 8
    x = rng.standard_normal((C, h, w))
    y = rng.standard_normal((h, w))
    inside, outside = (2.0, 20.0) if window == "moderate" else (1e-3, 1e5)  # reg_window_min / max
    win = np.full((h, w), outside)
    win[2:4, 3:6] = inside
    w2 = (win**2).astype(np.float32)
    xf, yf = np.fft.fft2(x), np.fft.fft2(y)
    if frame == 1:  # tracker.m:57-60: mu = 0, g_pre = 0
        theta, v_prev, mu, g_pre = 12.0, None, 0.0, np.zeros_like(xf)
    else:
        g_pre = np.fft.fft2(rng.standard_normal((C, h, w)) * 0.1)
        theta, mu = 12.0, 12.0
        v_prev = g_pre[..., : w // 2 + 1].astype(np.complex64)
    p = ADMMParams(iterations=4, gamma0=1.0, beta=10.0, gamma_max=10000.0, h_step=h_step)
    vf, _ = admm(np.fft.rfft2(x).astype(np.complex64), np.fft.rfft2(y).astype(np.complex64), w2, theta, v_prev,
                 p, make_fft("scipy"))
    expected = run_training_reference(xf, yf, w2.astype(float), mu, g_pre, 4, h_step)[..., : w // 2 + 1]
    other = run_training_reference(xf, yf, w2.astype(float), mu, g_pre, 4,
                                   "standard" if h_step == "authors" else "authors")[..., : w // 2 + 1]
    tol = 1e-4 * np.abs(expected).max()
    if window == "moderate":
        assert np.abs(other - expected).max() > 100 * tol  # the two h-steps are told apart
    assert np.abs(vf - expected).max() < tol


# --------------------------------------------------------------------------------------------
# 6. fhog: which channel wins a tie; Piotr's SSE arithmetic
# --------------------------------------------------------------------------------------------

def tie_image():
    """B = 20 + 5x and R = 120 - 3x - 4y: at every pixel (borders too, one-sided) their gradients
    (I[p+1] - I[p-1])/2 are (5, 0) and (-3, -4), both of magnitude 5; G is flat. Orientation
    atan2(gy, gx) (rows down): B 0° -> bin 0 of 18; R 233.13° -> 11.66 bins -> bin 12."""
    y, x = np.mgrid[0:16, 0:16]
    image = np.zeros((16, 16, 3), np.uint8)
    image[..., 0] = 20 + 5 * x
    image[..., 1] = 50
    image[..., 2] = 120 - 3 * x - 4 * y
    return image


@pytest.mark.parametrize("arithmetic", ["exact", "sse", pytest.param("sse_cpu", marks=X86_ONLY)])
@pytest.mark.parametrize("order, winner", [("bgr", 0), ("rgb", 12)])
def test_fhog_channel_order_decides_ties(arithmetic, order, winner):
    feats = fhog(tie_image(), 4, channel_order=order, arithmetic=arithmetic)
    sensitive = feats[:18].sum(axis=(1, 2))
    loser = 12 if winner == 0 else 0
    assert sensitive[winner] > 0
    assert sensitive[loser] == 0
    assert np.count_nonzero(sensitive) == 1


def strongest_gradients(image):
    """Piotr's grad1/gradMag (gradientMex.cpp:14-36, 69-78): per pixel the channel with the largest
    gx² + gy² (the first on ties), gx = (I[x+1] - I[x-1])/2, one-sided on the border. float64."""
    img = image.astype(np.float64)
    if img.ndim == 2:
        img = img[..., None]
    gy, gx = np.gradient(img, axis=(0, 1))  # centred /2 inside, one-sided on the border: the same
    m2 = gx**2 + gy**2
    c = np.argmax(m2, axis=2)[..., None]
    return np.take_along_axis(gx, c, 2)[..., 0], np.take_along_axis(gy, c, 2)[..., 0]


def boundary_band(angle):
    """How close to a bin boundary an orientation may come before Piotr's table and SSE estimates
    could put it in the other bin: the table's step 1e-4/sin(o) plus a 4e-4 relative error of
    rsqrt in the cosine (4e-4 |cot(o)| rad), and some margin."""
    return 1e-4 / np.abs(np.sin(angle)) + 4e-4 / np.abs(np.tan(angle)) + 2e-4


@pytest.mark.parametrize("arithmetic", ["sse", pytest.param("sse_cpu", marks=X86_ONLY)])
def test_fhog_sse_is_close_to_exact_away_from_bin_boundaries(arithmetic):
    """With no pixel's orientation within the table/estimate uncertainty of a bin boundary (checked
    with the test's own gradients), every pixel lands in the same bin both ways and the features
    differ only by the SSE estimates of the magnitudes (~12 bits)."""
    rng = np.random.default_rng(22)  # a seed whose image meets the precondition
    image = cv2.GaussianBlur(rng.uniform(0, 255, (16, 24, 3)).astype(np.float32), (0, 0), 1.2)
    gx, gy = strongest_gradients(image)
    o = np.mod(np.arctan2(gy, gx), 2 * np.pi)
    boundaries = 2 * np.pi * (np.arange(18) + 0.5) / 18
    distance = np.abs(o[..., None] - boundaries).min(axis=-1)
    nearest = boundaries[np.abs(o[..., None] - boundaries).argmin(axis=-1)]
    assert np.all(distance > boundary_band(nearest))  # the precondition, so no bin can flip
    exact = fhog(image, 4)
    sse = fhog(image, 4, arithmetic=arithmetic)
    assert np.abs(sse - exact).max() < 2e-3
    assert np.abs(sse - exact).max() > 0  # the estimates are not exact arithmetic


def piotr_bin(gx, gy):
    """gradMag + gradQuantize (gradientMex.cpp:46-56, 80-95, 140) with an EXACT 1/|g|: idx =
    trunc(10000 gx/|g|), negated when gy < 0; o = acos(idx/10000) (float32), + π when gy < 0;
    bin = trunc(o * 18/(2π) + 0.5), 18 -> 0. PI is Piotr's 3.14159265f."""
    pi = np.float32(3.14159265)
    r = 1.0 / np.hypot(gx, gy)
    cosine = (gx * r * 10000.0) * np.where(gy < 0, -1, 1)
    idx = np.trunc(cosine)
    o = np.arccos(idx / 10000.0).astype(np.float32)
    o = np.where(gy < 0, o + pi, o).astype(np.float32)
    o_mult = np.float32(18) / (np.float32(2) * pi)
    b = np.trunc(o * o_mult + np.float32(0.5)).astype(int)
    return np.where(b >= 18, 0, b), idx


@pytest.mark.parametrize("arithmetic", ["sse", pytest.param("sse_cpu", marks=X86_ONLY)])
def test_fhog_sse_takes_the_acos_table_bin_near_a_boundary(arithmetic):
    """Brute force over integer gradients (gx, gy) for one whose exact orientation is within 1e-4 rad
    of a bin boundary and whose bin by Piotr's table differs from the nearest bin, robustly: every
    table index reachable with a ±4e-4 relative error of the rsqrt estimate gives the same bin. Such
    cases are near 90° and 270° (cos ≈ 0, where the estimate's error vanishes): gx/|g| < 1e-4
    truncates to index 0, acos(0) = π/2 rounds up to bin 5 (or 13.5 -> 14), while the true angle is
    just short of the boundary. A float32 ramp I = gx x + gy y gives every pixel that gradient."""
    gx, gy = np.meshgrid(np.arange(-3, 4), np.concatenate([np.arange(-30000, -9000), np.arange(9000, 30001)]))
    gx, gy = gx.ravel().astype(float), gy.ravel().astype(float)
    angle = np.mod(np.arctan2(gy, gx), 2 * np.pi)
    position = angle * 18 / (2 * np.pi)
    exact_bin = np.floor(position + 0.5).astype(int) % 18
    near = np.abs(position - np.floor(position) - 0.5) * 2 * np.pi / 18
    table_bin, _ = piotr_bin(gx, gy)
    # robust: the truncated index is the same for 1/|g| anywhere within ±4e-4 of its exact value
    cosine = np.abs(gx) / np.hypot(gx, gy) * 10000
    robust = np.trunc(cosine * (1 - 4e-4)) == np.trunc(cosine * (1 + 4e-4))
    candidates = np.flatnonzero((near < 1e-4) & (near > 1e-6) & robust & (table_bin != exact_bin))
    assert candidates.size > 0
    for k in (candidates[0], candidates[-1]):  # (-2, -30000) near 270° and (2, 30000) near 90°
        a, b = int(gx[k]), int(gy[k])
        yy, xx = np.mgrid[0:8, 0:8]
        image = (a * xx + b * yy - min(0, 7 * b) - min(0, 7 * a)).astype(np.float32)
        exact = fhog(image, 4)[:18].sum(axis=(1, 2))
        sse = fhog(image, 4, arithmetic=arithmetic)[:18].sum(axis=(1, 2))
        assert np.flatnonzero(exact).tolist() == [exact_bin[k]], (a, b)
        assert np.flatnonzero(sse).tolist() == [table_bin[k]], (a, b)


@pytest.mark.parametrize("arithmetic", ["sse", pytest.param("sse_cpu", marks=X86_ONLY)])
def test_fhog_sse_flat_image_has_the_magnitude_floor(arithmetic):
    """gradientMex.cpp:82-84: M = rcp(min(rsqrt(0) = inf, 1e10)) ≈ 1e-10 (an estimate: ±4e-4), not 0,
    and cos = 0 -> acos(0) = π/2 -> trunc(4.5 + 0.5) = bin 5. Every cell's histogram is then M (the
    bilinear weights of cell² pixels over cell², Piotr's 8/7 restoring a border cell's outer half);
    each of its 4 block norms is 1/sqrt(~4M² + eps) = 1/sqrt(eps) = 3200, eps = 1e-4/4/4⁴; so bin 5 and
    its contrast-insensitive twin 18 + 5 are 4 · 0.5 · 3200 M = 6.4e-7 and each texture channel
    0.2357 · 3200 M. The exact fhog of a flat image is zero."""
    flat = np.full((12, 16, 3), 77, np.uint8)
    assert not fhog(flat, 4).any()
    feats = fhog(flat, 4, arithmetic=arithmetic)
    orient = feats[:27].reshape(27, -1)
    assert np.flatnonzero(orient.any(axis=1)).tolist() == [5, 23]
    np.testing.assert_allclose(feats[[5, 23]], 6.4e-7, rtol=1e-3)
    np.testing.assert_allclose(feats[27:], 0.2357 * 3200 * 1e-10, rtol=1e-3)


# --------------------------------------------------------------------------------------------
# 7. gray: get_colorspace's rgb2gray
# --------------------------------------------------------------------------------------------

@pytest.mark.parametrize("bgr", [(30, 200, 90), (255, 0, 0), (0, 0, 255), (13, 77, 251)])
def test_gray_matlab_conversion_of_a_uniform_patch(bgr):
    # get_colorspace.m:5,10: rgb2gray(single(im)/255) - 0.5, rgb2gray = 0.298936 R + 0.587043 G + 0.114021 B
    b, g, r = bgr
    patch = np.empty((8, 12, 3), np.uint8)
    patch[:] = bgr  # dcfkit's images are BGR
    expected = (0.298936 * r + 0.587043 * g + 0.114021 * b) / 255 - 0.5
    got = Gray(Gray.Params(conversion="matlab")).extract(patch, 4)
    assert got.shape == (1, 2, 3)
    np.testing.assert_allclose(got, expected, atol=2e-7)


def test_gray_opencv_conversion_rounds_to_whole_levels():
    patch = np.full((8, 8, 3), (30, 200, 90), np.uint8)
    got = Gray().extract(patch, 4)
    np.testing.assert_allclose(got, round(0.299 * 90 + 0.587 * 200 + 0.114 * 30) / 255 - 0.5, atol=2e-7)


# --------------------------------------------------------------------------------------------
# 8. DSST: init_scale.m's model size and window, shift_sample_scale.m
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


# --------------------------------------------------------------------------------------------
# 9. tracker: init_position, box_output, clamp_position, translation
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
    tracker = dcfkit.load_tracker("strcf", overrides={"tracker.translation": translation})
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
    monkeypatch.setattr(tracker, "_peak", lambda maps: peaks.append(find_peak(maps)) or peaks[-1])
    monkeypatch.setattr(tracker.label, "make", lambda g, d: (d and offsets.append(d.offset)) or make_label(g, d))
    monkeypatch.setattr(tracker_module, "shift_spectrum",
                        lambda xf, dy, dx, shape: shifts.append((dy, dx)) or shift(xf, dy, dx, shape))
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

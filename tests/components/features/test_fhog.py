"""fhog: Felzenszwalb HOG as in Piotr's toolbox, checked against per-pixel loop references."""
import math
import platform

import cv2
import numpy as np
import pytest

from dcfkit.components.features.fhog import _cell_histograms, fhog, fhog_channels

# --------------------------------------------------------------- loop references


def ref_gradients(img):
    """Per-pixel [-1, 0, 1]/2 differences (one-sided, unhalved, at the border); colour:
    the channel with the largest squared magnitude, the first one on ties."""
    img = np.asarray(img, np.float64)
    if img.ndim == 2:
        img = img[..., None]
    h, w, nc = img.shape
    gx = np.zeros((h, w))
    gy = np.zeros((h, w))
    for y in range(h):
        for x in range(w):
            best = -1.0
            for c in range(nc):
                if x == 0:
                    dx = img[y, 1, c] - img[y, 0, c]
                elif x == w - 1:
                    dx = img[y, w - 1, c] - img[y, w - 2, c]
                else:
                    dx = (img[y, x + 1, c] - img[y, x - 1, c]) / 2
                if y == 0:
                    dy = img[1, x, c] - img[0, x, c]
                elif y == h - 1:
                    dy = img[h - 1, x, c] - img[h - 2, x, c]
                else:
                    dy = (img[y + 1, x, c] - img[y - 1, x, c]) / 2
                if dx * dx + dy * dy > best:
                    best = dx * dx + dy * dy
                    gx[y, x], gy[y, x] = dx, dy
    return gx, gy


def ref_cell_histograms(img, cell, n_bins, soft=True):
    """Loop version of the un-normalised histograms: orientation split linearly between
    the two nearest of n_bins bins (bin k centred at 2*pi*k/n_bins; nearest bin only if
    not soft), position split bilinearly between the 4 nearest cell centres, /cell**2,
    cells on the border x 8/7 per border (Piotr's gradHist)."""
    gx, gy = ref_gradients(img)
    hb, wb = gx.shape[0] // cell, gx.shape[1] // cell
    hist = np.zeros((n_bins, hb, wb))
    for y in range(hb * cell):
        for x in range(wb * cell):
            mag = math.hypot(gx[y, x], gy[y, x])
            o = (math.atan2(gy[y, x], gx[y, x]) % (2 * math.pi)) * n_bins / (2 * math.pi)
            if soft:
                o0 = math.floor(o)
                orients = [(o0 % n_bins, 1 - (o - o0)), ((o0 + 1) % n_bins, o - o0)]
            else:
                orients = [(math.floor(o + 0.5) % n_bins, 1.0)]
            ty, tx = (y + 0.5) / cell - 0.5, (x + 0.5) / cell - 0.5
            cy, cx = math.floor(ty), math.floor(tx)
            for yy, wy in ((cy, 1 - (ty - cy)), (cy + 1, ty - cy)):
                for xx, wx in ((cx, 1 - (tx - cx)), (cx + 1, tx - cx)):
                    if 0 <= yy < hb and 0 <= xx < wb:
                        for ob, wo in orients:
                            hist[ob, yy, xx] += mag * wo * wy * wx
    hist /= cell**2
    for edge in (hist[:, 0], hist[:, -1], hist[:, :, 0], hist[:, :, -1]):
        edge *= 8 / 7
    return hist


def ref_normalise(hist, n_orients, clip, cell):
    """Loop version of the block normalisation: each cell is divided by the norm of the
    contrast-insensitive histogram over each 2x2 block containing it (border cells use
    the nearest block), clipped; orientation channels sum the 4 results x 0.5, texture
    channel k sums the 2n sensitive orientations for block k x 0.2357, blocks in the
    order below-right, above-right, below-left, above-left of the cell."""
    n2, hb, wb = hist.shape
    insens = hist[:n_orients] + hist[n_orients:]
    feats = np.concatenate([hist, insens])
    eps = 1e-4 / 4 / cell**4
    out = np.zeros((3 * n_orients + 4, hb, wb))
    for i in range(hb):
        for j in range(wb):
            blocks = [(i, j), (i - 1, j), (i, j - 1), (i - 1, j - 1)]
            for k, (bi, bj) in enumerate(blocks):
                bi, bj = min(max(bi, 0), hb - 2), min(max(bj, 0), wb - 2)
                energy = sum(
                    (insens[o, bi + a, bj + b]) ** 2 for o in range(n_orients) for a in (0, 1) for b in (0, 1)
                )
                norm = 1 / math.sqrt(energy + eps)
                for c in range(3 * n_orients):
                    t = min(feats[c, i, j] * norm, clip)
                    out[c, i, j] += 0.5 * t
                    if c < n2:
                        out[3 * n_orients + k, i, j] += 0.2357 * t
    return out


def textured(shape, seed=0, scale=255.0):
    """A smooth random texture (float32) with gradients in all directions."""
    rng = np.random.default_rng(seed)
    h, w = shape[:2]
    y, x = np.mgrid[0:h, 0:w].astype(np.float64)
    img = np.zeros(shape)
    for _ in range(6):
        fy, fx, ph = rng.uniform(0.05, 0.4), rng.uniform(0.05, 0.4), rng.uniform(0, 2 * np.pi, size=shape[2:] or 1)
        img += np.sin(fy * y[..., None] + fx * x[..., None] * rng.choice([-1, 1]) + ph).reshape(img.shape)
    img -= img.min()
    return (img / img.max() * scale).astype(np.float32)


# ----------------------------------------------------------------- shapes, dtypes


@pytest.mark.parametrize("shape", [(64, 48), (64, 48, 3), (37, 41, 3)])
def test_shape_dtype_layout(shape):
    img = np.random.default_rng(1).integers(0, 256, shape, dtype=np.uint8)
    f = fhog(img)
    assert f.shape == (31, shape[0] // 4, shape[1] // 4)
    assert f.dtype == np.float32 and f.flags.c_contiguous
    assert fhog_channels() == 31
    g = fhog(img, cell_size=8, n_orients=6)
    assert g.shape == (fhog_channels(6), shape[0] // 8, shape[1] // 8) == (22, shape[0] // 8, shape[1] // 8)


def test_uint8_and_float32_with_equal_values_are_identical():
    img = np.random.default_rng(2).integers(0, 256, (40, 44, 3), dtype=np.uint8)
    np.testing.assert_array_equal(fhog(img), fhog(img.astype(np.float32)))


@pytest.mark.parametrize("colour", [False, True])
def test_batch_equals_per_image(colour):
    rng = np.random.default_rng(3)
    shape = (5, 32, 16, 3) if colour else (5, 32, 16)
    # different content per image, so that a seam leaking into a neighbour shows
    batch = (rng.integers(0, 256, shape) * rng.uniform(0.1, 1.0, (5,) + (1,) * (len(shape) - 1))).astype(np.uint8)
    f = fhog(batch, batch=True)
    assert f.shape == (5, 31, 8, 4) and f.dtype == np.float32 and f.flags.c_contiguous
    for i in range(5):
        np.testing.assert_allclose(f[i], fhog(batch[i]), rtol=1e-5, atol=1e-6)
    # rows/columns beyond whole cells are cropped the same way in both paths
    odd = batch[:, :31, :15]
    fo = fhog(odd, batch=True)
    for i in range(5):
        np.testing.assert_allclose(fo[i], fhog(odd[i]), rtol=1e-5, atol=1e-6)


def test_non_contiguous_input():
    img = np.random.default_rng(4).integers(0, 256, (48, 80, 3), dtype=np.uint8)
    view = img[:, ::2]
    np.testing.assert_array_equal(fhog(view), fhog(np.ascontiguousarray(view)))


def test_colour_with_equal_channels_equals_gray():
    gray = np.random.default_rng(5).integers(0, 256, (40, 36), dtype=np.uint8)
    np.testing.assert_array_equal(fhog(np.repeat(gray[..., None], 3, axis=2)), fhog(gray))


# ------------------------------------------------------------- brute-force references


@pytest.mark.parametrize(
    "shape, cell",
    [((16, 16), 4), ((16, 16, 3), 4), ((18, 17), 4), ((12, 10, 3), 2), ((24, 16), 8), ((15, 13, 3), 3),
     ((6, 5), 1)],
)
def test_cell_histograms_match_loop_reference(shape, cell):
    img = np.random.default_rng(6).integers(0, 256, shape, dtype=np.uint8)
    got = _cell_histograms(img[None], cell, 18)[0]
    want = ref_cell_histograms(img, cell, 18)
    assert got.shape == want.shape
    np.testing.assert_allclose(got, want, rtol=1e-4, atol=1e-5 * want.max())


def test_batch_histograms_match_loop_reference():
    # images of a batch share one compiled pass: each must get only its own pixels
    img = np.random.default_rng(15).integers(0, 256, (53, 24, 3), dtype=np.uint8)
    batch = np.stack([img, img[::-1], np.zeros_like(img)])
    got = _cell_histograms(batch, 4, 18)
    for i in range(2):
        want = ref_cell_histograms(batch[i], 4, 18)
        np.testing.assert_allclose(got[i], want, rtol=1e-4, atol=1e-5 * want.max())
    assert not got[2].any()


def test_hard_orientation_binning_matches_loop_reference():
    # Nearest-bin rounding jumps at bin boundaries, so use ramps whose directions
    # lie 5 degrees off bin centres (and check that no pixel, seams included, is
    # within float32 noise of a boundary).
    rng = np.random.default_rng(7)
    y, x = np.mgrid[0:16, 0:16]
    img = np.zeros((16, 16))
    for (r0, r1, c0, c1) in [(0, 8, 0, 8), (0, 8, 8, 16), (8, 16, 0, 8), (8, 16, 8, 16)]:
        a = np.deg2rad(20 * rng.integers(0, 18) + rng.choice([-5, 5]))
        img[r0:r1, c0:c1] = (3 * np.cos(a) * x + 3 * np.sin(a) * y)[r0:r1, c0:c1]
    img = (img - img.min()).astype(np.float32)
    gx, gy = ref_gradients(img)
    o = np.arctan2(gy, gx) % (2 * np.pi) * 18 / (2 * np.pi) - 0.5
    assert np.abs(o - np.round(o))[np.hypot(gx, gy) > 0].min() > 1e-3
    got = _cell_histograms(img[None], 4, 18, soft_orientation=False)[0]
    want = ref_cell_histograms(img, 4, 18, soft=False)
    np.testing.assert_allclose(got, want, rtol=1e-4, atol=1e-4 * want.max())
    assert fhog(img, soft_orientation=False).shape == (31, 4, 4)


@pytest.mark.parametrize("shape", [(16, 16), (16, 20, 3)])
def test_normalised_output_matches_loop_reference(shape):
    img = np.random.default_rng(8).integers(0, 256, shape, dtype=np.uint8)
    want = ref_normalise(ref_cell_histograms(img, 4, 18), 9, 0.2, 4)
    np.testing.assert_allclose(fhog(img, soft_orientation=True), want, rtol=1e-4, atol=1e-5)
    # a smooth texture: most values below the clip, so the normaliser itself is tested
    tex = textured((16, 16), seed=9)
    want = ref_normalise(ref_cell_histograms(tex, 4, 18), 9, 0.2, 4)
    np.testing.assert_allclose(fhog(tex, soft_orientation=True), want, rtol=1e-4, atol=1e-5)


def test_other_parameters_match_loop_reference():
    img = np.random.default_rng(13).integers(0, 256, (10, 12, 3), dtype=np.uint8)
    want = ref_normalise(ref_cell_histograms(img, 2, 12), 6, 0.3, 2)
    got = fhog(img, cell_size=2, n_orients=6, clip=0.3, soft_orientation=True)
    assert got.shape == (22, 5, 6)
    np.testing.assert_allclose(got, want, rtol=1e-4, atol=1e-5)


def test_scratch_buffers_are_per_thread_and_per_shape():
    # fhog reuses scratch arrays between calls: results must not depend on what ran
    # before, in this thread or another.
    from concurrent.futures import ThreadPoolExecutor

    rng = np.random.default_rng(14)
    images = [rng.integers(0, 256, (8 * (k % 3 + 2), 8 * (k % 2 + 2), 3), dtype=np.uint8) for k in range(7)]
    expected = [fhog(im) for im in images]
    for im, want in zip(images[::-1], expected[::-1]):  # more shapes than are kept
        np.testing.assert_array_equal(fhog(im), want)
    with ThreadPoolExecutor(2) as pool:
        for got, want in zip(pool.map(fhog, images * 3), expected * 3):
            np.testing.assert_array_equal(got, want)


def test_empty_batch():
    assert fhog(np.zeros((0, 32, 24, 3), np.uint8), batch=True).shape == (0, 31, 8, 6)


# ------------------------------------------------------------------ known edges


def channel_energy(f):
    """(31,) total of each channel over the interior cells (away from the image border)."""
    return f[:, 1:-1, 1:-1].sum(axis=(1, 2))


def step(shape, axis, rising=True):
    img = np.zeros(shape, np.uint8)
    half = shape[axis] // 2
    if axis == 1:
        img[:, half:] = 200
    else:
        img[half:, :] = 200
    return img if rising else 200 - img


def test_vertical_edge_goes_to_direction_0_or_pi():
    rising = channel_energy(fhog(step((32, 32), axis=1, rising=True)))  # dark -> bright along x: angle 0
    falling = channel_energy(fhog(step((32, 32), axis=1, rising=False)))  # angle pi
    assert rising[:18].argmax() == 0 and rising[:18].sum() == pytest.approx(rising[0])
    assert falling[:18].argmax() == 9 and falling[:18].sum() == pytest.approx(falling[9])
    # opposite contrast-sensitive bins, same contrast-insensitive bin
    assert rising[18:27].argmax() == falling[18:27].argmax() == 0
    np.testing.assert_allclose(rising[18:27], falling[18:27], rtol=1e-6)


def test_horizontal_edge_goes_to_direction_half_pi():
    # angle pi/2 lies half way between bins 4 and 5 (20 degrees each)
    down = channel_energy(fhog(step((32, 32), axis=0, rising=True), soft_orientation=True))
    up = channel_energy(fhog(step((32, 32), axis=0, rising=False), soft_orientation=True))
    assert set(np.argsort(down[:18])[-2:]) == {4, 5}
    assert down[4] == pytest.approx(down[5], rel=1e-3) and down[4] + down[5] == pytest.approx(down[:18].sum())
    assert set(np.argsort(up[:18])[-2:]) == {13, 14}  # 3pi/2
    assert set(np.argsort(down[18:27])[-2:]) == set(np.argsort(up[18:27])[-2:]) == {4, 5}


def test_diagonal_edge_goes_to_matching_bins():
    y, x = np.mgrid[0:32, 0:32]
    img = np.where(x + y >= 32, 200, 0).astype(np.uint8)  # gradient along (1, 1): 45 degrees
    e = channel_energy(fhog(img, soft_orientation=True))
    # 45 degrees = 2.25 bins: 3/4 in bin 2, 1/4 in bin 3 (before clipping)
    assert list(np.argsort(e[:18])[-2:]) == [3, 2]
    h = _cell_histograms(img[None], 4, 18)[0, :, 1:-1, 1:-1].sum(axis=(1, 2))  # no one-sided border pixels
    assert h[2] / h[3] == pytest.approx(3.0, rel=1e-3)
    assert h[2] + h[3] == pytest.approx(h.sum())


@pytest.mark.parametrize("degrees", [0, 30, 45, 100, 200, 315])
def test_ramp_direction_splits_between_nearest_bins(degrees):
    # A linear ramp has the same gradient at every pixel, border included.
    a = np.deg2rad(degrees)
    y, x = np.mgrid[0:24, 0:24]
    img = (100 + 2 * np.cos(a) * x + 2 * np.sin(a) * y).astype(np.float32)
    h = _cell_histograms(img[None], 4, 18)[0].sum(axis=(1, 2))
    o = degrees / 20
    o0 = int(np.floor(o))
    expected = np.zeros(18)
    expected[o0 % 18] += 1 - (o - o0)
    expected[(o0 + 1) % 18] += o - o0
    np.testing.assert_allclose(h / h.sum(), expected, atol=1e-5)


# ---------------------------------------------------------- normalisation, clipping


def test_values_finite_nonnegative_and_bounded():
    img = np.random.default_rng(10).integers(0, 256, (60, 52, 3), dtype=np.uint8)
    f = fhog(img)
    assert np.isfinite(f).all() and (f >= 0).all()
    assert f[:27].max() <= 4 * 0.5 * 0.2 + 1e-6  # 4 clipped normalisations x 0.5
    assert f[27:].max() <= 18 * 0.2357 * 0.2 + 1e-6


def test_contrast_scaling_leaves_features_unchanged():
    tex = textured((48, 48, 3), seed=11, scale=100.0)
    f1, f2 = fhog(tex), fhog(tex * np.float32(2))
    np.testing.assert_allclose(f1, f2, atol=1e-4)
    assert f1.max() > 0.05  # not trivially zero


def test_constant_image_gives_zero_features():
    for value in (0, 128, 255):
        f = fhog(np.full((32, 40, 3), value, np.uint8))
        assert np.abs(f).max() == 0.0


def test_clip_bounds_each_normalised_value():
    img = np.random.default_rng(12).integers(0, 256, (32, 32), dtype=np.uint8)
    tight = fhog(img, clip=0.05)
    assert tight[:27].max() <= 4 * 0.5 * 0.05 + 1e-6
    assert (fhog(img, clip=10.0)[:27] >= tight[:27] - 1e-6).all()


# -------------------------------------------------------------------------- errors


@pytest.mark.parametrize(
    "image, kwargs, match",
    [
        (np.zeros(64, np.uint8), {}, r"shape \(64,\).*\(H, W\) or \(H, W, 3\)"),
        (np.zeros((5, 5), np.uint8), {}, r"\(5, 5\).*too small.*8 pixels"),
        (np.zeros((32, 32, 4), np.uint8), {}, r"shape \(32, 32, 4\)"),
        (np.zeros((2, 32, 32), np.uint8), {}, r"batch=True"),
        (np.zeros((32, 32), np.uint8), {"batch": True}, r"\(N, H, W\)"),
        (np.zeros((32, 32), np.float64), {}, r"dtype float64.*uint8.*float32"),
        (np.zeros((32, 32), np.uint8), {"cell_size": 0}, r"cell_size"),
    ],
)
def test_invalid_input_raises_informative_value_error(image, kwargs, match):
    with pytest.raises(ValueError, match=match):
        fhog(image, **kwargs)


def test_result_does_not_depend_on_where_the_image_sits_in_memory():
    """cv2.magnitude's SIMD path rounded differently by alignment, which made tracking
    non-deterministic across processes; the magnitude is computed with numpy instead."""
    patch = np.random.default_rng(21).integers(0, 256, (64, 72, 3), dtype=np.uint8)
    expected = fhog(patch)
    for offset in range(1, 9):
        storage = np.empty(patch.size + offset, np.uint8)
        moved = storage[offset:].reshape(patch.shape)
        moved[:] = patch
        np.testing.assert_array_equal(fhog(moved), expected)


# The authors' MATLAB detail this option reproduces, against an independent reference (the
# line worked out by hand or re-run in numpy, a brute-force loop, a dense solve). file.m:line
# cites ../shared/reference/DR2Track/DR2Track1 unless STRCF's (../shared/reference/STRCF) is named.
# --------------------------------------------------------------------------------------------
# the authors' MATLAB: fhog: which channel wins a tie; Piotr's SSE arithmetic
# --------------------------------------------------------------------------------------------

X86_ONLY = pytest.mark.skipif(platform.machine().lower() not in ("x86_64", "amd64"),
                              reason="the processor's own SSE estimates need x86-64")


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

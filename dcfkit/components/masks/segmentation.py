"""CSR-DCF's segmentation (Lukežič et al., CVPR 2017, Sec. 3.1): colour histograms of the
target and its surroundings, a spatial prior, and the posteriors smoothed by the Markov random
field of Kristan et al. (ACCV 2014), as the authors' ``segment.cpp`` computes them.

Every function is pure numpy/OpenCV on small arrays: a histogram is ``n_bins³`` float64
values, its bin of a pixel ``Σ_d n_bins^(2-d) ⌊n_bins v_d / 256⌋`` over the three channels.
"""
from __future__ import annotations

import cv2
import numpy as np

EPANECHNIKOV = 2.0 / 3.14  # the authors' kernel profile constant (it cancels in every normalisation)
P_BACKGROUND = 5.0 / 3.0  # segment.cpp's prior of the background relative to the foreground
MAX_ITERATIONS, TOLERANCE = 50, 0.1  # the MRF's iterations and its stop on the mean log-likelihood


def hsv255(bgr: np.ndarray) -> np.ndarray:
    """(H, W, 3) uint8 BGR -> (H, W, 3) uint8 HSV on 0..255: ``rgb2hsv(img) * 255`` as the authors'
    mex reads it (rounded to even): Octave's rgb2hsv in double, its operations in its order, red
    winning ties with green and blue, green with blue. (OpenCV's 8-bit hue runs to 180 or wraps.)"""
    x = bgr.astype(np.float64)
    x /= 255  # im2double
    b, g, r = x[..., 0], x[..., 1], x[..., 2]
    low, v = np.minimum(np.minimum(b, g), r), np.maximum(np.maximum(b, g), r)
    red, green = v == r, v == g
    gray = low == v
    d = v - low
    d[gray] = 1.0
    num = np.where(red, g - b, np.where(green, b - r, r - g))
    num *= 1 / 6
    num /= d
    h = np.where(red, 0.0, np.where(green, 1 / 3, 2 / 3))
    h += num  # 2/3 + 1/6 * (r - g) ./ (v - s), and so on
    h[gray] = 0.0
    h[h < 0] += 1
    sat = low / np.where(gray, 1.0, v)
    np.subtract(1.0, sat, out=sat)
    sat[gray] = 0.0
    out = np.stack([h, sat, v], axis=2)
    out *= 255
    return np.rint(out, out=out).astype(np.uint8)


def bins(pixels: np.ndarray, n_bins: int) -> np.ndarray:
    """The histogram bin of every pixel of (..., 3) uint8 -> (...) int64."""
    q = pixels.astype(np.int32) * n_bins // 256
    return (q[..., 0] * n_bins + q[..., 1]) * n_bins + q[..., 2]


def foreground_histogram(pixels: np.ndarray, box: tuple[int, int, int, int], n_bins: int) -> np.ndarray:
    """Histogram of the box (x1, y1, x2, y2), inclusive pixel indices of ``pixels``, each pixel
    weighted by an Epanechnikov kernel on the box (extractForegroundHistogram); sums to 1."""
    x1, y1, x2, y2 = box
    ys, xs = np.mgrid[y1:y2 + 1, x1:x2 + 1]
    kw, kh = 1.0 / (0.5 * (x2 - x1) * 1.4142 + 1), 1.0 / (0.5 * (y2 - y1) * 1.4142 + 1)
    d = ((x1 + (x2 - x1) / 2.0 - xs) * kw) ** 2 + ((y1 + (y2 - y1) / 2.0 - ys) * kh) ** 2
    weights = np.where(d <= 1, EPANECHNIKOV * (1 - d), 0.0)
    hist = np.bincount(bins(pixels[y1:y2 + 1, x1:x2 + 1], n_bins).ravel(), weights.ravel(), n_bins**3)
    return hist / max(hist.sum(), np.finfo(float).tiny)


def background_histogram(pixels: np.ndarray, box: tuple[int, int, int, int], outer: tuple[int, int, int, int],
                         n_bins: int) -> np.ndarray:
    """Histogram of the ``outer`` rows and columns [x1, x2) x [y1, y2) but the ``box``
    (inclusive), unweighted (extractBackGroundHistogram); sums to 1."""
    ox1, oy1, ox2, oy2 = outer
    x1, y1, x2, y2 = box
    ring = np.ones((max(oy2 - oy1, 0), max(ox2 - ox1, 0)), np.uint8)
    ring[max(y1 - oy1, 0):max(y2 + 1 - oy1, 0), max(x1 - ox1, 0):max(x2 + 1 - ox1, 0)] = 0
    if not ring.any():
        return np.zeros(n_bins**3)
    # OpenCV's uniform bins over [0, 256): bin ⌊n_bins v / 256⌋ of each channel, channel 0 first
    hist = cv2.calcHist([np.ascontiguousarray(pixels[oy1:oy2, ox1:ox2])], [0, 1, 2], ring, [n_bins] * 3,
                        [0, 256] * 3).ravel().astype(float)
    return hist / hist.sum()


def location_prior(shape: tuple[int, int], target: np.ndarray, rows=None, cols=None) -> np.ndarray:
    """The foreground prior over a patch of ``shape`` (h, w) pixels (get_location_prior): an
    Epanechnikov kernel of the target's smaller side, centred, scaled to peak 1 and clipped
    to [0.5, 0.9]; the background's is 1 minus it. (h, w) float64, or only at ``rows`` x ``cols``."""
    h, w = shape
    k = 1.0 / (0.5 * float(np.min(target)) * 1.4142 + 1)
    dy = (np.arange(1, h + 1) - (1 + 0.5 * (h - 1))) * k
    dx = (np.arange(1, w + 1) - (1 + 0.5 * (w - 1))) * k
    peak = 1.0 - (np.min(dy * dy) + np.min(dx * dx))
    if rows is not None:
        dy, dx = dy[rows], dx[cols]
    d = np.add.outer(dy * dy, dx * dx)
    # the profile (1 - d) over its peak, 0 beyond d = 1 (raised to 0.5 by the clip all the same)
    np.subtract(1.0, d, out=d)
    d *= 1.0 / peak
    return np.clip(d, 0.5, 0.9, out=d)


def mrf_kernels(width: int) -> tuple[np.ndarray, np.ndarray]:
    """The MRF's neighbourhood: a Gaussian of half-size ⌊3 width / 50 + 0.5⌋ (at least 1), σ a
    third of it, its centre 0 and the rest summing to 1 (λ), and the same with centre 1 (λ₂)."""
    half = max(1, int(np.floor(width * 3.0 / 50.0 + 0.5)))
    r = np.arange(-half, half + 1, dtype=float)
    std2 = (half / 3.0) ** 2
    lam = np.exp(-(r[:, None] ** 2 + r[None, :] ** 2) / (2 * std2)) / (2 * np.pi * std2)
    lam[half, half] = 0.0
    lam /= lam.sum()
    lam2 = lam.copy()
    lam2[half, half] = 1.0
    return lam, lam2


def regularised(prob_o: np.ndarray, prior_o: np.ndarray) -> np.ndarray:
    """The MRF smoothing of segment.cpp's getRegularizedSegmentation (Kristan et al., ACCV 2014):
    from the foreground posterior and prior (h, w) float64, the smoothed foreground
    probability Q_o, iterated until the mean log-likelihood moves less than 0.1 (at most 50).
    Foreground and background are filtered together, as the channels of one image."""
    lam, lam2 = mrf_kernels(prob_o.shape[1])
    eps = np.finfo(float).eps
    prob = np.dstack([prob_o, 1.0 - prob_o])
    # the four maps filtered together: the priors (o, b) and the likelihoods P_I (o, b)
    state = np.dstack([prior_o, 1.0 - prior_o, prior_o, prior_o])
    prior, p_i = state[..., :2], state[..., 2:]
    reflect = cv2.BORDER_REFLECT
    log_like = np.finfo(float).max
    for _ in range(MAX_ITERATIONS):
        np.multiply(prior, prob, out=p_i)
        p_i += eps
        s_q = cv2.filter2D(state, -1, lam, borderType=reflect)
        s_q *= state
        s_q[..., :2] /= (s_q[..., 0] + s_q[..., 1])[..., None]  # S_i, normalised over o and b
        s_q[..., 2:] /= (s_q[..., 2] + s_q[..., 3])[..., None]  # Q_i
        sums = cv2.filter2D(s_q, -1, lam2, borderType=reflect)  # S_sum (o, b), Q_sum (o, b)
        np.add(sums[..., 2:], sums[..., :2], out=prior)
        prior /= (prior[..., 0] + prior[..., 1])[..., None]  # the 0.25 cancels here
        new = -np.log(sums[..., 2:]).sum() / (2 * prob_o.size)
        if abs(log_like - new) < TOLERANCE:
            break
        log_like = new
    return sums[..., 2]


def linear_taps(n_in: int, n_out: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """OpenCV's INTER_LINEAR resampling of ``n_in`` pixels to ``n_out``: for each output pixel
    its two source pixels and the second's weight (``cv::resize``'s geometry: pixel centres
    aligned, the borders clamped)."""
    f = (np.arange(n_out) + 0.5) * (n_in / n_out) - 0.5
    i0 = np.floor(f).astype(np.int64)
    w = f - i0
    low, high = i0 < 0, i0 >= n_in - 1
    w[low | high] = 0.0
    i0 = np.clip(i0, 0, n_in - 1)
    return i0, np.minimum(i0 + 1, n_in - 1), w


def bilinear(read, taps_y, taps_x) -> np.ndarray:
    """The bilinear resampling of a map that ``read(rows, cols)`` gives only where it is needed
    ((len(rows), len(cols)[, C]) float), float64: the four source pixels of each output pixel."""
    (y0, y1, wy), (x0, x1, wx) = taps_y, taps_x
    top_left = read(y0, x0)
    extra = (1,) * (top_left.ndim - 2)  # a colour axis
    wy, wx = wy.reshape(-1, 1, *extra), wx.reshape(1, -1, *extra)
    top = top_left * (1 - wx) + read(y0, x1) * wx
    bottom = read(y1, x0) * (1 - wx) + read(y1, x1) * wx
    return top * (1 - wy) + bottom * wy


def small_size(h: int, w: int) -> tuple[int, int]:
    """segment.cpp's working size (w, h): the patch less one pixel each way, shrunk to about 1000
    pixels (never enlarged), truncated as cv::Size truncates."""
    factor = min(1.0, float(np.sqrt(1000.0 / max((w - 1) * (h - 1), 1))))
    return max(int((w - 1) * factor), 1), max(int((h - 1) * factor), 1)


def posterior(pixels, shape: tuple[int, int], hist_fg: np.ndarray, hist_bg: np.ndarray, target: np.ndarray,
              n_bins: int, unseen: str = "neutral") -> np.ndarray | None:
    """segment.cpp's computePosteriors on a patch of ``shape`` (h, w) that ``pixels(rows, cols)``
    reads ((n, m, 3) uint8 colours): the patch and the :func:`location_prior` of the ``target``
    size shrunk to about 1000 pixels (bilinearly, each read only at the pixels the shrinking
    takes: :func:`bilinear`), each pixel's likelihoods from the histograms times the priors,
    Bayes' rule with the background 5/3 as likely, and the MRF: the foreground probability at
    that small size (:func:`on_grid` takes it to the filter grid). Where neither histogram has
    the pixel's colour, 0.5 (``unseen`` 'neutral'), or None ('discard': the authors' 0/0, a NaN
    that their MRF, which then runs all its iterations, spreads over the whole patch)."""
    h, w = shape
    size = small_size(h, w)
    taps = linear_taps(h, size[1]), linear_taps(w, size[0])
    small = np.rint(bilinear(lambda r, c: pixels(r, c).astype(np.float32), *taps)).astype(np.uint8)
    prior_o = bilinear(lambda r, c: location_prior((h, w), target, r, c), *taps)
    index = bins(small, n_bins)
    fg = hist_fg[index] * prior_o
    bg = hist_bg[index] * (1.0 - prior_o)
    p_o = 1.0 / (P_BACKGROUND + 1)
    den = p_o * fg + P_BACKGROUND * bg
    if unseen == "discard" and not den.all():
        return None
    prob_o = np.divide(p_o * fg, den, out=np.full_like(fg, 0.5), where=den > 0)
    return regularised(prob_o, prior_o)


def _extremes(first_tap: np.ndarray, lo: int, hi: int) -> np.ndarray:
    """The output pixels lo..hi-1 that are the first or last to read their source pixel: where
    a bilinear resize takes its extreme values (it is linear in each weight between them)."""
    taps = first_tap[lo:hi]
    change = taps[1:] != taps[:-1]
    return np.arange(lo, hi)[np.r_[True, change] | np.r_[change, True]]


def on_grid(q: np.ndarray, size: tuple[int, int], keep: tuple[tuple[int, int], tuple[int, int]],
            grid: tuple[int, int], threshold: float) -> np.ndarray:
    """The authors' mask of segment.cpp's small foreground probability ``q``: resized (bilinear)
    to the patch's ``size`` (h, w), zero outside the rows and columns ``keep`` ((r0, r1), (c0, c1)),
    divided by its maximum, above ``threshold``, then ``imresize(.., grid, 'nearest')``: (grid)
    bool. Computed at the patch pixels 'nearest' reads, and the maximum at the pixels where the
    bilinear resize takes its extremes (:func:`_extremes`), never at the patch's full size."""
    taps = linear_taps(q.shape[0], size[0]), linear_taps(q.shape[1], size[1])

    def at(rows, cols):  # the resized map at rows x cols
        return bilinear(lambda r, c: q[np.ix_(r, c)], *((t[0][i], t[1][i], t[2][i]) for t, i in zip(taps, (rows, cols))))

    (r0, r1), (c0, c1) = keep
    peak = float(at(_extremes(taps[0][0], r0, r1), _extremes(taps[1][0], c0, c1)).max()) if r1 > r0 and c1 > c0 else 0
    rows, cols = (((np.arange(g) + 0.5) * n / g).astype(int) for g, n in zip(grid, size))  # MATLAB's 'nearest'
    values = at(rows, cols).astype(np.float32)  # the mex's single
    values *= ((rows >= r0) & (rows < r1))[:, None] & ((cols >= c0) & (cols < c1))[None, :]
    return values / np.float32(peak if peak > 0 else 1.0) > threshold

"""KCF's kernel solver and DSST's ridge solver against dense references (every cyclic shift
written out, np.linalg.solve), and the two shipped trackers on generated scenes: both follow
a moving target, KCF keeps its box size, DSST follows a zoom."""
import cv2
import numpy as np
import pytest

import dcfkit
from dcfkit.components.labels.base import gaussian_label
from dcfkit.components.solvers import KernelParams, KernelRidge, Ridge, RidgeParams, kernel_correlation
from dcfkit.components.solvers.kcf import squared_norm
from dcfkit.config import load_config
from dcfkit.errors import ConfigError
from dcfkit.numerics.fft import make_fft
from dcfkit.params import parse_params

SHAPES = [(5, 6), (6, 7), (4, 4)]  # even and odd widths: the half spectrum's Parseval weights differ


def shifted(z: np.ndarray, ty: int, tx: int) -> np.ndarray:
    """(P^τ z)(p) = z(p + τ), circularly, for (C, H, W) maps."""
    return np.roll(z, (-ty, -tx), axis=(-2, -1))


def kernel(p: KernelParams, a: np.ndarray, b: np.ndarray) -> float:
    """κ(a, b) of KCF's three kernels, N = a.size, in float64."""
    n, a, b = a.size, a.astype(np.float64), b.astype(np.float64)
    if p.kernel == "gaussian":
        return float(np.exp(-np.sum((a - b) ** 2) / (p.sigma**2 * n)))
    dot = float(np.sum(a * b)) / n
    return dot if p.kernel == "linear" else (dot + p.poly_a) ** p.poly_b


def brute_kernel_correlation(p, x, z):
    """k^{xz}(τ) = κ(P^τ z, x) at every shift τ, one shift at a time."""
    _, H, W = x.shape
    return np.array([[kernel(p, shifted(z, ty, tx), x) for tx in range(W)] for ty in range(H)])


def dense_kernel_matrix(p, x):
    """K_στ = κ(P^σ x, P^τ x) over all cyclic shifts, flattened row-major (σ = (σy, σx))."""
    _, H, W = x.shape
    shifts = [shifted(x, ty, tx) for ty in range(H) for tx in range(W)]
    return np.array([[kernel(p, a, b) for b in shifts] for a in shifts])


def data_matrix(x):
    """X with (X h)[τ] = Σ_c Σ_p h_c(p) x_c(p + τ) (dcfkit's correlation), h flattened (c, y, x)."""
    _, H, W = x.shape
    return np.array([shifted(x, ty, tx).reshape(-1) for ty in range(H) for tx in range(W)], np.float64)


def spectra(fft, *maps):
    return [fft.rfft2(np.asarray(m, np.float32)).astype(np.complex64) for m in maps]


KERNELS = [KernelParams(kernel="gaussian", sigma=0.5), KernelParams(kernel="gaussian", sigma=2.0),
           KernelParams(kernel="linear"), KernelParams(kernel="polynomial", poly_a=1.0, poly_b=3)]


# ------------------------------------------------------------------------- KCF's kernel solver


@pytest.mark.parametrize("backend", ["scipy", "pyfftw"])
@pytest.mark.parametrize("shape", SHAPES)
@pytest.mark.parametrize("p", KERNELS, ids=lambda p: f"{p.kernel}-{p.sigma}")
def test_kernel_correlation_is_the_kernel_at_every_cyclic_shift(p, shape, backend):
    rng = np.random.default_rng(0)
    fft = make_fft(backend)
    x = rng.standard_normal((3, *shape)).astype(np.float32)
    zs = rng.standard_normal((2, 3, *shape)).astype(np.float32)
    zs[1] = shifted(x, 1, 2) + 0.1 * zs[1]  # near a shift of x: the Gaussian's distance nearly cancels there
    xf, zf = spectra(fft, x, zs)
    got = kernel_correlation(xf, zf, shape, p, fft)
    assert got.shape == (2, *shape)
    for z, k in zip(zs, got):
        np.testing.assert_allclose(k, brute_kernel_correlation(p, x, z), rtol=1e-5, atol=1e-7)


@pytest.mark.parametrize("shape", SHAPES)
def test_squared_norms_from_half_spectra_are_exact(shape):
    rng = np.random.default_rng(1)
    x = rng.standard_normal((2, 3, *shape))
    np.testing.assert_allclose(squared_norm(np.fft.rfft2(x), shape), np.sum(x**2, axis=(1, 2, 3)), rtol=1e-12)


def first_frame(solver, x, y, fft):
    xf, yf = spectra(fft, x, y)
    return xf, solver.train(xf, yf[0] if yf.ndim == 3 else yf, np.zeros(y.shape, np.float32), 0.0, fft)


@pytest.mark.parametrize("shape", SHAPES)
@pytest.mark.parametrize("p", KERNELS, ids=lambda p: f"{p.kernel}-{p.sigma}")
def test_kernel_ridge_is_the_dense_kernel_ridge_regression(p, shape):
    """α = (K + λI)⁻¹ y with the dense kernel matrix over all cyclic shifts of x (KCF Eq. 17
    against its definition); the response on the training sample is Kα = y - λα."""
    rng = np.random.default_rng(2)
    fft = make_fft("scipy")
    p = KernelParams(**{**vars(p), "lam": 0.05})  # a λ that shows: y - λα differs from y
    x = rng.standard_normal((3, *shape)).astype(np.float32)
    y = gaussian_label(shape, 1.0)
    K = dense_kernel_matrix(p, x)
    alpha = np.linalg.solve(K + p.lam * np.eye(K.shape[0]), y.reshape(-1).astype(np.float64)).reshape(shape)
    solver = KernelRidge(p)
    xf, model = first_frame(solver, x, y, fft)
    np.testing.assert_allclose(fft.irfft2(solver.alphaf, shape), alpha, rtol=1e-4, atol=1e-5 * np.abs(alpha).max())
    response = solver.response(model, xf[None], shape, fft)
    assert response.shape == (1, *shape) and response.dtype == np.float32
    np.testing.assert_allclose(response[0], (K @ alpha.reshape(-1)).reshape(shape), rtol=1e-4, atol=1e-5)
    np.testing.assert_allclose(response[0], y - p.lam * alpha, rtol=1e-4, atol=1e-5)


def test_kernel_ridge_with_a_small_lambda_reproduces_the_label_and_follows_a_shift():
    """KCF's λ = 1e-4: the response on the training sample is the label, and on the sample
    moved by τ it is the label moved by τ (the regression is over every cyclic shift)."""
    fft = make_fft("scipy")
    rng = np.random.default_rng(3)
    shape = (12, 15)
    x = rng.standard_normal((4, *shape)).astype(np.float32)
    y = gaussian_label(shape, 1.5)
    solver = KernelRidge(KernelParams())
    xf, model = first_frame(solver, x, y, fft)
    moved = spectra(fft, np.roll(x, (3, -5), axis=(1, 2)))[0]  # the content moved by (3, -5)
    maps = solver.response(model, np.stack([xf, moved]), shape, fft)
    np.testing.assert_allclose(maps[0], y, atol=1e-3)
    np.testing.assert_allclose(maps[1], np.roll(y, (3, -5), axis=(0, 1)), atol=1e-3)


def test_kernel_ridge_interpolates_the_model_and_alpha():
    """KCF's model update: x̂ and α̂ each (1 - η) old + η new; η = 1 keeps the new frame alone."""
    fft = make_fft("scipy")
    rng = np.random.default_rng(4)
    shape = (6, 7)
    x1, x2 = rng.standard_normal((2, 2, *shape)).astype(np.float32)
    y = gaussian_label(shape, 1.0)
    alone = KernelRidge(KernelParams())
    x2f, _ = first_frame(alone, x2, y, fft)
    for eta in (1.0, 0.3):
        solver = KernelRidge(KernelParams(learning_rate=eta))
        x1f, _ = first_frame(solver, x1, y, fft)
        first_alpha = solver.alphaf.copy()
        model = solver.train(x2f, spectra(fft, y)[0], np.zeros(shape, np.float32), 0.0, fft)
        np.testing.assert_allclose(model, (1 - eta) * x1f + eta * x2f, rtol=1e-5, atol=1e-4)
        np.testing.assert_allclose(solver.alphaf, (1 - eta) * first_alpha + eta * alone.alphaf, rtol=1e-6, atol=1e-9)


# ------------------------------------------------------------------------- DSST's ridge solver


@pytest.mark.parametrize("backend", ["scipy", "pyfftw"])
@pytest.mark.parametrize("shape", SHAPES)
def test_ridge_is_the_dense_multichannel_ridge_regression(shape, backend):
    """One frame: ĥ = A / (B + λ) (DSST Eq. 2) is argmin ‖X h - y‖² + λ‖h‖² over all cyclic
    shifts, X the dense circulant data matrix of the C channels."""
    rng = np.random.default_rng(5)
    fft = make_fft(backend)
    C, lam = 3, 0.3
    x = rng.standard_normal((C, *shape)).astype(np.float32)
    y = gaussian_label(shape, 1.0)
    X = data_matrix(x)
    h = np.linalg.solve(X.T @ X + lam * np.eye(X.shape[1]), X.T @ y.reshape(-1)).reshape(C, *shape)
    solver = Ridge(RidgeParams(lam=lam))
    xf, hf = first_frame(solver, x, y, fft)
    assert hf.shape == xf.shape and hf.dtype == np.complex64
    np.testing.assert_allclose(fft.irfft2(hf, shape), h, rtol=1e-4, atol=1e-5 * np.abs(h).max())
    response = solver.response(hf, xf[None], shape, fft)[0]  # the linear response (DSST Eq. 4)
    np.testing.assert_allclose(response, (X @ h.reshape(-1)).reshape(shape), rtol=1e-4, atol=1e-5)


def test_ridge_averages_numerator_and_denominator():
    """DSST Eq. 3: A and B each (1 - η) old + η new, ĥ = A / (B + λ); with η = 1 the filter
    is the second frame's dense solution alone."""
    fft = make_fft("scipy")
    rng = np.random.default_rng(6)
    shape, lam = (5, 6), 0.2
    x1, x2 = rng.standard_normal((2, 2, *shape)).astype(np.float32)
    y = gaussian_label(shape, 1.0)
    X = data_matrix(x2)
    alone = np.linalg.solve(X.T @ X + lam * np.eye(X.shape[1]), X.T @ y.reshape(-1)).reshape(2, *shape)
    (yf,) = spectra(fft, y)
    for eta in (1.0, 0.25):
        solver = Ridge(RidgeParams(lam=lam, learning_rate=eta))
        x1f, _ = first_frame(solver, x1, y, fft)
        x2f = spectra(fft, x2)[0]
        hf = solver.train(x2f, yf, np.zeros(shape, np.float32), 0.0, fft)
        energy = lambda f: np.sum(np.abs(f.astype(np.complex128)) ** 2, axis=0)  # noqa: E731
        num = np.conj(yf) * ((1 - eta) * x1f + eta * x2f)
        den = (1 - eta) * energy(x1f) + eta * energy(x2f)
        np.testing.assert_allclose(hf, num / (den + lam), rtol=1e-4, atol=1e-6)
        if eta == 1.0:
            np.testing.assert_allclose(fft.irfft2(hf, shape), alone, rtol=1e-4, atol=1e-5 * np.abs(alone).max())


# ------------------------------------------------------------------------- parameters and configs


@pytest.mark.parametrize("cls, params, key", [
    (KernelRidge, {"lam": 0.0}, "lam"), (KernelRidge, {"sigma": 0.0}, "sigma"),
    (KernelRidge, {"poly_a": -1.0}, "poly_a"), (KernelRidge, {"poly_b": 0}, "poly_b"),
    (KernelRidge, {"learning_rate": 0.0}, "learning_rate"), (Ridge, {"lam": 0.0}, "lam"),
    (Ridge, {"learning_rate": 1.5}, "learning_rate"),
])
def test_values_the_closed_forms_cannot_take_are_refused(cls, params, key):
    with pytest.raises(ConfigError, match=key):
        parse_params(cls.Params, params, "x")


@pytest.mark.parametrize("solver", ["kernel_ridge", "ridge"])
@pytest.mark.parametrize("role, spec", [("spatial", {"name": "box"}), ("temporal", {"name": "temporal"})])
def test_a_regularizer_the_closed_forms_have_no_term_for_is_refused(solver, role, spec):
    with pytest.raises(ConfigError, match=rf"solver '{solver}' has no {role} term.*regularizers\.{role}: null"):
        dcfkit.load_tracker({"name": "t", "features": [{"name": "gray"}], "label": {"name": "gaussian"},
                             "regularizers": {role: spec}, "solver": {"name": solver}})


def test_the_configs_have_the_papers_parameters():
    kcf, dsst = load_config("kcf"), load_config("dsst")
    assert kcf["solver"] == {"name": "kernel_ridge", "kernel": "gaussian", "sigma": 0.5, "poly_a": 1.0, "poly_b": 9,
                             "lam": 1e-4, "learning_rate": 0.02}
    assert kcf["tracker"]["search_area_scale"] == 2.5 and kcf["tracker"]["search_area_shape"] == "proportional"
    assert kcf["tracker"]["output_sigma_factor"] == 0.1 and kcf["tracker"]["cell_size"] == 4
    assert kcf["tracker"]["window"] == "hann" and [f["name"] for f in kcf["features"]] == ["fhog"]
    assert kcf["scale"] == {"name": "fixed"} and kcf["regularizers"] == {"spatial": None, "temporal": None}
    assert dsst["solver"] == {"name": "ridge", "lam": 0.01, "learning_rate": 0.025}
    assert dsst["tracker"]["search_area_scale"] == 2 and dsst["tracker"]["output_sigma_factor"] == 1 / 16
    assert [f["name"] for f in dsst["features"]] == ["gray", "fhog"] and dsst["tracker"]["window"] == "hann"
    scale = dsst["scale"]
    assert scale["name"] == "dsst" and scale["n_scales"] == 33 and scale["step"] == 1.02
    assert scale["sigma_factor"] == 0.25 and scale["learning_rate"] == 0.025 and scale["lam"] == 0.01
    assert scale["model_max_area"] == 512


# ------------------------------------------------------------------------- the trackers


def zoom_scene(n=40, size=(240, 320), target=(30, 40), zoom=1.01, seed=0):
    """A camera zooming in by ``zoom`` a frame (and panning 1 px a frame) over textured ground
    with a textured box on it: the target grows by zoom^k. Returns frames and (x, y, w, h) boxes."""
    rng = np.random.default_rng(seed)
    H, W = size
    world = cv2.resize(rng.random((H // 8, W // 8)).astype(np.float32), (W, H), interpolation=cv2.INTER_CUBIC)
    world = world + 0.5 * cv2.resize(rng.random((H // 2, W // 2)).astype(np.float32), (W, H))
    box = cv2.resize(rng.random((target[0] // 3, target[1] // 3)).astype(np.float32), target[::-1],
                     interpolation=cv2.INTER_NEAREST)
    cy, cx = H / 2, W / 2
    world[int(cy - target[0] / 2):int(cy + target[0] / 2), int(cx - target[1] / 2):int(cx + target[1] / 2)] = 2 * box
    world = np.clip(world * 100, 0, 255).astype(np.uint8)
    frames, boxes = [], []
    for k in range(n):
        s, shift = zoom**k, np.array([0.5 * k, 1.0 * k])  # the target's centre moves by shift (y, x)
        M = np.float32([[s, 0, cx + shift[1] - s * cx], [0, s, cy + shift[0] - s * cy]])
        frames.append(cv2.cvtColor(cv2.warpAffine(world, M, (W, H), flags=cv2.INTER_LINEAR), cv2.COLOR_GRAY2BGR))
        h, w = target[0] * s, target[1] * s
        boxes.append((cx + shift[1] - (w - 1) / 2, cy + shift[0] - (h - 1) / 2, w, h))
    return frames, np.array(boxes)


def track(config, frames, box):
    tracker = dcfkit.load_tracker(config)
    tracker.init(frames[0], box)
    return np.array([box] + [tracker.update(f) for f in frames[1:]], float)


def test_kcf_keeps_the_box_size_and_dsst_follows_a_zoom():
    frames, truth = zoom_scene()
    assert truth[-1, 2] / truth[0, 2] > 1.45  # the target grows by half
    centre = lambda b: b[:, :2] + (b[:, 2:] - 1) / 2  # noqa: E731
    kcf, dsst = track("kcf", frames, truth[0]), track("dsst", frames, truth[0])
    assert np.all(kcf[:, 2:] == truth[0, 2:])  # no scale estimation: KCF's box keeps its size
    assert np.hypot(*(centre(kcf) - centre(truth)).T).max() < 10  # and still follows the centre
    ratio = dsst[:, 2] / truth[:, 2]
    assert np.all(np.abs(ratio[-10:] - 1) < 0.1), ratio.round(3)  # DSST's box grows with the target
    assert np.isclose(dsst[-1, 2] / dsst[-1, 3], truth[0, 2] / truth[0, 3])  # one scale for both sides
    assert np.hypot(*(centre(dsst) - centre(truth)).T).max() < 6

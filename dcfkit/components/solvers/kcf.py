"""KCF's solver: kernelized ridge regression over all cyclic shifts of the sample (Henriques
et al., "High-Speed Tracking with Kernelized Correlation Filters", TPAMI 2015).

The regression f(z) = Σ_τ α_τ κ(z, P^τ x) over the cyclic shifts P^τ x of the sample x has
the dual solution α = (K + λI)⁻¹ y, K_στ = κ(P^σ x, P^τ x). For a kernel that depends on
the shift only through ⟨P^σ x, P^τ x⟩ and the norms (linear, polynomial, Gaussian) K is
circulant, diagonalised by the DFT, with eigenvalues k̂^{xx}:

* training (KCF Eq. 17): α̂ = ŷ / (k̂^{xx} + λ);
* detection (KCF Eq. 22): R = F⁻¹(k̂^{xz} ⊙ α̂), the regression at every shift of z;
* kernel correlation k^{xz}(τ) = κ(P^τ z, x), through c(τ) = Σ_p x(p) z(p+τ) =
  F⁻¹(Σ_c conj(x̂_c) ⊙ ẑ_c) (dcfkit's correlation, :mod:`dcfkit.numerics.response`):
  Gaussian (Eq. 31, its channels summed as in KCF's multi-channel extension)
  exp(-max(0, ‖x‖² + ‖z‖² - 2c) / (σ² N)), linear c / N, polynomial (c / N + a)^b, with
  N = C·H·W the sample's size (the authors' ``numel(xf)``).

The model is KCF's: x̂ and α̂ each interpolated linearly with the learning rate (the
authors' ``interp_factor``), the first frame taken whole. There is no spatial or temporal
term: the solver declares none (``terms``), and the tracker refuses a config that names one.

Spectra are half spectra (rfft2) of real maps, (C, H, W//2+1) complex64. The kernel maps
k (H, W) are real and computed in float64 from them: a few H·W maps a frame, cheap next to
the C-channel spectra, and the Gaussian's ‖x‖² + ‖z‖² - 2c, which cancels near the peak,
then loses nothing to rounding.
"""
from __future__ import annotations

import dataclasses

import numpy as np

from dcfkit.components.base import running_average
from dcfkit.components.solvers.base import Solver
from dcfkit.params import param

KERNELS = ("gaussian", "linear", "polynomial")


def parseval_weights(width: int) -> np.ndarray:
    """(W//2+1,) float64: how many times each column of a width-``width`` half spectrum stands in
    the full one. Column 0 is its own mirror, as is column W/2 for an even W; the others stand
    for themselves and their conjugate mirror (Hermitian symmetry of a real map's spectrum)."""
    weights = np.full(width // 2 + 1, 2.0)
    weights[0] = 1.0
    if width % 2 == 0:
        weights[-1] = 1.0
    return weights


def squared_norm(xf: np.ndarray, shape: tuple[int, int]) -> np.ndarray:
    """‖x‖² = Σ_c Σ_p x_c(p)² of real (..., C, H, W) maps from their (..., C, H, W//2+1) half
    spectra, by Parseval (1/(H·W) of the full spectrum's energy) -> (...,) float64, exact."""
    xf = np.ascontiguousarray(xf)
    parts = xf.view(xf.real.dtype)  # (..., C, H, 2 Wr): re, im interleaved
    # per column Σ_c Σ_h (re² + im²), accumulated in float64 without a float64 copy of the spectra
    columns = np.einsum("...chw,...chw->...w", parts, parts, dtype=np.float64)
    # weighted by numpy's own loops: a BLAS matmul sums in the order of its processor kernel
    return np.einsum("...w,w->...", columns, np.repeat(parseval_weights(shape[1]), 2)) / (shape[0] * shape[1])


def kernel_correlation(xf: np.ndarray, zf: np.ndarray, shape: tuple[int, int], p, fft) -> np.ndarray:
    """k^{xz}(τ) = κ(P^τ z, x) at every cyclic shift τ (KCF Eq. 31 for the Gaussian, summed
    over channels; its linear and polynomial kernels alike): model xf (C, H, Wr), samples zf
    (..., C, H, Wr) -> (..., H, W) float64, the circular layout of the response (τ = 0 at
    index (0, 0)).

    ``p``: :class:`KernelParams` (``kernel``, ``sigma``, ``poly_a``, ``poly_b``); ``fft``: the
    tracker's backend (:mod:`dcfkit.numerics.fft`). N = C·H·W.
    """
    n = xf.shape[0] * shape[0] * shape[1]
    # c(τ) = Σ_c Σ_p x_c(p) z_c(p+τ): summed over channels in the Fourier domain, one inverse FFT
    cross = fft.irfft2(np.einsum("chw,...chw->...hw", xf.conj(), zf, dtype=np.complex128), shape)
    if p.kernel == "linear":
        return cross / n
    if p.kernel == "polynomial":
        return (cross / n + p.poly_a) ** p.poly_b
    xx = squared_norm(xf, shape)
    zz = squared_norm(zf, shape)[..., None, None]
    # ‖x - P^τ z‖² = ‖x‖² + ‖z‖² - 2c(τ) >= 0; the max drops what rounding takes below 0
    distance = np.maximum(xx + zz - 2 * cross, 0.0)
    return np.exp(-distance / (p.sigma**2 * n))


@dataclasses.dataclass(frozen=True)
class KernelParams:
    kernel: str = param("gaussian", "κ: 'gaussian' exp(-‖x - x'‖² / (σ² N)) (KCF), 'linear' ⟨x, x'⟩ / N "
                        "(KCF's DCF), 'polynomial' (⟨x, x'⟩ / N + a)^b; N = the sample's C·H·W values",
                        choices=KERNELS)
    # σ² N divides the distance; beyond these bounds the kernel is 0 or 1 everywhere
    sigma: float = param(0.5, "σ of the Gaussian kernel", ge=1e-6, le=1e6)
    # a < 0 is not positive semi-definite: k̂^{xx} + λ may reach 0; (1 + 100)^20 stays well inside float64
    poly_a: float = param(1.0, "a of the polynomial kernel", ge=0, le=100)
    poly_b: int = param(9, "b, the polynomial kernel's degree", ge=1, le=20)
    # α̂ divides by k̂^{xx} + λ, which may be λ alone
    lam: float = param(1e-4, "λ: ridge regularization, α̂ = ŷ / (k̂^{xx} + λ)", ge=1e-10, le=1e10)
    learning_rate: float = param(0.02, "η: weight of the new frame in the model x̂ and in α̂ (KCF's interp_factor)",
                                 gt=0, le=1)


class KernelRidge(Solver):
    """KCF: kernel ridge regression over the cyclic shifts, α̂ = ŷ / (k̂^{xx} + λ) (KCF Eq. 17),
    detection F⁻¹(k̂^{xz} ⊙ α̂) (Eq. 22); x̂ and α̂ interpolated with η. ``train`` returns the
    model x̂ (C, H, Wr), which ``response`` correlates the samples with; α̂ stays here."""

    name = "kernel_ridge"
    Params = KernelParams
    terms = ()

    def reset(self):
        self.model = None   # x̂, (C, H, Wr) complex64
        self.alphaf = None  # α̂, (H, Wr) complex128

    def train(self, xf, yf, w2, theta, fft):
        shape = w2.shape
        kf = fft.rfft2(kernel_correlation(xf, xf, shape, self.params, fft))
        # k^{xx} is real and even, so k̂^{xx} is real: the eigenvalues of the kernel matrix, >= 0 for
        # these kernels (positive semi-definite); the imaginary part and anything below 0 are rounding
        alphaf = yf / (np.maximum(kf.real, 0.0) + self.params.lam)
        eta = self.params.learning_rate
        self.model = running_average(self.model, xf, eta, np.complex64)
        self.alphaf = running_average(self.alphaf, alphaf, eta)
        return self.model

    def response(self, hf, samples, shape, fft):
        """KCF Eq. (22): model ``hf`` = x̂ (C, H, Wr) and (S, C, H, Wr) samples ẑ ->
        F⁻¹(k̂^{xz} ⊙ α̂), (S, H, W) float32."""
        kzf = fft.rfft2(kernel_correlation(hf, samples, shape, self.params, fft))
        return fft.irfft2(kzf * self.alphaf, shape).astype(np.float32)

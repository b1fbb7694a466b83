"""fDSST's scale filter (Danelljan et al., TPAMI 2017, Sec. 4), as ECO uses it: S scales
sampled, each described by fHOG, compressed to S dimensions by an orthonormal basis of the
sample model (QR), the 1-D response's spectrum padded to S' > S scales (interpolation) and
the peak refined by a parabola through three of them (ECO's scale_filter/*.m)."""
from __future__ import annotations

import dataclasses

import numpy as np

from dcfkit.components.base import running_average
from dcfkit.components.features.fhog import ARITHMETICS, fhog
from dcfkit.components.scale.base import MAX_SCALES, MIN_LAM, ScaleEstimator, check_span
from dcfkit.numerics.patches import resize_auto, whole_pixel_crop
from dcfkit.params import param


def resize_spectrum(xf: np.ndarray, n: int) -> np.ndarray:
    """A 1-D DFT of length m zero-padded (or cut) to ``n``, scaled by n / m, its low positive
    and negative frequencies kept (ECO's resizeDFT)."""
    m = len(xf)
    keep = min(m, n)
    out = np.zeros(n, dtype=complex)
    head, tail = (keep + 1) // 2, (keep - 1) // 2 - 1
    out[:head] = xf[:head] * (n / m)
    if tail >= 0:
        out[n - tail - 1:] = xf[m - tail - 1:] * (n / m)
    return out


def _times(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """a @ b summed by einsum in index order (a BLAS product's order depends on the processor and
    its threads)."""
    return np.einsum("ij,jk->ik", a, b)


class FDSST(ScaleEstimator):
    """fDSST's compressed, interpolated scale filter (ECO-HC's: 17 scales read at 33)."""

    name = "fdsst"

    @dataclasses.dataclass(frozen=True)
    class Params:
        n_scales: int = param(17, "scales sampled (S)", ge=3, le=MAX_SCALES)
        n_interp: int = param(33, "scales the response is interpolated to (S')", ge=3, le=4 * MAX_SCALES)
        step: float = param(1.02, "ratio between neighbouring interpolated scales", gt=1)
        sigma_factor: float = param(1 / 16, "label σ = n_interp · sigma_factor (in interpolated scales)",
                                    gt=0, le=10)
        lam: float = param(0.01, "λ: regularization of the scale filter", ge=MIN_LAM, le=1e10)
        learning_rate: float = param(0.025, "interpolation rate of the scale model", gt=0, le=1)
        model_max_area: int = param(512, "largest area (pixels) of a scale sample", ge=1, le=10000)
        cell_size: int = param(4, "fHOG cell size of the scale samples", ge=1, le=16)
        poly_interp: bool = param(True, "refine the peak by a parabola through it and its neighbours")
        channel_order: str = param("bgr", "colour channel order deciding fHOG's ties (see fhog.channel_order)",
                                   choices=("bgr", "rgb"))
        fhog_arithmetic: str = param("exact", "fHOG's arithmetic (see fhog.arithmetic)", choices=ARITHMETICS)

        def validate(self):
            """step ** ((n_interp - 1) / 2) <= 10; n_interp >= n_scales."""
            if self.n_interp < self.n_scales:
                return "n_interp must be >= n_scales"
            return check_span(self.n_interp, self.step)

    def init(self, image, centre, base_target, scale, limits):
        super().init(image, centre, base_target, scale, limits)
        p = self.params
        n, ni = p.n_scales, p.n_interp
        exps = (np.arange(n) - (n - 1) // 2) * ni / n
        self.size_factors = p.step ** exps
        interp = np.roll(np.arange(ni) - (ni - 1) // 2, -((ni - 1) // 2))
        self.interp_factors = p.step ** interp
        sigma = ni * p.sigma_factor
        self.label_f = np.fft.fft(np.exp(-0.5 * np.roll(exps, -((n - 1) // 2)) ** 2 / sigma**2))
        self.window = np.hanning(n)
        target = np.round(self.base_target * scale, 9)  # the first frame's box in pixels
        area = float(np.prod(target))
        factor = np.sqrt(p.model_max_area / area) if area > p.model_max_area else 1.0
        # at least 8 px (the authors') and 2 cells, which fhog needs
        self.model_size = np.maximum(np.floor(target * factor), max(8, 2 * p.cell_size)).astype(int)
        self.num = self.den = self.model = None
        self._learn(image, centre, scale)

    def _samples(self, image, centre, scale) -> np.ndarray:
        """(D, S) fHOG of the S scale samples around ``centre`` (ECO's extract_scale_sample:
        the image taken every floor(min scale)-th pixel when that is over 1)."""
        scales = scale * self.size_factors
        step = int(np.floor(scales.min()))
        if step > 1:
            image, centre, scales = image[::step, ::step], np.asarray(centre) / step, scales / step
        patches = np.stack([resize_auto(whole_pixel_crop(image, centre, np.maximum(np.floor(self.base_target * s), 1)),
                                        self.model_size) for s in scales])
        feats = fhog(patches, cell_size=self.params.cell_size, batch=True, channel_order=self.params.channel_order,
                     arithmetic=self.params.fhog_arithmetic)
        return feats.reshape(len(patches), -1).T.astype(np.float64)

    def _learn(self, image, centre, scale) -> None:
        """ECO's scale_filter_update: the model's running average, its QR basis, numerator and
        denominator."""
        xs = self._samples(image, centre, scale)
        lr = self.params.learning_rate
        self.model = running_average(self.model, xs, lr)
        self.basis = np.linalg.qr(self.model)[0].T
        basis_den = np.linalg.qr(xs)[0].T
        self.num = self.label_f[None] * np.conj(np.fft.fft(self.window * _times(self.basis, self.model), axis=1))
        new_den = np.sum(np.abs(np.fft.fft(self.window * _times(basis_den, xs), axis=1)) ** 2, axis=0)
        self.den = new_den if self.den is None else (1 - lr) * self.den + lr * new_den

    def _change(self, image, centre, scale) -> float:
        """ECO's scale_filter_track: the relative scale change at ``centre``."""
        xsf = np.fft.fft(self.window * _times(self.basis, self._samples(image, centre, scale)), axis=1)
        response_f = np.sum(self.num * xsf, axis=0) / (self.den + self.params.lam)
        response = np.fft.ifft(resize_spectrum(response_f, self.params.n_interp)).real
        best = int(np.argmax(response))
        if not self.params.poly_interp:
            return float(self.interp_factors[best])
        ids = [(best - 1) % len(response), best, (best + 1) % len(response)]
        xs = self.interp_factors[ids]
        poly = np.linalg.solve(np.stack([xs**2, xs, np.ones(3)], axis=1), response[ids])
        with np.errstate(divide="ignore", invalid="ignore"):
            peak = -poly[1] / (2 * poly[0])
        # a flat or convex response (a uniform target) has no maximum: keep the grid's best
        if not (poly[0] < 0 and np.isfinite(peak)):
            return float(self.interp_factors[best])
        return float(peak)

    def update(self, image, centre, scale):
        new_scale = float(np.clip(scale * self._change(image, centre, scale), *self.limits))
        self._learn(image, centre, new_scale)
        return new_scale

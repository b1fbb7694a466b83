"""The DSST's scale filter (Danelljan et al., BMVC 2014), as DR²Track and STRCF use it."""
from __future__ import annotations

import dataclasses

import cv2
import numpy as np

from dcfkit.components.base import running_average
from dcfkit.components.features.fhog import ARITHMETICS, fhog
from dcfkit.components.scale.base import MAX_SCALES, MIN_LAM, ScaleEstimator, check_span, scale_factors
from dcfkit.numerics.imresize import imresize
from dcfkit.numerics.patches import resize_auto, sample, sampler, whole_pixel_crop
from dcfkit.params import param


class DSST(ScaleEstimator):
    """Discriminative scale filter: fHOG of S target-sized samples, a 1-D filter over scale."""

    name = "dsst"

    @dataclasses.dataclass(frozen=True)
    class Params:
        n_scales: int = param(33, "number of scales in the scale filter", ge=3, le=MAX_SCALES)
        step: float = param(1.03, "ratio between neighbouring scales", gt=1)
        # beyond 10, σ is over 1.7 n_scales: a flat label, every scale alike
        sigma_factor: float = param(0.25, "label width: σ = n_scales / √33 · sigma_factor", gt=0, le=10)
        # the scale filter divides by Σ|x̂|² + λ, which may be λ alone: λ bounds its gain, 1/λ. The floor
        # is the ADMM penalty's (solvers.PENALTY_RANGE), far below Σ|x̂|² of a textured sample (7 to 3000
        # on the synthetic sequence, where the default 0.01 is a thousandth of the least); subnormals
        # (1e-320) were accepted
        lam: float = param(0.01, "λ: regularization of the scale filter", ge=MIN_LAM, le=1e10)
        learning_rate: float = param(0.025, "interpolation rate of the scale model", gt=0, le=1)
        model_max_area: int = param(512, "largest area (pixels) of a scale sample", ge=1, le=10000)
        cell_size: int = param(4, "fHOG cell size of the scale samples", ge=1, le=16)
        model_size: str = param("base_target", "size of a scale sample: 'base_target' the target at the search "
                                "patch's resolution (at least 2x2 cells), 'image_target' its size in image pixels "
                                "(the authors' init_scale: floored; at least 2 cells, where theirs allows 2 px), "
                                "'square' CSR-DCF's square template (tracker.search_area_shape padded_square) "
                                "shrunk to at most model_max_area, floored: floor(√model_max_area) a side unless the "
                                "template is smaller (without a template, that side)", choices=("base_target", "image_target", "square"))
        sampling: str = param("working_patch", "'working_patch': the largest region cut once and each scale "
                              "resampled from it; 'whole_pixel': each scale cropped in whole pixels and resized "
                              "(the authors' get_scale_sample); 'whole_pixel_bilinear' the same around the pixel "
                              "nearest the centre, resized bilinearly (CSR-DCF's get_scale_subwindow, whose centre is "
                              "half a pixel from dcfkit's; MATLAB's imresize 'bilinear' without antialiasing)",
                              choices=("working_patch", "whole_pixel", "whole_pixel_bilinear"))
        bilinear: str = param("opencv", "the resize of 'whole_pixel_bilinear': 'opencv' cv2's bilinear (8-bit fixed "
                              "point), or 'matlab' imresize's (in double, rounded; the authors', slower)",
                              choices=("opencv", "matlab"))
        window: str = param("hann_interior", "window over the scales: 'hann_interior' hann(S+2) without its zero "
                            "ends, or 'hann' hann(S) (the authors')", choices=("hann_interior", "hann"))
        channel_order: str = param("bgr", "colour channel order deciding fHOG's ties (see fhog.channel_order)",
                                   choices=("bgr", "rgb"))
        fhog_arithmetic: str = param("exact", "fHOG's arithmetic (see fhog.arithmetic)", choices=ARITHMETICS)
        model_update: str = param("reextract", "samples the model learns from after a scale change: 'reextract' at "
                                  "the new scale, or 'shift' the search samples moved by the scale change, missing "
                                  "ones extracted (DR²Track's shift_sample_scale, which leaves those at the large "
                                  "end unwindowed)", choices=("reextract", "shift"))

        def validate(self):
            """step ** ((n_scales - 1) / 2) <= 10: the scales span at most x10 each way."""
            return check_span(self.n_scales, self.step)

    template = None  # CSR-DCF's template side (image pixels), from start()

    def start(self, target) -> None:
        self.template = target.template

    def init(self, image, centre, base_target, scale, limits):
        super().init(image, centre, base_target, scale, limits)
        p = self.params
        n = p.n_scales
        self.factors = scale_factors(n, p.step)
        offsets = np.arange(n) - (n - 1) // 2
        sigma = n / np.sqrt(33) * p.sigma_factor
        with np.errstate(over="ignore"):  # a σ so small that σ² underflows: a delta label, not NaN
            self.label_f = np.fft.fft(np.exp(-0.5 * offsets**2 / max(sigma**2, np.finfo(float).tiny)))
        self.window = np.hanning(n + 2)[1:-1] if p.window == "hann_interior" else np.hanning(n)
        authors = p.model_size == "image_target"  # init_scale: the target in image pixels, floored
        # the authors' target_sz is whole pixels; base_target * scale rebuilds it up to rounding
        # (10.999999999999998 for 11), which the floor below must not see
        target = np.round(self.base_target * scale, 9) if authors else self.base_target
        area = float(np.prod(target))
        shrink = np.sqrt(p.model_max_area / area) if area > p.model_max_area else 1.0
        # at least 2 cells, which fhog needs (init_scale allows 2 px: a side under 8 px differs)
        if p.model_size == "square":  # create_csr_tracker.m's scale_model_sz
            side = self.template if self.template is not None else np.sqrt(p.model_max_area)
            target, shrink = np.full(2, side), min(1.0, float(np.sqrt(p.model_max_area / side**2)))
        self.model_size = np.maximum((np.floor if authors or p.model_size == "square" else np.round)(target * shrink),
                                     2 * p.cell_size).astype(int)
        # the working patch and its resampling to each scale keep their geometry every frame
        span = self.factors[-1] / self.factors[0]
        self.work_size = np.ceil(self.model_size * span).astype(int)
        middle = (self.work_size - 1) / 2
        self.resamplers = [sampler(self.work_size, middle, self.work_size * (f / self.factors[-1]), self.model_size)
                           for f in self.factors]
        # CSR-DCF's get_scale_subwindow: floor(target_sz x their scale x factor), their scale 1 at first
        self.scale0, self.target0 = scale, np.round(self.base_target * scale, 9)
        self.num = self.den = None
        self._learn(np.fft.fft(self._samples(image, centre, scale), axis=1))

    def _samples(self, image, centre, scale, which=None, windowed=True) -> np.ndarray:
        """(D, S) windowed fHOG of the S scale samples around ``centre`` (``which``: only these
        scales, (D, len(which))).

        'working_patch': the largest region is cut from the image and resampled once to a
        small working patch (fine enough for the smallest scale); every scale sample is resized
        from it. 'whole_pixel': floor(target x scale) whole pixels per scale, resized."""
        which = range(len(self.factors)) if which is None else which
        if self.params.sampling != "working_patch":
            bilinear = self.params.sampling == "whole_pixel_bilinear"
            at = np.asarray(centre, float) + (0.5 if bilinear else 0.0)
            patches = np.stack([
                (self._bilinear(crop) if bilinear else resize_auto(crop, self.model_size))
                for crop in (whole_pixel_crop(image, at, np.maximum(np.floor(self._scaled(scale, f, bilinear)), 2))
                             for f in self.factors[list(which)])])
        else:
            work = sample(image, centre, self.base_target * scale * self.factors[-1], self.work_size)
            patches = np.stack([self.resamplers[i](work) for i in which])
        feats = fhog(patches, cell_size=self.params.cell_size, batch=True, channel_order=self.params.channel_order,
                     arithmetic=self.params.fhog_arithmetic)
        feats = feats.reshape(len(patches), -1).T
        return feats * self.window[None, list(which)] if windowed else feats

    def _bilinear(self, crop: np.ndarray) -> np.ndarray:
        """``crop`` resized bilinearly, without antialiasing, to the scale sample's size."""
        if self.params.bilinear == "matlab":
            return imresize(crop, self.model_size, bilinear=True)
        return cv2.resize(crop, (int(self.model_size[1]), int(self.model_size[0])), interpolation=cv2.INTER_LINEAR)

    def _scaled(self, scale: float, factor: float, csr: bool) -> np.ndarray:
        """The target at ``scale`` times ``factor``, in image pixels: CSR-DCF's target_sz times
        their scale factor (a product of the factors chosen) times ``factor`` (``csr``), else
        base_target x scale x factor."""
        if csr:
            return self.target0 * ((scale / self.scale0) * factor)
        return self.base_target * (scale * factor)

    def _learn(self, xsf: np.ndarray) -> None:
        """Update the scale model with the (D, S) spectrum of the scale samples."""
        num = self.label_f[None, :] * xsf.conj()
        den = np.einsum("ds,ds->s", xsf, xsf.conj()).real
        self.num = running_average(self.num, num, self.params.learning_rate)
        self.den = running_average(self.den, den, self.params.learning_rate)

    def update(self, image, centre, scale):
        xs = self._samples(image, centre, scale)
        xsf = np.fft.fft(xs, axis=1)
        resp = np.fft.ifft(np.einsum("ds,ds->s", self.num, xsf) / (self.den + self.params.lam)).real
        best = int(np.argmax(resp))
        new_scale = float(np.clip(scale * self.factors[best], *self.limits))
        if self.params.model_update == "shift":
            xsf = np.fft.fft(self._shifted(xs, best - (len(self.factors) - 1) // 2, image, centre, new_scale), axis=1)
        elif new_scale != scale:  # learn from samples at the new scale; unchanged: the same samples
            xsf = np.fft.fft(self._samples(image, centre, new_scale), axis=1)
        self._learn(xsf)
        return new_scale

    def _shifted(self, xs, step, image, centre, new_scale) -> np.ndarray:
        """DR²Track's shift_sample_scale: scale k of the new samples is scale k + ``step`` of the
        search samples ``xs`` (re-windowed), the ones beyond the ends are extracted at
        ``new_scale``; those at the large end (``step`` > 0) are left unwindowed, as theirs."""
        if step == 0:
            return xs
        n, win = len(self.factors), self.window
        out = np.zeros_like(xs)
        source = np.arange(n) + step
        kept = (source >= 0) & (source < n)
        out[:, kept] = xs[:, source[kept]] / (win[source[kept]] + 1e-5) * win[kept]
        fresh = np.flatnonzero(~kept)
        out[:, fresh] = self._samples(image, centre, new_scale, fresh, windowed=step < 0)
        return out

"""The tracker's own parameters: the ``tracker:`` mapping of a config."""
from __future__ import annotations

import dataclasses

from dcfkit.params import param


@dataclasses.dataclass(frozen=True)
class TrackerParams:
    """Geometry of the search area and of the label (STRCF's init_size)."""

    # upper bounds: far beyond any tracker's, where patches stop fitting in memory
    search_area_scale: float = param(5.0, "search area side / sqrt(target area) ('square') or per axis", ge=1, le=50)
    search_area_shape: str = param("square", "'square' (5√(WH) square), 'proportional' (5W x 5H), or "
                                   "'padded_square': CSR-DCF's template, a square whose side is the mean of "
                                   "floor(W + p√(WH)) and floor(H + p√(WH)), p = search_area_scale - 1, in whole cells "
                                   "of its rescaled floor", choices=("square", "proportional", "padded_square"))
    min_image_sample_size: float = param(150.0**2, "smallest area (px²) of the resampled search patch",
                                         ge=8**2, le=2000**2)
    max_image_sample_size: float = param(200.0**2, "largest area (px²) of the resampled search patch",
                                         ge=8**2, le=2000**2)
    cell_size: int = param(4, "feature cell size in pixels", ge=1, le=64)
    output_sigma_factor: float = param(1 / 16, "label σ as a fraction of sqrt(target area in cells)", gt=0)
    output_sigma: float = param(0.0, "label σ in cells, whatever the target's size (CSR-DCF's y_sigma); 0: from "
                                "output_sigma_factor", ge=0, le=1000)
    fft_backend: str = param("scipy", "FFT implementation", choices=("scipy", "pyfftw"))
    spectra: str = param("half", "'half' spectra of real maps, or 'full' complex spectra of the whole grid as "
                         "DR²Track's code (its shifted sample and ADMM filter are complex; resp_newton refines on "
                         "the complex response spectrum; scipy's FFT)", choices=("half", "full"))
    training_sample: str = param("extract", "'extract' m^t at p^t (Algorithm 1) or 'shift' the detection sample "
                                 "to p^t in the Fourier domain, as DR²Track's code (by the translation over the "
                                 "scale after the scale update; one extraction less)",
                                 choices=("extract", "shift"))
    init_position: str = param("exact", "'exact': the box's centre x + (w-1)/2; 'whole_pixel': the authors' BACF and "
                               "DR²Track, centre floor(x + floor(w/2)) and size floor(w) (1-based)",
                               choices=("exact", "whole_pixel"))
    init_area: str = param("floored", "the size frame 1's search area is computed from under init_position "
                           "'whole_pixel': 'floored', floor(w) as the authors' BACF, STRCF and AutoTrack; 'given', "
                           "the annotation's own size, as the authors' DR²Track (prod(wsize * search_area_scale) "
                           "before floor)", choices=("floored", "given"))
    sampling: str = param("subpixel", "'subpixel': the search region around the exact centre, area-averaged and "
                          "bilinearly mapped onto the sample grid; 'whole_pixel': the authors' get_pixels, whole "
                          "pixels around round(centre), then OpenCV's resize (bilinear when the width grows, else "
                          "area)", choices=("subpixel", "whole_pixel"))
    resize: str = param("auto", "how 'padded_square' whole-pixel samples are resized: 'auto' OpenCV's (bilinear when "
                        "the width grows, else area), 'matlab_bicubic' MATLAB's imresize (CSR-DCF's)",
                        choices=("auto", "matlab_bicubic"))
    window: str = param("hann_interior", "cosine window of the features: 'hann_interior' hann(n+2) without its zero "
                        "ends (DR²Track's code), 'hann' hann(n) with them (STRCF's and BACF's)",
                        choices=("hann_interior", "hann"))
    peak: str = param("bounded_newton", "sub-cell peak: 'bounded_newton' Newton steps kept within the grid maximum's "
                      "cell, the scale with the highest grid value; 'newton' the authors' resp_newton (unbounded "
                      "steps, the scale with the highest refined value); 'parabola' CSR-DCF's parabola through the "
                      "grid maximum's neighbours on each axis", choices=("bounded_newton", "newton", "parabola"))
    translation: str = param("exact", "'exact', or 'whole_pixel': the displacement rounded to whole image pixels "
                             "(BACF's and DR²Track's translation_vec), or 'exact_centre': with sampling 'whole_pixel', "
                             "the move added to the exact centre, not to the whole pixel the patch is cut around "
                             "(CSR-DCF's c + d)", choices=("exact", "whole_pixel", "exact_centre"))
    scale_limits: str = param("exact", "the smallest and largest scale: 'exact' the ratios themselves (the search "
                              "region keeps 5 cells, the target fits the image); 'step_powers' those rounded "
                              "inwards to whole powers of the scale estimator's step, as the authors' STRCF, BACF, "
                              "ARCF, AutoTrack and DR²Track", choices=("exact", "step_powers"))
    clamp_position: bool = param(True, "keep the target centre on the image (the authors' codes do not)")
    box_output: str = param("exact", "the reported box: 'exact' x = cx - (w-1)/2 with the exact size; "
                            "'rounded' the same rounded to whole 1-based pixels (STRCF's report_tracking_result); "
                            "'half_size' x = cx - w/2 with the size rounded (DR²Track's rect_position); "
                            "'floor_half' x = cx - floor(w/2) with the size floored (BACF's)",
                            choices=("exact", "rounded", "half_size", "floor_half"))
    box_scale: str = param("current", "the reported box's size: at the scale 'current', or 'previous' the scale before "
                           "this frame's scale update (CSR-DCF's region)", choices=("current", "previous"))
    newton_iterations: int = param(5, "Newton steps refining the response peak", ge=0, le=100)
    cell_selection_thresh: float = param(0.0, "BACF's small-target rule: if the search area holds fewer than this "
                                         "fraction of max_image_sample_size / cell_size² cells, use cells of "
                                         "ceil(sqrt(area / (fraction x that many))) pixels instead (0: off)",
                                         ge=0, le=1)
    cell_area: float = param(0.0, "CSR-DCF's small-target rule: cells of min(cell_size, max(1, ceil(w·h / cell_area))) "
                             "pixels for a w x h target (0: off)", ge=0, le=1e6)
    blank_std: float = param(1.0, "a frame whose pixel values vary less than this (standard deviation, RMS over "
                             "colour channels) is a dropped frame: the box is held, nothing is learnt (0: off); "
                             "the first frame's search area must vary at least this much", ge=0)

    def validate(self):
        """min_image_sample_size <= max_image_sample_size."""
        if self.min_image_sample_size > self.max_image_sample_size:
            return "need min_image_sample_size <= max_image_sample_size"

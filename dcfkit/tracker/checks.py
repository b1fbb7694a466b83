"""What the tracker checks of its input and configuration, before any state changes: the
image and the first box, that every configured term is used, and that a frame's samples stay
within the memory budgets of :mod:`dcfkit.limits` (docs/hardening.md)."""
from __future__ import annotations

import copy
from typing import Any

import cv2
import numpy as np

from dcfkit.components.scale.dsst import DSST
from dcfkit.components.solvers.base import Solver
from dcfkit.config.slots import SLOTS
from dcfkit.contracts import ContractViolation
from dcfkit.errors import ConfigError, InputError, TrackingError, shown
from dcfkit.limits import SAMPLE_PIXELS_VARIABLE, sample_budget
from dcfkit.numerics.patches import cropper, sampler
from dcfkit.tracker.geometry import Geometry

MAX_CHANNELS = 256  # feature channels in all: 6 times the shipped configs' 42 (gray, fhog, colornames)
MAX_BOX_TO_IMAGE = 10  # an initial box is at most this many times the image's width and height


def check_image(image: Any, frame: int) -> np.ndarray:
    """Reject anything but a non-empty (H, W) or (H, W, 3) uint8 array, naming the frame."""
    if not isinstance(image, np.ndarray):
        raise InputError(f"frame {frame}: expected a numpy image, got {type(image).__name__}")
    if image.dtype != np.uint8:
        raise InputError(f"frame {frame}: expected a uint8 image, got dtype {image.dtype}")
    if image.ndim == 3 and image.shape[2] == 1:
        image = image[:, :, 0]
    if not (image.ndim == 2 or (image.ndim == 3 and image.shape[2] == 3)):
        raise InputError(f"frame {frame}: expected an HxW or HxWx3 image, got shape {image.shape}")
    if image.shape[0] < 1 or image.shape[1] < 1:
        raise InputError(f"frame {frame}: the image is empty (shape {image.shape})")
    return image


def check_box(box: Any, image_shape: tuple[int, ...]) -> np.ndarray:
    """A finite (x, y, w, h) that overlaps the image, each side at least a pixel and at most
    ``MAX_BOX_TO_IMAGE`` times the image's."""
    try:
        raw = np.asarray(box)
        if raw.dtype.kind not in "iuf":  # not booleans, complex numbers, strings or objects
            raise TypeError
        b = raw.astype(float).reshape(-1)
    except (TypeError, ValueError):
        raise InputError(f"initial box must be 4 numbers (x, y, w, h), got {shown(box)}") from None
    if b.size != 4 or not np.all(np.isfinite(b)):
        raise InputError(f"initial box must be 4 finite numbers (x, y, w, h), got {shown(box)}")
    x, y, w, h = (float(v) for v in b)
    if w <= 0 or h <= 0:
        raise InputError(f"initial box {(x, y, w, h)} has non-positive size (w={w:g}, h={h:g})")
    if w < 1 or h < 1:  # nothing to track, and a size that underflows the geometry's areas
        raise InputError(f"initial box {(x, y, w, h)} is under a pixel wide or tall (w={w:g}, h={h:g}); "
                         f"boxes are in pixels, not fractions of the image")
    height, width = image_shape[:2]
    if w > MAX_BOX_TO_IMAGE * width or h > MAX_BOX_TO_IMAGE * height:
        raise InputError(f"initial box {(x, y, w, h)} is more than {MAX_BOX_TO_IMAGE} times as wide or as tall "
                         f"as the {width}x{height} image")
    if x + w <= 0 or y + h <= 0 or x >= width or y >= height:
        raise InputError(f"initial box {(x, y, w, h)} lies outside the {width}x{height} image")
    return b


def read_only(w2: np.ndarray) -> np.ndarray:
    """``w2``, which every component reads and none may change (a solver that wrote into it
    would be caught by the regularizer's check, and the regularizer blamed), made read-only."""
    w2 = np.array(w2, dtype=np.float32)  # a copy: the regularizer's own array stays writable for it
    w2.setflags(write=False)
    return w2


def check_terms(tracker) -> None:
    """ConfigError if a regularizer or a mask is configured that the solver has no term for
    (``Solver.terms``): it would be ignored; channel weights with a solver whose response is
    not the linear correlation (KCF's kernel), whose channels cannot be weighted; or a gate or
    re-detection without the reliability component they act on."""
    for slot in SLOTS:
        regularizer = getattr(tracker, slot.name) if slot.role is not None else None
        if regularizer is not None and slot.role not in tracker.solver.terms:
            raise ConfigError(f"{tracker.name}: solver '{tracker.solver.name}' has no {slot.role} term, so "
                              f"{slot.key} '{regularizer.name}' would be ignored: set {slot.key}: null")
    if tracker.mask is not None and "spatial" not in tracker.solver.terms:
        raise ConfigError(f"{tracker.name}: solver '{tracker.solver.name}' has no spatial term, so mask "
                          f"'{tracker.mask.name}' would be ignored: set mask: null")
    linear = type(tracker.solver).response is Solver.response
    if tracker.channel_weights is not None and not linear:
        raise ConfigError(f"{tracker.name}: channel_weights '{tracker.channel_weights.name}' weight the channels "
                          f"of a linear filter's response; solver '{tracker.solver.name}' has its own response: "
                          f"set channel_weights: null")
    gate = tracker.schedule if getattr(tracker.schedule, "needs_reliability", False) else None
    for key, needs in (("schedule", gate), ("redetect", tracker.redetect)):
        if needs is not None and tracker.reliability is None:
            raise ConfigError(f"{tracker.name}: {key} '{needs.name}' acts on the reliability of each detection, "
                              f"and the config has no reliability component: add one, e.g. reliability: "
                              f"{{name: lmcf}}")


def check_spectra(tracker) -> None:
    """ConfigError if ``tracker.spectra: full`` is given a solver that works on half spectra only."""
    if tracker.params.spectra == "full" and not tracker.solver.full_spectra:
        raise ConfigError(f"{tracker.name}: tracker.spectra 'full' (whole complex spectra, as DR²Track's code) "
                          f"needs a solver that takes them, such as admm_strcf; solver '{tracker.solver.name}' "
                          f"works on half spectra: set tracker.spectra: half")


def check_sampling(tracker) -> None:
    """ConfigError for keys only whole-pixel sampling reads: ``search_area_shape: padded_square``
    (CSR-DCF's template, cropped in whole pixels) and ``resize`` (how that template is resized)."""
    p = tracker.params
    if p.search_area_shape == "padded_square" and p.sampling != "whole_pixel":
        raise ConfigError(f"{tracker.name}: tracker.search_area_shape 'padded_square' (CSR-DCF's template) is "
                          f"cropped in whole pixels; tracker.sampling '{p.sampling}' would ignore the template: "
                          f"set tracker.sampling: whole_pixel")
    if p.resize != "auto" and not (p.sampling == "whole_pixel" and p.search_area_shape == "padded_square"):
        raise ConfigError(f"{tracker.name}: tracker.resize '{p.resize}' resizes the padded_square template's "
                          f"whole-pixel samples; with tracker.sampling '{p.sampling}' and search_area_shape "
                          f"'{p.search_area_shape}' it would be ignored: set tracker.resize: auto")


def search_scales(tracker) -> np.ndarray:
    """The relative scales of the search samples (one sample each per frame)."""
    try:
        return np.asarray(tracker.scale_estimator.search_factors(), dtype=float).reshape(-1)
    except ContractViolation as exc:
        if exc.__cause__ is None:  # what it returned, not an exception it raised: said
            raise
        return np.ones(1)  # an estimator that needs init first: budgeted as one scale, copies checked anyway
    except Exception:  # likewise, from an estimator no registry built
        return np.ones(1)


def check_config_budget(tracker) -> None:
    """ConfigError naming the keys whose samples would be over :func:`sample_budget` for any box
    (features hold channels x cells floats, so the channels count too)."""
    p, n = tracker.params, len(search_scales(tracker))
    pixels, cells = sample_budget()
    channels = sum(f.channels() for f in tracker.features)
    if channels > MAX_CHANNELS:
        raise ConfigError(f"{tracker.name}: the features have {channels} channels together, over the limit of "
                          f"{MAX_CHANNELS} (dcfkit.tracker.MAX_CHANNELS; the shipped configs have 42)")
    area = p.max_image_sample_size
    if n * area > pixels or n * area / p.cell_size**2 > cells:
        raise ConfigError(f"{tracker.name}: {n} search scales (scale.n_scales) of tracker.max_image_sample_size "
                          f"{area:g} px (tracker.cell_size {p.cell_size}) are {n * area:.3g} px and "
                          f"{n * area / p.cell_size**2:.3g} cells a frame, over the limit of {pixels:.3g} px and "
                          f"{cells:.3g} cells (${SAMPLE_PIXELS_VARIABLE})")
    if isinstance(tracker.scale_estimator, DSST):
        d = tracker.scale_estimator.params
        model = max(d.model_max_area, (2 * d.cell_size) ** 2)  # a sample has at least 2x2 cells
        work = model * (d.n_scales + d.step ** (2 * (d.n_scales - 1)))  # the samples and their working patch
        if work > pixels:
            raise ConfigError(f"{tracker.name}: scale.n_scales {d.n_scales} samples of scale.model_max_area "
                              f"{d.model_max_area} px, and their working patch (scale.step {d.step:g}), are "
                              f"{work:.3g} px a frame, over the limit of {pixels:.3g} (${SAMPLE_PIXELS_VARIABLE})")


def check_first_frame(tracker, shape, centre: np.ndarray, g: Geometry, scale: float, box: np.ndarray) -> None:
    """InputError naming the initial box if its samples would be over a budget: the search
    samples' pixels and cells (:func:`sample_budget`; an extreme aspect ratio can inflate
    them), or a region copied from the image at the largest search scale or by the DSST
    (``$DCFKIT_MAX_IMAGE_PIXELS``). Checked before any state changes."""
    what = f"frame 1: initial box {tuple(float(v) for v in box)}"
    factors = search_scales(tracker)
    pixels, cells = sample_budget()
    n, area, n_cells = len(factors), int(np.prod(g.sample_size)), int(np.prod(g.filter_size))
    if n * area > pixels or n * n_cells > cells:
        raise InputError(f"{what}: {n} search samples of {g.sample_size[1]}x{g.sample_size[0]} px "
                         f"({g.filter_size[1]}x{g.filter_size[0]} cells) a frame, over the limit of {pixels:.3g} px "
                         f"and {cells:.3g} cells (${SAMPLE_PIXELS_VARIABLE})")
    largest = float(factors.max(initial=1.0))
    try:
        tracker._sampler(shape, centre, scale * largest, g)  # the geometry only: nothing is copied
        if isinstance(tracker.scale_estimator, DSST):
            check_dsst_copies(tracker, shape, centre, g.base_target * scale)
    except InputError as exc:
        raise InputError(f"{what}: {exc}") from None


def check_dsst_copies(tracker, shape, centre: np.ndarray, target: np.ndarray) -> None:
    """The geometry of the DSST's largest copy at its first frame (an InputError if it would
    be over the image budget): its largest scale sample, cut whole ('whole_pixel'), or cut
    for the working patch, which is at least 2 cells times the span a side: the most a
    sampler can copy for it (the more it shrinks, the wider its blocks of edge pixels; one
    that shrinks less than 2 times copies the region itself, which is then under 4 working
    patches: within the DSST's sample budget)."""
    d = tracker.scale_estimator.params
    span = d.step ** (d.n_scales - 1)
    region = np.maximum(np.floor(target * span ** 0.5), 2)
    if d.sampling != "working_patch":  # whole pixels of each scale
        cropper(shape, centre, region)
    else:
        sampler(shape, centre, region, np.full(2, np.ceil(2 * d.cell_size * span)))


def check_blank_first(tracker, patch: np.ndarray, centre: np.ndarray, shape) -> None:
    """InputError if the first frame's search ``patch`` is blank (``tracker.blank_std``):
    there is nothing to learn. ``centre`` is the 0-based (y, x) box centre."""
    std = blank(tracker, patch)
    if std is None:
        return
    outside = not (0 <= centre[0] < shape[0] and 0 <= centre[1] < shape[1])
    raise InputError(f"frame 1: the search area around the initial box is blank (standard deviation "
                     f"{std:.2f} < tracker.blank_std {tracker.params.blank_std:g}); nothing to learn"
                     + (f" (the box centre (x={centre[1]:g}, y={centre[0]:g}) is outside the "
                        f"{shape[1]}x{shape[0]} image)" if outside else ""))


def first_due(tracker) -> None:
    """TrackingError if the schedule, reset for a new target, would skip frame 1, where the
    first filter must be learnt. A copy is asked: the schedule itself is untouched, so a
    refused init leaves the tracker as it was, and it is asked once per frame as before (a
    schedule that cannot be copied is only asked by the loop, after the state changed)."""
    if tracker.schedule is None:
        return
    try:
        probe = copy.deepcopy(tracker.schedule)
    except Exception:  # a plugin's state that cannot be copied: the loops still ask it, later
        return
    probe.reset()
    if not probe.due(1):
        raise TrackingError(f"frame 1: schedule '{tracker.schedule.name}' skips the first frame, where the filter "
                            f"must be learnt")


def blank(tracker, pixels: np.ndarray) -> float | None:
    """The standard deviation of the pixel values (RMS over colour channels) if it is below
    ``tracker.blank_std``, else None. Asked of every frame: most are told varied by a
    sixteenth of their rows (:func:`_surely_varied`), the same answer at a fraction of the
    cost (it was a quarter of KCF's frame on a 720p sequence)."""
    limit = tracker.params.blank_std
    if not limit > 0 or _surely_varied(pixels, limit):  # a standard deviation is never below 0
        return None
    std = _rms_std(pixels)
    return std if std < limit else None


def _rms_std(pixels: np.ndarray) -> float:
    """The population standard deviation of each channel, their RMS."""
    return float(np.sqrt(np.mean(np.square(cv2.meanStdDev(pixels)[1]))))


def _surely_varied(pixels: np.ndarray, limit: float) -> bool:
    """Whether every sixteenth row of ``pixels`` (k of their n pixels) varies so much that all
    of them vary by at least twice ``limit``: n var(all) >= k var(subset) in each channel (the
    subset's squared deviations from the mean of all are at least those from its own), so
    std(all) >= sqrt(k / n) std(subset); the factor 2 leaves the rounding of the sums far
    behind. Whole rows: a frame is read from memory by the cache line, and a sixteenth of the
    rows is a sixteenth of the lines."""
    subset = pixels[::16]
    return np.sqrt(len(subset) / len(pixels)) * _rms_std(subset) >= 2 * limit

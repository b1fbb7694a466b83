"""The DCF tracking loop: Algorithm 1 of DR²Track, with every step a configured component.

Frame 1 (``init``): extract the sample m¹ at the ground truth, train h¹ (θ = 0), V¹ = 0.
Frame t (``update``): centre the search area (Eq. 14), compute the response (Eq. 12) at each
search scale, take the peak as p^t, update the scale, extract m^t at p^t, build the label
(Eq. 3 for the repressed label), train h^t (Eqs. 9–11), and update the velocity (Eq. 13).
A blank frame (standard deviation of its pixel values below ``tracker.blank_std``: a dropped
or black video frame) is held: the box stays, nothing is learnt, and the frame number goes
to ``held_frames``. The whole frame is tested, not the search patch: a dark scene or a
featureless stretch of sky is tracked as any other frame.

Images are (H, W, 3) uint8 BGR or (H, W) uint8 gray; boxes are (x, y, w, h) floats,
0-based pixels. The tracker is deterministic.
"""
from __future__ import annotations

import dataclasses
from typing import Any, Mapping

import cv2
import numpy as np

from dcfkit.tracker.confidence import Confidence
from dcfkit.config import TrackerParams, load_config
from dcfkit.contracts import ContractViolation, naming_the_frame
from dcfkit.errors import ConfigError, InputError, TrackingError, shown
from dcfkit.components.features import extract_stack
from dcfkit.numerics.fft import make_fft
from dcfkit.components.labels import Detection, gaussian_label
from dcfkit.limits import SAMPLE_PIXELS_VARIABLE, sample_budget
from dcfkit.numerics.patches import box_to_centre_size, centre_size_to_box, cropper, round_half_away, sampler, whole_pixel_sampler
from dcfkit.registry import get_registry
from dcfkit.numerics.response import newton_peak, shift_spectrum, subpixel_peak
from dcfkit.components.scale import DSST, scale_limits

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


def _read_only(w2: np.ndarray) -> np.ndarray:
    """``w2``, which every component reads and none may change (a solver that wrote into it
    would be caught by the regularizer's check, and the regularizer blamed), made read-only."""
    w2 = np.array(w2, dtype=np.float32)  # a copy: the regularizer's own array stays writable for it
    w2.setflags(write=False)
    return w2


def hann2d(shape: tuple[int, int], interior: bool = True) -> np.ndarray:
    """Cosine window, (H, W) float32: without zero borders (hann(n + 2) trimmed: BACF, DR²Track)
    or, with ``interior=False``, hann(n) itself, zero on the border (STRCF)."""
    pad = 2 if interior else 0
    ends = slice(1, -1) if interior else slice(None)
    return np.outer(np.hanning(shape[0] + pad)[ends], np.hanning(shape[1] + pad)[ends]).astype(np.float32)


@dataclasses.dataclass
class Geometry:
    """Sizes fixed at init, in pixels at scale 1 unless stated (see STRCF's init_size)."""

    base_target: np.ndarray      # (h, w) target
    sample_size: np.ndarray      # (h, w) resampled search patch, a multiple of the cell size
    filter_size: tuple[int, int]  # (H, W) in cells
    target_cells: tuple[float, float]
    cell_size: int               # pixels per cell (tracker.cell_size, or smaller for a small target)


class Tracker:
    """A DCF tracker assembled from components (see :func:`dcfkit.load_tracker`)."""

    def __init__(self, config: Mapping[str, Any]):
        registry = get_registry()
        self.config = dict(config)
        self.name = config["name"]
        self.params = TrackerParams(**config["tracker"])
        build = lambda kind, spec, where: registry.build(kind, spec, f"{self.name}: {where}")  # noqa: E731
        self.features = [build("feature", f, f"features[{i}]") for i, f in enumerate(config["features"])]
        self.label = build("label", config["label"], "label")
        regs = config["regularizers"]
        self.spatial = build("regularizer", regs["spatial"], "regularizers.spatial") if regs.get("spatial") else None
        self.temporal = build("regularizer", regs["temporal"], "regularizers.temporal") if regs.get("temporal") else None
        self.solver = build("solver", config["solver"], "solver")
        self._check_terms()
        self.search = build("search", config["search"], "search")
        self.scale_estimator = build("scale", config["scale"], "scale")
        self.fft = make_fft(self.params.fft_backend)
        self.frame = 0
        # diagnostics of the last frame: the response map (cells, centred: fftshift), the image box
        # (x, y, w, h) it covers, and the repressed distractors as (x, y) image pixels; the
        # confidence read from the map is the property last_confidence
        self.last_response: np.ndarray | None = None
        self.last_search_box: tuple[float, float, float, float] | None = None
        self.last_distractors = np.zeros((0, 2))
        self.held_frames: list[int] = []  # 1-based numbers of frames held as blank
        self._check_config_budget()

    def _check_terms(self) -> None:
        """ConfigError if a regularizer is configured that the solver has no term for (``Solver.terms``):
        it would be ignored."""
        for role, regularizer in (("spatial", self.spatial), ("temporal", self.temporal)):
            if regularizer is not None and role not in self.solver.terms:
                raise ConfigError(f"{self.name}: solver '{self.solver.name}' has no {role} term, so "
                                  f"regularizers.{role} '{regularizer.name}' would be ignored: "
                                  f"set regularizers.{role}: null")

    # -- budgets: memory and time per frame stay bounded (docs/architecture.md) -------------
    def _search_scales(self) -> np.ndarray:
        """The relative scales of the search samples (one sample each per frame)."""
        try:
            return np.asarray(self.scale_estimator.search_factors(), dtype=float).reshape(-1)
        except ContractViolation as exc:
            if exc.__cause__ is None:  # what it returned, not an exception it raised: said
                raise
            return np.ones(1)  # an estimator that needs init first: budgeted as one scale, copies checked anyway
        except Exception:  # likewise, from an estimator no registry built
            return np.ones(1)

    def _check_config_budget(self) -> None:
        """ConfigError naming the keys whose samples would be over :func:`sample_budget` for any box
        (features hold channels x cells floats, so the channels count too)."""
        p, n = self.params, len(self._search_scales())
        pixels, cells = sample_budget()
        channels = sum(f.channels() for f in self.features)
        if channels > MAX_CHANNELS:
            raise ConfigError(f"{self.name}: the features have {channels} channels together, over the limit of "
                              f"{MAX_CHANNELS} (dcfkit.tracker.tracker.MAX_CHANNELS; the shipped configs have 42)")
        area = p.max_image_sample_size
        if n * area > pixels or n * area / p.cell_size**2 > cells:
            raise ConfigError(f"{self.name}: {n} search scales (scale.n_scales) of tracker.max_image_sample_size "
                              f"{area:g} px (tracker.cell_size {p.cell_size}) are {n * area:.3g} px and "
                              f"{n * area / p.cell_size**2:.3g} cells a frame, over the limit of {pixels:.3g} px and "
                              f"{cells:.3g} cells (${SAMPLE_PIXELS_VARIABLE})")
        if isinstance(self.scale_estimator, DSST):
            d = self.scale_estimator.params
            model = max(d.model_max_area, (2 * d.cell_size) ** 2)  # a sample has at least 2x2 cells
            work = model * (d.n_scales + d.step ** (2 * (d.n_scales - 1)))  # the samples and their working patch
            if work > pixels:
                raise ConfigError(f"{self.name}: scale.n_scales {d.n_scales} samples of scale.model_max_area "
                                  f"{d.model_max_area} px, and their working patch (scale.step {d.step:g}), are "
                                  f"{work:.3g} px a frame, over the limit of {pixels:.3g} (${SAMPLE_PIXELS_VARIABLE})")

    # -- geometry ---------------------------------------------------------------------------
    def _geometry(self, target: np.ndarray) -> tuple[Geometry, float]:
        """STRCF's init_size, in its arithmetic (a floor of a size decides a sample's pixels), with
        BACF's smaller cells for a target whose search area has too few of them."""
        p = self.params
        cell, low, high = p.cell_size, p.min_image_sample_size, p.max_image_sample_size
        area = float(np.prod(target * p.search_area_scale))
        if p.cell_selection_thresh > 0 and area / cell**2 < p.cell_selection_thresh * high / cell**2:
            smaller = min(cell, max(1, int(np.ceil(np.sqrt(area / (p.cell_selection_thresh * high / cell**2))))))
            low, high = low * (smaller / cell) ** 2, high * (smaller / cell) ** 2  # the same areas in cells
            cell = smaller
        scale = 1.0
        if area > high:
            scale = np.sqrt(area / high)
        elif area < low:
            scale = np.sqrt(area / low)
        base_target = target / scale
        region = (np.full(2, np.sqrt(np.prod(base_target * p.search_area_scale))) if p.search_area_shape == "square"
                  else np.floor(base_target * p.search_area_scale))
        cells = np.maximum(round_half_away(region / cell), 4).astype(int)
        target_cells = tuple(float(v) for v in base_target / cell)
        geom = Geometry(base_target, cells * cell, (int(cells[0]), int(cells[1])), target_cells, cell)
        return geom, float(scale)

    def _patch(self, image: np.ndarray, centre: np.ndarray, scale: float, g: Geometry | None = None) -> np.ndarray:
        """The search patch at ``centre``, resampled to the sample size (``tracker.sampling``)."""
        try:
            cut = self._sampler(image.shape, centre, scale, g)
        except InputError as exc:  # a copy over the image budget: the target has grown beyond it
            raise InputError(f"frame {self.frame}: the search region at scale {scale:g}: {exc}") from None
        return cut(image)

    def _sampler(self, shape, centre: np.ndarray, scale: float, g: Geometry | None = None):
        """:meth:`_patch`'s geometry, built without touching an image (an InputError if its copy
        would be over the image budget)."""
        g = g or self.geometry
        if self.params.sampling == "whole_pixel":
            return whole_pixel_sampler(shape, round_half_away(centre), g.sample_size * scale, g.sample_size)
        return sampler(shape, centre, g.sample_size * scale, g.sample_size)

    def _spectrum(self, patch: np.ndarray) -> np.ndarray:
        """(C, H, Wr) complex64 spectrum of the windowed features of a search patch."""
        x = extract_stack(self.features, patch, self.geometry.cell_size)
        return self.fft.rfft2(x * self.window).astype(np.complex64, copy=False)

    def _sample(self, image: np.ndarray, centre: np.ndarray, scale: float) -> np.ndarray:
        return self._spectrum(self._patch(image, centre, scale))

    def _blank(self, pixels: np.ndarray) -> float | None:
        """The standard deviation of the pixel values (RMS over colour channels) if it is below
        ``blank_std``, else None."""
        std = float(np.sqrt(np.mean(np.square(cv2.meanStdDev(pixels)[1]))))
        return std if std < self.params.blank_std else None

    # -- Algorithm 1 ------------------------------------------------------------------------
    @naming_the_frame(lambda tracker: 1)
    def init(self, image: np.ndarray, box) -> None:
        """Frame 1: learn the first filter at ``box`` (x, y, w, h)."""
        image = check_image(image, 1)
        box = check_box(box, image.shape)
        centre, target = box_to_centre_size(box)
        if self.params.init_position == "whole_pixel":  # 1-based floor([y x] + floor([h w] / 2))
            target = np.floor(target)
            centre = np.floor(box[[1, 0]] + np.floor(target / 2))
        g, scale = self._geometry(target)
        limits = scale_limits(g.base_target, g.sample_size, image.shape, initial=scale)
        scale = float(np.clip(scale, *limits))
        self._check_first_frame(image.shape, centre, g, scale, box)
        patch = self._patch(image, centre, scale, g)
        std = self._blank(patch)
        if std is not None:  # checked before any state changes: a failed init leaves the tracker as it was
            outside = not (0 <= centre[0] < image.shape[0] and 0 <= centre[1] < image.shape[1])
            raise InputError(f"frame 1: the search area around the initial box is blank (standard deviation "
                             f"{std:.2f} < tracker.blank_std {self.params.blank_std:g}); nothing to learn"
                             + (f" (the box centre (x={centre[1]:g}, y={centre[0]:g}) is outside the "
                                f"{image.shape[1]}x{image.shape[0]} image)" if outside else ""))
        self.frame = 1
        self.image_size = image.shape[:2]
        self.geometry, self.scale, self.limits = g, scale, limits
        self.window = hann2d(g.filter_size, interior=self.params.window == "hann_interior")
        sigma = np.sqrt(np.prod(np.floor(np.asarray(g.target_cells)).clip(1))) * self.params.output_sigma_factor
        self.base_label = gaussian_label(g.filter_size, sigma)
        self.base_label.setflags(write=False)  # every frame's label starts from it
        regularizers = [r for r in (self.spatial, self.temporal) if r is not None]
        for component in (*self.features, self.label, self.solver, *regularizers):  # a new target: nothing kept
            component.reset()
        self.w2 = _read_only(self.spatial.weights_squared(g.filter_size, g.target_cells) if self.spatial is not None
                             else np.zeros(g.filter_size, np.float32))
        self.search.reset(centre)
        self.scale_estimator.init(image, centre, g.base_target, self.scale, self.limits)
        self.position = centre
        self.last_response, self.last_search_box = None, None
        self.last_distractors = np.zeros((0, 2))
        self.held_frames = []
        self._train(image, None, self._spectrum(patch))  # m^1: the patch checked above

    def _check_first_frame(self, shape, centre: np.ndarray, g: Geometry, scale: float, box: np.ndarray) -> None:
        """InputError naming the initial box if its samples would be over a budget: the search
        samples' pixels and cells (:func:`sample_budget`; an extreme aspect ratio can inflate
        them), or a region copied from the image at the largest search scale or by the DSST
        (``$DCFKIT_MAX_IMAGE_PIXELS``). Checked before any state changes."""
        what = f"frame 1: initial box {tuple(float(v) for v in box)}"
        factors = self._search_scales()
        pixels, cells = sample_budget()
        n, area, n_cells = len(factors), int(np.prod(g.sample_size)), int(np.prod(g.filter_size))
        if n * area > pixels or n * n_cells > cells:
            raise InputError(f"{what}: {n} search samples of {g.sample_size[1]}x{g.sample_size[0]} px "
                             f"({g.filter_size[1]}x{g.filter_size[0]} cells) a frame, over the limit of {pixels:.3g} px "
                             f"and {cells:.3g} cells (${SAMPLE_PIXELS_VARIABLE})")
        largest = float(factors.max(initial=1.0))
        try:
            self._sampler(shape, centre, scale * largest, g)  # the geometry only: nothing is copied
            if isinstance(self.scale_estimator, DSST):
                self._check_dsst_copies(shape, centre, g.base_target * scale)
        except InputError as exc:
            raise InputError(f"{what}: {exc}") from None

    def _check_dsst_copies(self, shape, centre: np.ndarray, target: np.ndarray) -> None:
        """The geometry of the DSST's largest copy at its first frame (an InputError if it would
        be over the image budget): its largest scale sample, cut whole ('whole_pixel'), or cut
        for the working patch, which is at least 2 cells times the span a side: the most a
        sampler can copy for it (the more it shrinks, the wider its blocks of edge pixels; one
        that shrinks less than 2 times copies the region itself, which is then under 4 working
        patches: within the DSST's sample budget)."""
        d = self.scale_estimator.params
        span = d.step ** (d.n_scales - 1)
        region = np.maximum(np.floor(target * span ** 0.5), 2)
        if d.sampling == "whole_pixel":
            cropper(shape, centre, region)
        else:
            sampler(shape, centre, region, np.full(2, np.ceil(2 * d.cell_size * span)))

    @naming_the_frame(lambda tracker: tracker.frame)
    def update(self, image: np.ndarray) -> tuple[float, float, float, float]:
        """Frame t > 1: locate the target, return its box (x, y, w, h), and learn from it."""
        if self.frame == 0:
            raise TrackingError("update() called before init()")
        self.frame += 1  # every frame given counts, rejected ones too: numbers match the caller's video
        image = check_image(image, self.frame)
        if image.shape[:2] != self.image_size:
            raise InputError(f"frame {self.frame}: the image is {image.shape[1]}x{image.shape[0]}, but the "
                             f"sequence's first frame was {self.image_size[1]}x{self.image_size[0]}")
        g, p = self.geometry, self.params
        centre = self._clamp(np.array(self.search.centre(), dtype=float), image.shape)  # Eq. (14); a copy
        if p.sampling == "whole_pixel":  # the patch is centred on a whole pixel, and so are displacements
            centre = round_half_away(centre)
        factors = np.array(self.scale_estimator.search_factors(), dtype=float)  # copies: a plugin may change its own
        if self._blank(image[::4, ::4]) is not None:  # a dropped frame: hold, learn nothing
            self.last_response, self.last_search_box, self.last_distractors = None, None, np.zeros((0, 2))
            self.held_frames.append(self.frame)
            return self.box
        patches = [self._patch(image, centre, self.scale * f) for f in factors]
        samples = np.stack([self._spectrum(patch) for patch in patches])
        maps = self._response(samples)  # Eq. (12)
        if not np.all(np.isfinite(maps)):
            raise TrackingError(f"frame {self.frame}: the response map is not finite (the filter overflowed: "
                                f"look for extreme solver, regularizer or label values in the config)")
        best, dy, dx = self._peak(maps)
        step = g.cell_size * self.scale * factors[best]  # pixels per cell
        move = np.array([dy, dx]) * g.cell_size * self.scale * factors[best]  # not * step: the authors' rounding
        if p.translation == "whole_pixel":
            move = round_half_away(move)
        self.position = self._clamp(centre + move, image.shape)
        self.scale = float(self.scale_estimator.update(image, self.position, self.scale * factors[best]))
        self.search.observe(self.position)  # Eq. (13)
        peak = np.unravel_index(int(np.argmax(maps[best])), g.filter_size)
        self.last_response = np.fft.fftshift(maps[best])
        self.last_search_box = centre_size_to_box(centre, g.sample_size * step / g.cell_size)
        xf = None
        if p.training_sample == "shift":  # the detection sample, moved to p^t in cells of the new scale
            sy, sx = (self.position - centre) / (g.cell_size * self.scale)
            xf = shift_spectrum(samples[best], sy, sx, g.filter_size)
        detection = Detection(maps[best], (int(peak[0]), int(peak[1])), g.target_cells, (dy, dx))
        self._observe(detection)
        self._train(image, detection, xf)
        return self.box

    def _response(self, samples: np.ndarray) -> np.ndarray:
        """The solver's (S, H, W) response maps of the (S, C, H, Wr) search samples."""
        return self.solver.response(self.hf, samples, self.geometry.filter_size, self.fft)

    def _observe(self, detection: Detection) -> None:
        """Give the detection to the components that adapt to it: the solver, and the spatial
        regularizer, whose w² it returns is used from this frame on."""
        self.solver.observe(detection)
        if self.spatial is not None:
            self.w2 = _read_only(self.spatial.adapt(self.w2, detection))

    def _theta(self, detection: Detection | None) -> float:
        """θ of this frame's training (0 without a temporal term; ``inf``: keep the last filter)."""
        return 0.0 if self.temporal is None else float(self.temporal.weight(detection))

    def _peak(self, maps: np.ndarray) -> tuple[int, float, float]:
        """The search scale whose response is best and its peak as a (dy, dx) offset in cells."""
        if self.params.peak == "newton":
            best, dy, dx, _ = newton_peak(maps, self.params.newton_iterations)
            return best, dy, dx
        best = int(np.argmax(maps.reshape(len(maps), -1).max(axis=1)))
        dy, dx, _ = subpixel_peak(maps[best], self.params.newton_iterations)
        return best, dy, dx

    def _train(self, image: np.ndarray, detection: Detection | None, xf: np.ndarray | None = None) -> None:
        if xf is None:
            xf = self._sample(image, self.position, self.scale)  # m^t at p^t
        y, offsets = self._label(detection)  # Eq. (3)
        yf = self.fft.rfft2(y).astype(np.complex64, copy=False)
        theta = self._theta(detection)
        if theta == np.inf and detection is None:
            raise TrackingError(f"frame {self.frame}: temporal regularizer '{self.temporal.name}' returned θ = inf "
                                f"on the first frame, where there is no filter to keep")
        if theta != np.inf:  # inf: the temporal term holds the filter where it is
            self.hf = self.solver.train(xf, yf, self.w2, theta, self.fft)  # Eqs. (9)-(11)
        step = self.geometry.cell_size * self.scale
        self.last_distractors = (self.position[None, ::-1] + offsets[:, ::-1] * step) if len(offsets) else \
            np.zeros((0, 2))

    def _label(self, detection: Detection | None) -> tuple[np.ndarray, np.ndarray]:
        """The label component's ``(y, offsets)``: y as float32, no offsets as ``(0, 2)``."""
        y, offsets = self.label.make(self.base_label, detection)
        return y.astype(np.float32, copy=False), offsets if offsets.size else np.zeros((0, 2), int)

    def _clamp(self, centre: np.ndarray, shape) -> np.ndarray:
        """Keep the centre on the image (``tracker.clamp_position``)."""
        if not self.params.clamp_position:
            return centre
        return np.clip(centre, 0, np.array(shape[:2], dtype=float) - 1)

    @property
    def last_confidence(self) -> Confidence:
        """The last frame's :class:`~dcfkit.tracker.confidence.Confidence`: ``peak`` (max of
        ``last_response``) and ``apce`` (Wang et al.'s average peak-to-correlation energy, chosen
        over the PSR because it has no sidelobe window to size in cells). Both NaN after
        ``init`` and on a held blank frame, which have no response. Read-only: computed from
        ``last_response`` when asked, it changes nothing the tracker does."""
        return Confidence.of(self.last_response)

    @property
    def box(self) -> tuple[float, float, float, float]:
        """Current (x, y, w, h), 0-based pixels (``tracker.box_output``)."""
        size = self.geometry.base_target * self.scale
        if self.params.box_output == "half_size":  # DR²Track's [pos - round(size) / 2, round(size)]
            (cy, cx), (h, w) = self.position, round_half_away(size)
            return float(cx - w / 2), float(cy - h / 2), float(w), float(h)
        if self.params.box_output == "floor_half":  # BACF's [pos - floor(floor(size) / 2), floor(size)]
            (cy, cx), (h, w) = self.position, np.floor(size)
            return float(cx - np.floor(w / 2)), float(cy - np.floor(h / 2)), float(w), float(h)
        box = centre_size_to_box(self.position, size)
        if self.params.box_output == "rounded":  # round([pos - (sz - 1)/2, sz]), 1-based
            return tuple(float(v) for v in round_half_away(np.add(box, (1, 1, 0, 0))) - (1, 1, 0, 0))
        return box


def load_tracker(config: str | Mapping[str, Any], **overrides: Any) -> Tracker:
    """Build a tracker from a config path, shipped name ('dr2track') or dict, with dotted overrides.

    Overrides use ``__`` for dots in keyword form (``label__mu=0.3``) or pass a mapping via
    ``overrides={'label.mu': 0.3}``.
    """
    extra = dict(overrides.pop("overrides", None) or {})
    extra.update({k.replace("__", "."): v for k, v in overrides.items()})
    return Tracker(load_config(config, extra))

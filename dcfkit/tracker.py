"""The DCF tracking loop: Algorithm 1 of DR²Track, with every step a configured component.

Frame 1 (``init``): extract the sample m¹ at the ground truth, train h¹ (θ = 0), V¹ = 0.
Frame t (``update``): centre the search area (Eq. 14), compute the response (Eq. 12) at each
search scale, take the peak as p^t, update the scale, extract m^t at p^t, build the label
(Eq. 3 for the repressed label), train h^t (Eqs. 9–11), and update the velocity (Eq. 13).
A frame whose search patch is blank (standard deviation of its pixel values below
``tracker.blank_std``: a dropped or black video frame) is held: the box stays, nothing is
learnt, and the frame number goes to ``held_frames``.

Images are (H, W, 3) uint8 BGR or (H, W) uint8 gray; boxes are (x, y, w, h) floats,
0-based pixels. The tracker is deterministic.
"""
from __future__ import annotations

import dataclasses
from typing import Any, Mapping

import cv2
import numpy as np

from .config import TrackerParams, load_config
from .errors import InputError, TrackingError, blamed_on
from .features import extract_stack
from .fft import make_fft
from .labels import Detection, gaussian_label
from .patches import box_to_centre_size, centre_size_to_box, sample
from .registry import get_registry
from .response import response, shift_spectrum, subpixel_peak
from .scale import scale_limits


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
    """A finite (x, y, w, h) with positive size that overlaps the image."""
    try:
        raw = np.asarray(box)
        if raw.dtype.kind not in "iuf":  # not booleans, complex numbers, strings or objects
            raise TypeError
        b = raw.astype(float).reshape(-1)
    except (TypeError, ValueError):
        raise InputError(f"initial box must be 4 numbers (x, y, w, h), got {box!r}") from None
    if b.size != 4 or not np.all(np.isfinite(b)):
        raise InputError(f"initial box must be 4 finite numbers (x, y, w, h), got {box!r}")
    x, y, w, h = (float(v) for v in b)
    if w <= 0 or h <= 0:
        raise InputError(f"initial box {(x, y, w, h)} has non-positive size (w={w:g}, h={h:g})")
    height, width = image_shape[:2]
    if x + w <= 0 or y + h <= 0 or x >= width or y >= height:
        raise InputError(f"initial box {(x, y, w, h)} lies outside the {width}x{height} image")
    return b


def hann2d(shape: tuple[int, int]) -> np.ndarray:
    """Cosine window without zero borders (hann(n + 2) trimmed), (H, W) float32."""
    return np.outer(np.hanning(shape[0] + 2)[1:-1], np.hanning(shape[1] + 2)[1:-1]).astype(np.float32)


@dataclasses.dataclass
class Geometry:
    """Sizes fixed at init, in pixels at scale 1 unless stated (see STRCF's init_size)."""

    base_target: np.ndarray      # (h, w) target
    sample_size: np.ndarray      # (h, w) resampled search patch, a multiple of the cell size
    filter_size: tuple[int, int]  # (H, W) in cells
    target_cells: tuple[float, float]


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
        self.search = build("search", config["search"], "search")
        self.scale_estimator = build("scale", config["scale"], "scale")
        self.fft = make_fft(self.params.fft_backend)
        self.frame = 0
        # diagnostics of the last frame: the response map (cells, centred: fftshift), the image box
        # (x, y, w, h) it covers, and the repressed distractors as (x, y) image pixels
        self.last_response: np.ndarray | None = None
        self.last_search_box: tuple[float, float, float, float] | None = None
        self.last_distractors = np.zeros((0, 2))
        self.held_frames: list[int] = []  # 1-based numbers of frames held as blank

    # -- geometry ---------------------------------------------------------------------------
    def _geometry(self, target: np.ndarray) -> tuple[Geometry, float]:
        p = self.params
        region = (np.full(2, p.search_area_scale * np.sqrt(np.prod(target))) if p.search_area_shape == "square"
                  else target * p.search_area_scale)
        area = float(np.prod(region))
        scale = 1.0
        if area > p.max_image_sample_size:
            scale = np.sqrt(area / p.max_image_sample_size)
        elif area < p.min_image_sample_size:
            scale = np.sqrt(area / p.min_image_sample_size)
        cells = np.maximum(np.round(region / scale / p.cell_size), 4).astype(int)
        base_target = target / scale
        target_cells = tuple(float(v) for v in base_target / p.cell_size)
        geom = Geometry(base_target, cells * p.cell_size, (int(cells[0]), int(cells[1])), target_cells)
        return geom, float(scale)

    def _patch(self, image: np.ndarray, centre: np.ndarray, scale: float) -> np.ndarray:
        """The search patch at ``centre``, resampled to the sample size."""
        g = self.geometry
        return sample(image, centre, g.sample_size * scale, g.sample_size)

    def _spectrum(self, patch: np.ndarray) -> np.ndarray:
        """(C, H, Wr) complex64 spectrum of the windowed features of a search patch."""
        x = extract_stack(self.features, patch, self.params.cell_size, f"frame {self.frame}: ")
        return self.fft.rfft2(x * self.window).astype(np.complex64, copy=False)

    def _sample(self, image: np.ndarray, centre: np.ndarray, scale: float) -> np.ndarray:
        return self._spectrum(self._patch(image, centre, scale))

    def _blank(self, patch: np.ndarray) -> float | None:
        """The standard deviation of the patch's pixel values (RMS over colour channels) if it is
        below ``blank_std``, else None."""
        std = float(np.sqrt(np.mean(np.square(cv2.meanStdDev(patch)[1]))))
        return std if std < self.params.blank_std else None

    # -- Algorithm 1 ------------------------------------------------------------------------
    def init(self, image: np.ndarray, box) -> None:
        """Frame 1: learn the first filter at ``box`` (x, y, w, h)."""
        image = check_image(image, 1)
        box = check_box(box, image.shape)
        centre, target = box_to_centre_size(box)
        g, scale = self._geometry(target)
        limits = scale_limits(g.base_target, g.sample_size, image.shape, initial=scale)
        scale = float(np.clip(scale, *limits))
        patch = sample(image, centre, g.sample_size * scale, g.sample_size)
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
        self.window = hann2d(g.filter_size)
        sigma = np.sqrt(np.prod(np.floor(np.asarray(g.target_cells)).clip(1))) * self.params.output_sigma_factor
        self.base_label = gaussian_label(g.filter_size, sigma)
        self.base_label.setflags(write=False)  # every frame's label starts from it
        self.w2 = (self.spatial.weights_squared(g.filter_size, g.target_cells) if self.spatial is not None
                   else np.zeros(g.filter_size, np.float32))
        self.solver.reset()
        self.search.reset(centre)
        self.scale_estimator.init(image, centre, g.base_target, self.scale, self.limits)
        self.position = centre
        self.last_response, self.last_search_box = None, None
        self.last_distractors = np.zeros((0, 2))
        self.held_frames = []
        self._train(image, None, self._spectrum(patch))  # m^1: the patch checked above

    def update(self, image: np.ndarray) -> tuple[float, float, float, float]:
        """Frame t > 1: locate the target, return its box (x, y, w, h), and learn from it."""
        if self.frame == 0:
            raise TrackingError("update() called before init()")
        self.frame += 1  # every frame given counts, rejected ones too: numbers match the caller's video
        image = check_image(image, self.frame)
        if image.shape[:2] != self.image_size:
            raise InputError(f"frame {self.frame}: the image is {image.shape[1]}x{image.shape[0]}, but the "
                             f"sequence's first frame was {self.image_size[1]}x{self.image_size[0]}")
        g = self.geometry
        centre = self._clamp(self.search.centre(), image.shape)  # Eq. (14)
        factors = self.scale_estimator.search_factors()
        patches = [self._patch(image, centre, self.scale * f) for f in factors]
        if self._blank(patches[len(factors) // 2]) is not None:  # a dropped frame: hold, learn nothing
            self.last_response, self.last_search_box, self.last_distractors = None, None, np.zeros((0, 2))
            self.held_frames.append(self.frame)
            return self.box
        samples = np.stack([self._spectrum(patch) for patch in patches])
        maps = response(self.hf, samples, g.filter_size, self.fft)  # Eq. (12)
        if not np.all(np.isfinite(maps)):
            raise TrackingError(f"frame {self.frame}: the response map is not finite (the filter overflowed: "
                                f"look for extreme solver, regularizer or label values in the config)")
        best = int(np.argmax(maps.reshape(len(factors), -1).max(axis=1)))
        dy, dx, _ = subpixel_peak(maps[best])
        step = self.params.cell_size * self.scale * factors[best]
        self.position = self._clamp(centre + np.array([dy, dx]) * step, image.shape)
        self.scale = self.scale_estimator.update(image, self.position, self.scale * factors[best])
        self.search.observe(self.position)  # Eq. (13)
        peak = np.unravel_index(int(np.argmax(maps[best])), g.filter_size)
        self.last_response = np.fft.fftshift(maps[best])
        self.last_search_box = centre_size_to_box(centre, g.sample_size * step / self.params.cell_size)
        xf = None
        if self.params.training_sample == "shift":  # the detection sample, moved to p^t
            dy, dx = (self.position - centre) / step
            xf = shift_spectrum(samples[best], dy, dx, g.filter_size)
        self._train(image, Detection(maps[best], (int(peak[0]), int(peak[1])), g.target_cells), xf)
        return self.box

    def _train(self, image: np.ndarray, detection: Detection | None, xf: np.ndarray | None = None) -> None:
        if xf is None:
            xf = self._sample(image, self.position, self.scale)  # m^t at p^t
        y, offsets = self._label(detection)  # Eq. (3)
        yf = self.fft.rfft2(y).astype(np.complex64, copy=False)
        theta = self.temporal.params.theta if self.temporal is not None else 0.0
        self.hf = self.solver.train(xf, yf, self.w2, theta, self.fft)  # Eqs. (9)-(11)
        step = self.params.cell_size * self.scale
        self.last_distractors = (self.position[None, ::-1] + offsets[:, ::-1] * step) if len(offsets) else \
            np.zeros((0, 2))

    def _label(self, detection: Detection | None) -> tuple[np.ndarray, np.ndarray]:
        """The label component's ``(y, offsets)``, with what a (plugin) label got wrong said as a
        TrackingError naming the frame."""
        what = f"frame {self.frame}: label '{self.label.name}'"
        with blamed_on(what):
            out = self.label.make(self.base_label, detection)
        if not (isinstance(out, tuple) and len(out) == 2):
            raise TrackingError(f"{what}: make() must return (y, offsets), got {type(out).__name__}")
        y, offsets = np.asarray(out[0]), np.asarray(out[1])
        if y.shape != self.base_label.shape:
            raise TrackingError(f"{what} returned y of shape {y.shape}, expected g's {self.base_label.shape}")
        if not np.isfinite(y).all():
            raise TrackingError(f"{what} returned NaN or infinite values")
        if offsets.size == 0:
            offsets = np.zeros((0, 2), int)
        elif offsets.ndim != 2 or offsets.shape[1] != 2:
            raise TrackingError(f"{what} returned offsets of shape {offsets.shape}, expected (N, 2) (dy, dx) cells")
        return y.astype(np.float32, copy=False), offsets

    @staticmethod
    def _clamp(centre: np.ndarray, shape) -> np.ndarray:
        """Keep the centre on the image so a target leaving it never yields a NaN box."""
        return np.clip(centre, 0, np.array(shape[:2], dtype=float) - 1)

    @property
    def box(self) -> tuple[float, float, float, float]:
        """Current (x, y, w, h), 0-based pixels."""
        return centre_size_to_box(self.position, self.geometry.base_target * self.scale)


def load_tracker(config: str | Mapping[str, Any], **overrides: Any) -> Tracker:
    """Build a tracker from a config path, shipped name ('dr2track') or dict, with dotted overrides.

    Overrides use ``__`` for dots in keyword form (``label__mu=0.3``) or pass a mapping via
    ``overrides={'label.mu': 0.3}``.
    """
    extra = dict(overrides.pop("overrides", None) or {})
    extra.update({k.replace("__", "."): v for k, v in overrides.items()})
    return Tracker(load_config(config, extra))

"""The DCF tracking loop: Algorithm 1 of DR²Track, with every step a configured component.

Frame 1 (``init``): extract the sample m¹ at the ground truth, train h¹ (θ = 0), V¹ = 0.
Frame t (``update``): centre the search area (Eq. 14), compute the response (Eq. 12) at each
search scale, take the peak as p^t (re-detected if judged lost: :mod:`.recovery`), update
the scale, extract m^t at p^t, build the label (Eq. 3 for the repressed label), train h^t
(Eqs. 9–11), and update the velocity (Eq. 13). A blank frame (standard deviation of its
pixel values below ``tracker.blank_std``: a dropped or black video frame; the whole frame
tested, so a dark scene is tracked) is held: the box stays, nothing is learnt, and the frame
number goes to ``held_frames``.

Images are (H, W, 3) uint8 BGR or (H, W) uint8 gray; boxes are (x, y, w, h) floats,
0-based pixels. The tracker is deterministic.
"""
from __future__ import annotations

from typing import Any, Mapping

import numpy as np

from dcfkit.components.base import Target
from dcfkit.components.features.base import extract_stack
from dcfkit.components.labels.base import Detection, gaussian_label
from dcfkit.components.reliability.base import unreliable
from dcfkit.components.scale.base import scale_limits
from dcfkit.config import load_config
from dcfkit.config.slots import SLOTS, build
from dcfkit.config.tracker_params import TrackerParams
from dcfkit.contracts import naming_the_frame
from dcfkit.errors import InputError, TrackingError
from dcfkit.numerics.fft import make_fft
from dcfkit.numerics.patches import box_to_centre_size, centre_size_to_box, round_half_away
from dcfkit.numerics.response import newton_peak, parabola_peak, response_spectra, shift_spectrum, subpixel_peak
from dcfkit.registry import get_registry
from dcfkit.tracker.checks import (
    blank, check_blank_first, check_box, check_config_budget, check_first_frame,
    check_image, check_sampling, check_spectra, check_terms, first_due, read_only,
)
from dcfkit.tracker.confidence import Confidence
from dcfkit.tracker.continuous import continuous_loop
from dcfkit.tracker.geometry import (
    Geometry, geometry, hann2d, label_sigma, limit_step, patch_sampler, reported_box,
)
from dcfkit.tracker.learnt import channel_maps, learn_channels, masked_w2
from dcfkit.tracker.recovery import Located, gated, judged, recovered


class Tracker:
    """A DCF tracker assembled from components (see :func:`dcfkit.load_tracker`)."""

    def __init__(self, config: Mapping[str, Any]):
        """``config``: as :func:`dcfkit.load_config` resolved it. Each slot of
        :data:`dcfkit.config.slots.SLOTS` is built once, into the attribute the slot names."""
        registry = get_registry()
        self.config = dict(config)
        self.name = config["name"]
        self.params = TrackerParams(**config["tracker"])
        for slot in SLOTS:
            setattr(self, slot.name, build(slot, registry, config, self.name))
        self.loop = continuous_loop(self)  # ECO's solver learns on the continuous domain: its own loop
        for check in (check_terms, check_spectra, check_sampling):
            check(self)
        self.fft = make_fft(self.params.fft_backend, full=self.params.spectra == "full")
        self.frame = 0
        # diagnostics of the last frame: the response map (cells, centred: fftshift), the image box
        # (x, y, w, h) it covers, and the repressed distractors as (x, y) image pixels; the
        # confidence read from the map is the property last_confidence
        self.last_response: np.ndarray | None = None
        self.last_search_box: tuple[float, float, float, float] | None = None
        self.last_distractors = np.zeros((0, 2))
        self.held_frames: list[int] = []  # 1-based numbers of frames held as blank
        self.last_score: float | None = None  # the reliability score of the last detection
        check_config_budget(self)

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
        return patch_sampler(self.params, g or self.geometry, shape, centre, scale)

    def _spectrum(self, patch: np.ndarray) -> np.ndarray:
        """(C, H, Wr) complex64 spectrum of the windowed features of a search patch."""
        x = extract_stack(self.features, patch, self.geometry.cell_size)
        return self.fft.rfft2(x * self.window).astype(np.complex64, copy=False)

    def _sample(self, image: np.ndarray, centre: np.ndarray, scale: float) -> np.ndarray:
        return self._spectrum(self._patch(image, centre, scale))

    # -- Algorithm 1 ------------------------------------------------------------------------
    @naming_the_frame(lambda tracker: 1)
    def init(self, image: np.ndarray, box) -> None:
        """Frame 1: learn the first filter at ``box`` (x, y, w, h)."""
        if self.loop is not None:
            return self.loop.init(image, box)
        image = check_image(image, 1)
        box = check_box(box, image.shape)
        centre, target = box_to_centre_size(box)
        given = target
        if self.params.init_position == "whole_pixel":  # 1-based floor([y x] + floor([h w] / 2))
            target = np.floor(target)
            centre = np.floor(box[[1, 0]] + np.floor(target / 2))
        g, scale = geometry(self.params, target, given if self.params.init_area == "given" else target)
        limits = scale_limits(g.base_target, g.sample_size, image.shape, initial=scale, step=limit_step(self))
        scale = float(np.clip(scale, *limits))
        check_first_frame(self, image.shape, centre, g, scale, box)
        patch = self._patch(image, centre, scale, g)
        # checked before any state changes: a failed init leaves the tracker as it was
        check_blank_first(self, patch, centre, image.shape)
        first_due(self)  # a copy of the schedule, reset, asked about frame 1
        self.frame = 1
        self.image_size = image.shape[:2]
        self.geometry, self.scale, self.limits = g, scale, limits
        self.box_scale = scale  # the reported box's (tracker.box_scale)
        self.window = hann2d(g.filter_size, interior=self.params.window == "hann_interior")
        sigma = label_sigma(self.params, g)
        self.base_label = gaussian_label(g.filter_size, sigma)
        self.base_label.setflags(write=False)  # every frame's label starts from it
        optional = [c for c in (self.spatial, self.temporal, self.schedule, self.mask, self.channel_weights,
                                self.reliability, self.redetect) if c is not None]
        for component in (*self.features, self.label, self.solver, *optional):  # a new target: nothing kept
            component.reset()
        target = Target(self.image_size, g.filter_size, g.target_cells, g.cell_size, scale, float(sigma), g.template)
        for component in (*self.features, self.label, self.solver, *optional, self.search, self.scale_estimator):
            component.start(target)
        self.w2 = read_only(self.spatial.weights_squared(g.filter_size, g.target_cells) if self.spatial is not None
                             else np.zeros(g.filter_size, np.float32))
        self.search.reset(centre)
        self.scale_estimator.init(image, centre, g.base_target, self.scale, self.limits)
        self.position = centre
        self.last_response, self.last_search_box, self.last_distractors = None, None, np.zeros((0, 2))
        self.held_frames = []
        self._train(image, None, self._spectrum(patch))  # m^1: the patch checked above

    @naming_the_frame(lambda tracker: tracker.frame)
    def update(self, image: np.ndarray) -> tuple[float, float, float, float]:
        """Frame t > 1: locate the target, return its box (x, y, w, h), and learn from it."""
        if self.frame == 0:
            raise TrackingError("update() called before init()")
        if self.loop is not None:
            return self.loop.update(image)
        self.frame += 1  # every frame given counts, rejected ones too: numbers match the caller's video
        image = check_image(image, self.frame)
        if image.shape[:2] != self.image_size:
            raise InputError(f"frame {self.frame}: the image is {image.shape[1]}x{image.shape[0]}, but the "
                             f"sequence's first frame was {self.image_size[1]}x{self.image_size[0]}")
        g, p = self.geometry, self.params
        centre = self._clamp(np.array(self.search.centre(), dtype=float), image.shape)  # Eq. (14); a copy
        if p.sampling == "whole_pixel" and p.translation != "exact_centre":  # the patch on a whole pixel, and moves
            centre = round_half_away(centre)
        factors = np.array(self.scale_estimator.search_factors(), dtype=float)  # copies: a plugin may change its own
        if blank(self, image[::4, ::4]) is not None:  # a dropped frame: hold, learn nothing
            self.last_response, self.last_search_box, self.last_distractors = None, None, np.zeros((0, 2))
            self.held_frames.append(self.frame)
            return self.box
        patches = [self._patch(image, centre, self.scale * f) for f in factors]
        samples = np.stack([self._spectrum(patch) for patch in patches])
        maps = self._response(samples)  # Eq. (12)
        if not np.all(np.isfinite(maps)):
            raise TrackingError(f"frame {self.frame}: the response map is not finite (the filter overflowed: "
                                f"look for extreme solver, regularizer or label values in the config)")
        best, dy, dx = self._peak(maps, samples)
        move = np.array([dy, dx]) * g.cell_size * self.scale * factors[best]  # not * step: the authors' rounding
        if p.translation == "whole_pixel":
            move = round_half_away(move)
        peak = np.unravel_index(int(np.argmax(maps[best])), g.filter_size)
        detection = judged(self, Detection(maps[best], (int(peak[0]), int(peak[1])), g.target_cells, (dy, dx)))
        channel_maps = self._channel_maps[best] if self.channel_weights is not None else None
        found = Located(self._clamp(centre + move, image.shape), centre, self.scale * factors[best],
                        g.cell_size * self.scale * factors[best], detection, samples[best], channel_maps)
        self._settle(image, recovered(self, image, found))
        return self.box

    def _settle(self, image: np.ndarray, found: Located) -> None:
        """Place the target where ``found`` says, estimate the scale there, and learn."""
        g, p = self.geometry, self.params
        self.position = found.position
        self.box_scale = self.scale if p.box_scale == "previous" else None  # CSR-DCF's region: the old scale
        if not gated(self, found.detection):  # a gated frame's scale filter would learn the background too
            self.scale = float(self.scale_estimator.update(image, self.position, found.scale))
        self.box_scale = self.box_scale or self.scale
        if found.jumped:  # re-detected: no motion to extrapolate from
            self.search.reset(self.position)
        else:
            self.search.observe(self.position)  # Eq. (13)
        self.last_response = np.fft.fftshift(found.detection.response)
        self.last_search_box = centre_size_to_box(found.centre, g.sample_size * found.step / g.cell_size)
        self.last_score = found.detection.score
        xf = None
        if p.training_sample == "shift":  # the detection sample, moved to p^t in cells of the new scale
            sy, sx = (self.position - found.centre) / (g.cell_size * self.scale)
            xf = shift_spectrum(found.sample, sy, sx, g.filter_size, self.fft.full)
        self._observe(found)
        self._train(image, found.detection, xf)

    def _response(self, samples: np.ndarray) -> np.ndarray:
        """The solver's (S, H, W) response maps of the (S, C, H, Wr) search samples."""
        if self.channel_weights is not None:  # each channel's map weighted (CSR-DCF's channel reliability)
            self._channel_maps = channel_maps(self, samples)
            return self.channel_weights.combine(self._channel_maps)
        return self.solver.response(self.hf, samples, self.geometry.filter_size, self.fft)

    def _observe(self, found: Located) -> None:
        """Give the frame's detection to the components that adapt to it: the solver, the
        schedule, the channel weights, the reliability and re-detection components, and the
        spatial regularizer, whose w² it returns is used from this frame on."""
        detection = found.detection
        self.solver.observe(detection)
        if self.schedule is not None:
            self.schedule.observe(detection)
        if self.channel_weights is not None:
            self.channel_weights.observe(found.channel_maps)
        if self.reliability is not None:
            self.reliability.observe(detection, detection.score)
        if self.redetect is not None:
            self.redetect.observe(self.position.copy(), not unreliable(detection.score))
        if self.spatial is not None:
            self.w2 = read_only(self.spatial.adapt(self.w2, detection))

    def _theta(self, detection: Detection | None) -> float:
        """θ of this frame's training (0 without a temporal term; ``inf``: keep the last filter)."""
        return 0.0 if self.temporal is None else float(self.temporal.weight(detection))

    def _peak(self, maps: np.ndarray, samples: np.ndarray) -> tuple[int, float, float]:
        """The search scale whose response is best and its peak as a (dy, dx) offset in cells."""
        if self.params.peak == "newton":
            # whole spectra: resp_newton refines on the response spectra as computed, not fft2 of the real map
            spectra = response_spectra(self.hf, samples) if self.fft.full else None
            best, dy, dx, _ = newton_peak(maps, self.params.newton_iterations, spectra)
            return best, dy, dx
        best = int(np.argmax(maps.reshape(len(maps), -1).max(axis=1)))
        if self.params.peak == "parabola":  # CSR-DCF's: a parabola through each axis's neighbours
            return (best, *parabola_peak(maps[best]))
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
        due = self.schedule is None or self.schedule.due(self.frame)  # sparse updates: not every frame
        if not due and detection is None:  # first_due asked a copy: only a schedule that changed its mind
            raise TrackingError(f"frame 1: schedule '{self.schedule.name}' skips the first frame")
        if theta != np.inf and due:  # inf: the temporal term holds the filter where it is
            w2 = self.w2 if self.mask is None else masked_w2(self, image)  # a mask: inf outside it
            self.hf = self.solver.train(xf, yf, w2, theta, self.fft)  # Eqs. (9)-(11)
            if self.channel_weights is not None:
                learn_channels(self, xf)
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
        """The last frame's :class:`~dcfkit.tracker.confidence.Confidence` (``peak``, ``apce`` and
        the reliability ``score``), NaN after ``init`` and on a held blank frame, which have no
        response. Read-only: computed when asked, it changes nothing the tracker does."""
        return Confidence.of(self.last_response, self.last_score)

    @property
    def box(self) -> tuple[float, float, float, float]:
        """Current (x, y, w, h), 0-based pixels (``tracker.box_output``)."""
        if self.loop is not None:
            return self.loop.box()
        return reported_box(self.position, self.geometry.base_target * self.box_scale, self.params.box_output)


def load_tracker(config: str | Mapping[str, Any], **overrides: Any) -> Tracker:
    """Build a tracker from a config path, shipped name ('dr2track') or dict, with dotted overrides.

    Overrides use ``__`` for dots in keyword form (``label__mu=0.3``) or pass a mapping via
    ``overrides={'label.mu': 0.3}``.
    """
    extra = dict(overrides.pop("overrides", None) or {})
    extra.update({k.replace("__", "."): v for k, v in overrides.items()})
    return Tracker(load_config(config, extra))

"""The continuous loop: ECO's tracker (Danelljan et al., CVPR 2017; its tracker.m), for
configs whose solver learns on the continuous domain (``solver.loop == "continuous"``).

Frame 1: the features of each block at its own cell size, windowed, their Fourier series
interpolated to the continuous domain (the cubic kernel's coefficients), the projection P
initialised by PCA and learnt with the filter (Gauss-Newton), the sample kept in the memory.
Frame t: the search sample projected and interpolated the same way, the blocks' responses
summed on the finest grid, the maximum of the Fourier series found by Newton's method; the
scale from the scale estimator; the detection sample, shifted to the new position, into the
memory; the filter trained by CG when the schedule says so.

The :class:`dcfkit.tracker.tracker.Tracker` built from the config holds the components and
hands ``init``, ``update`` and ``box`` to this loop (its ``loop``); the frame's checks, the
blank-frame hold and the diagnostics (``last_response``, ``held_frames``) are the discrete
loop's, kept on the tracker.
"""
from __future__ import annotations

import dataclasses

import numpy as np

from dcfkit.components.base import Target
from dcfkit.components.labels.base import Detection
from dcfkit.components.scale.base import scale_limits
from dcfkit.components.solvers.eco_joint import pca_projection, project
from dcfkit.config.tracker_params import TrackerParams
from dcfkit.errors import ConfigError, InputError, TrackingError
from dcfkit.numerics import fourier_series as fs
from dcfkit.numerics.patches import box_to_centre_size, centre_size_to_box, round_half_away
from dcfkit.tracker.blocks import extract, layout, sample_patch
from dcfkit.tracker.checks import blank, check_blank_first, check_box, check_image, first_due
from dcfkit.tracker.geometry import Geometry, limit_step, reported_box


def continuous_loop(tracker) -> "ContinuousLoop | None":
    """The continuous loop of ``tracker`` if its solver declares ``loop = "continuous"``, else
    None; a ConfigError for a memory the discrete loop would leave unused."""
    if getattr(tracker.solver, "loop", "discrete") == "continuous":
        return ContinuousLoop(tracker)
    if tracker.memory is not None:
        raise ConfigError(f"{tracker.name}: memory: solver '{tracker.solver.name}' keeps its own model")
    return None


# tracker keys of the discrete loop that the continuous one has no use for: ECO samples, windows,
# finds the peak and moves its own way, on half spectra of its blocks
UNUSED = ("sampling", "window", "peak", "translation", "training_sample", "init_position", "init_area",
          "cell_selection_thresh", "spectra", "fft_backend", "output_sigma", "cell_area", "box_scale", "resize")


def refuse_unused(tracker) -> None:
    """ConfigError naming a tracker key or component the continuous loop would silently ignore:
    a discrete-loop key changed from its default (``UNUSED``), ``search_area_shape: padded_square``,
    channel weights or a mask (ECO's filter has neither)."""
    default, solver = TrackerParams(), tracker.solver.name
    for key in UNUSED:
        if getattr(tracker.params, key) != getattr(default, key):
            raise ConfigError(f"{tracker.name}: tracker.{key}: solver '{solver}' runs in the "
                              f"continuous loop, which does not use it (keys it ignores: {', '.join(UNUSED)})")
    if tracker.params.search_area_shape == "padded_square":
        raise ConfigError(f"{tracker.name}: tracker.search_area_shape: 'padded_square' is the discrete loop's "
                          f"(CSR-DCF's); solver '{solver}' runs in the continuous loop: use square or proportional")
    for slot in ("channel_weights", "mask", "reliability", "redetect"):
        component = getattr(tracker, slot)
        if component is not None:
            raise ConfigError(f"{tracker.name}: {slot} '{component.name}': solver '{solver}' runs in the "
                              f"continuous loop, which would ignore it: set {slot}: null")
    if getattr(tracker.schedule, "needs_reliability", False):
        raise ConfigError(f"{tracker.name}: schedule '{tracker.schedule.name}' gates on the reliability of each "
                          f"detection, which solver '{solver}''s continuous loop does not judge: use another "
                          f"schedule (sparse, every_frame)")


class ContinuousLoop:
    """ECO's loop over the components of ``tracker`` (see the module docstring)."""

    def __init__(self, tracker):
        self.t = tracker
        s = tracker.solver.params
        refuse_unused(tracker)
        if tracker.memory is None:
            raise ConfigError(f"{tracker.name}: solver '{tracker.solver.name}' learns from a memory of samples: "
                              f"add one, e.g. memory: {{name: gmm}}")
        if len(s.cell_sizes) != len(tracker.features):
            raise ConfigError(f"{tracker.name}: solver.cell_sizes has {len(s.cell_sizes)} entries for "
                              f"{len(tracker.features)} features: one per feature, in their order")
        if tracker.label.name != "gaussian":  # the label is the Gaussian's Fourier series (tracker.output_sigma_factor)
            raise ConfigError(f"{tracker.name}: label: the continuous loop's label is a Gaussian's Fourier series; "
                              f"'{tracker.label.name}' would be ignored (use label: {{name: gaussian}})")
        for skip in ("gray_skip", "colour_skip"):
            # the defaults name ECO's features, whichever a config has; names given must be its own
            unknown = [n for n in getattr(s, skip) if n not in {f.name for f in tracker.features}]
            if unknown and getattr(s, skip) != getattr(type(s)(), skip):
                raise ConfigError(f"{tracker.name}: solver.{skip}: {', '.join(map(repr, unknown))} is not one of the "
                                  f"config's features ({', '.join(f.name for f in tracker.features)})")
            if all(f.name in getattr(s, skip) for f in tracker.features):
                raise ConfigError(f"{tracker.name}: solver.{skip} leaves out every feature")
        for f, d in zip(tracker.features, s.compressed_dims):
            if d > f.channels():
                raise ConfigError(f"{tracker.name}: solver.compressed_dims: {d} for feature '{f.name}', which has "
                                  f"{f.channels()} channels (at most that many)")

    def _active(self, colour: bool) -> list:
        """The features used on this sequence (ECO's useForGray), with their parameters."""
        s = self.t.solver.params
        keep = [f.name not in (s.colour_skip if colour else s.gray_skip) for f in self.t.features]
        if not any(keep):
            raise InputError(f"frame 1: every feature is in solver.{'colour' if colour else 'gray'}_skip, and the "
                             f"sequence is {'colour' if colour else 'gray'}")
        pick = dataclasses.replace(s, cell_sizes=tuple(c for c, k in zip(s.cell_sizes, keep) if k),
                                   compressed_dims=tuple(d for d, k in zip(s.compressed_dims, keep) if k))
        return [f for f, k in zip(self.t.features, keep) if k], pick

    def _spectra(self, maps: list[np.ndarray]) -> list[np.ndarray]:
        """Each block's (…, C, h, w) maps windowed -> interpolated full centred spectra."""
        return [fs.centred_dft(x * b.window) * b.interp_y[:, None] * b.interp_x[None, :]
                for x, b in zip(maps, self.layout.blocks)]

    def _samples(self, image, pos, scales) -> list[np.ndarray]:
        """Per block (S, C, h, w): the normalised maps at the whole pixel ``pos``, one per scale."""
        support = self.layout.support
        per_scale = [extract(self.layout.blocks, sample_patch(image, pos, support * s, support)) for s in scales]
        return [np.stack([m[k] for m in per_scale]) for k in range(len(self.layout.blocks))]

    def _shifted(self, half: list[np.ndarray], pos, sample_pos, scale) -> list[np.ndarray]:
        """The sample moved so that the target is at its middle (ECO's shift_sample)."""
        dy, dx = 2 * np.pi * (pos - sample_pos) / (scale * self.layout.support)
        return [fs.shift(x, dy, dx).astype(np.complex64) for x in half]

    # -- frame 1 ----------------------------------------------------------------------------
    def _start(self, image, centre, lay, limits) -> None:
        """A new target: the tracker's state and diagnostics set, every component reset and
        started, the search and scale estimator initialised."""
        t = self.t
        t.frame, t.image_size, t.scale, t.limits = 1, image.shape[:2], lay.scale, limits
        target_cells = tuple(float(v) for v in lay.base_target * lay.output / lay.support)
        t.geometry = Geometry(lay.base_target, lay.support, lay.output, target_cells, lay.blocks[0].cell)
        t.held_frames, t.last_response, t.last_search_box = [], None, None
        t.last_distractors = np.zeros((0, 2))
        kept = [c for c in (t.memory, t.schedule) if c is not None]
        for component in (*t.features, t.label, t.solver, *kept):
            component.reset()
        start = Target(t.image_size, lay.output, target_cells, lay.blocks[0].cell, lay.scale, 0.0)
        for component in (*t.features, t.label, t.solver, *kept, t.search, t.scale_estimator):
            component.start(start)
        t.search.reset(centre)
        t.scale_estimator.init(image, centre, lay.base_target, t.scale, t.limits)

    def init(self, image: np.ndarray, box) -> None:
        """Frame 1: learn the projection and the filter at ``box`` (x, y, w, h)."""
        image = check_image(image, 1)
        box = check_box(box, image.shape)
        centre, target = box_to_centre_size(box)
        colour = image.ndim == 3 and not np.array_equal(image[..., 2], image[..., 1])  # ECO: R == G means gray
        gray = image if image.ndim == 2 else image[..., 2]
        features, s = self._active(colour)
        lay = layout(self.t.params, s, target, features)
        image = image if colour else gray
        step = limit_step(self.t)
        limits = scale_limits(lay.base_target, lay.support, image.shape, step=step)
        pos = centre + 1  # ECO's 1-based position
        sample_pos = round_half_away(pos)
        # checked before any state changes: a failed init leaves the tracker as it was
        patch = sample_patch(image, sample_pos, lay.support * lay.scale, lay.support)
        check_blank_first(self.t, patch, centre, image.shape)
        first_due(self.t)
        self.colour, self.layout = colour, lay
        self._start(image, centre, lay, limits)
        maps = extract(lay.blocks, patch)
        xs = self._shifted([fs.half(x) for x in self._spectra(maps)], pos, sample_pos, self.t.scale)
        projections = [pca_projection(x, b.dim) for x, b in zip(maps, lay.blocks)]
        self.t.memory.insert([project(x, p) for x, p in zip(xs, projections)])
        if self.t.schedule is not None and not self.t.schedule.due(1):  # first_due asked a copy: changed its mind
            raise TrackingError(f"frame 1: schedule '{self.t.schedule.name}' skips the first frame, where the filter "
                                f"must be learnt")
        labels, regs = [b.label for b in lay.blocks], [b.reg for b in lay.blocks]
        self.t.memory.replace(0, self.t.solver.learn_first(xs, labels, projections, regs))
        self.t.position = pos - 1  # 0-based, as the discrete loop's

    # -- frame t ----------------------------------------------------------------------------
    def update(self, image: np.ndarray) -> tuple[float, float, float, float]:
        """Frame t > 1: locate the target, return its box (x, y, w, h), and learn from it."""
        self.t.frame += 1
        image = check_image(image, self.t.frame)
        if image.shape[:2] != tuple(self.t.image_size):
            raise InputError(f"frame {self.t.frame}: the image is {image.shape[1]}x{image.shape[0]}, but the "
                             f"sequence's first frame was {self.t.image_size[1]}x{self.t.image_size[0]}")
        if not self.colour and image.ndim == 3:
            image = image[..., 2]
        if blank(self.t, image[::4, ::4]) is not None:
            self.t.last_response, self.t.last_search_box, self.t.last_distractors = None, None, np.zeros((0, 2))
            self.t.held_frames.append(self.t.frame)
            return self.box()
        lay, blocks = self.layout, self.layout.blocks
        factors = np.array(self.t.scale_estimator.search_factors(), dtype=float)
        sample_pos = round_half_away(np.asarray(self.t.search.centre(), dtype=float) + 1)
        maps = self._samples(image, sample_pos, self.t.scale * factors)
        projected = [project(x, p) for x, p in zip(maps, self.t.solver.projections)]
        spectra = [x.astype(np.complex64) for x in self._spectra(projected)]
        scores = self.t.solver.scores(spectra, lay.output)
        if not np.all(np.isfinite(scores)):
            raise TrackingError(f"frame {self.t.frame}: the response is not finite (the filter overflowed)")
        dy, dx, best = fs.newton_maximum(scores, self.t.params.newton_iterations)
        detect_scale = self.t.scale * factors[best]
        pos = sample_pos + np.array([dy, dx]) * (lay.support / np.array(lay.output)) * detect_scale
        if self.t.params.clamp_position:
            pos = np.clip(pos, 1, np.array(image.shape[:2], dtype=float))
        self.t.position = pos - 1  # 0-based, as the discrete loop's
        self.t.scale = float(self.t.scale_estimator.update(image, pos - 1, detect_scale))
        self.t.search.observe(pos - 1)
        grid = fs.sample(scores[best])
        self.t.last_response = np.fft.fftshift(grid)
        self.t.last_search_box = centre_size_to_box(sample_pos - 1, lay.support * detect_scale)
        sample = self._shifted([fs.half(x[best]) for x in spectra], pos, sample_pos, detect_scale)
        self.t.memory.insert(sample)
        if self.t.schedule is not None:  # the detection on the output grid, as the discrete loop gives it
            peak = np.unravel_index(int(np.argmax(grid)), grid.shape)
            self.t.schedule.observe(Detection(grid.astype(np.float32), (int(peak[0]), int(peak[1])),
                                              self.t.geometry.target_cells, (float(dy), float(dx))))
        if self.t.schedule is None or self.t.schedule.due(self.t.frame):
            self.t.solver.learn(sample, self.t.memory.samples, self.t.memory.weights, [b.label for b in blocks],
                                [b.reg for b in blocks])
        return self.box()

    def box(self) -> tuple[float, float, float, float]:
        """Current (x, y, w, h), 0-based pixels (``tracker.box_output``)."""
        return reported_box(self.t.position, self.layout.base_target * self.t.scale, self.t.params.box_output)

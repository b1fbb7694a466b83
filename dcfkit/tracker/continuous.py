"""The continuous loop: ECO's tracker (Danelljan et al., CVPR 2017; its tracker.m), for
configs whose solver learns on the continuous domain (``solver.loop == "continuous"``).

Frame 1: the features of each block at its own cell size, windowed, their Fourier series
interpolated to the continuous domain (the cubic kernel's coefficients), the projection P
initialised by PCA and learnt with the filter (Gauss-Newton), the sample kept in the memory.
Frame t: the search sample projected and interpolated the same way, the blocks' responses
summed on the finest grid, the maximum of the Fourier series found by Newton's method; the
scale from the scale estimator; the detection sample, shifted to the new position, into the
memory; the filter trained by CG when the schedule says so.

The frame's checks, the blank-frame hold, ``box`` and the diagnostics are the discrete
loop's (:class:`dcfkit.tracker.tracker.Tracker`).
"""
from __future__ import annotations

import dataclasses

import numpy as np

from dcfkit.components.base import Target
from dcfkit.components.scale.base import scale_limits
from dcfkit.components.solvers.eco_joint import pca_projection, project
from dcfkit.contracts import naming_the_frame
from dcfkit.errors import ConfigError, InputError, TrackingError
from dcfkit.numerics import fourier_series as fs
from dcfkit.numerics.patches import box_to_centre_size, centre_size_to_box, round_half_away
from dcfkit.tracker.blocks import extract, layout, sample_patch
from dcfkit.tracker.checks import check_box, check_image
from dcfkit.tracker.geometry import Geometry, reported_box
from dcfkit.tracker.tracker import Tracker


class ContinuousTracker(Tracker):
    """ECO's loop over the configured components (see the module docstring)."""

    def __init__(self, config):
        super().__init__(config)
        s = self.solver.params
        if self.memory is None:
            raise ConfigError(f"{self.name}: solver '{self.solver.name}' learns from a memory of samples: "
                              f"add one, e.g. memory: {{name: gmm}}")
        if len(s.cell_sizes) != len(self.features):
            raise ConfigError(f"{self.name}: solver.cell_sizes has {len(s.cell_sizes)} entries for "
                              f"{len(self.features)} features: one per feature, in their order")

    def _active(self, colour: bool) -> list:
        """The features used on this sequence (ECO's useForGray), with their parameters."""
        s = self.solver.params
        keep = [colour or f.name not in s.gray_skip for f in self.features]
        if not any(keep):
            raise InputError("frame 1: every feature is in solver.gray_skip, and the sequence is gray")
        pick = dataclasses.replace(s, cell_sizes=tuple(c for c, k in zip(s.cell_sizes, keep) if k),
                                   compressed_dims=tuple(d for d, k in zip(s.compressed_dims, keep) if k))
        return [f for f, k in zip(self.features, keep) if k], pick

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
    @naming_the_frame(lambda tracker: 1)
    def init(self, image: np.ndarray, box) -> None:
        """Frame 1: learn the projection and the filter at ``box`` (x, y, w, h)."""
        image = check_image(image, 1)
        box = check_box(box, image.shape)
        centre, target = box_to_centre_size(box)
        colour = image.ndim == 3 and not np.array_equal(image[..., 2], image[..., 1])  # ECO: R == G means gray
        gray = image if image.ndim == 2 else image[..., 2]
        features, s = self._active(colour)
        lay = layout(self.params, s, target, features)
        self.colour, self.layout = colour, lay
        image = image if colour else gray
        step = self._limit_step()
        limits = scale_limits(lay.base_target, lay.support, image.shape, step=step)
        self.frame, self.image_size = 1, image.shape[:2]
        self.scale, self.limits = lay.scale, limits
        target_cells = tuple(float(v) for v in lay.base_target * lay.output / lay.support)
        self.geometry = Geometry(lay.base_target, lay.support, lay.output, target_cells, lay.blocks[0].cell)
        self.held_frames, self.last_response, self.last_search_box = [], None, None
        self.last_distractors = np.zeros((0, 2))
        optional = [c for c in (self.memory, self.schedule) if c is not None]
        for component in (*self.features, self.label, self.solver, *optional):
            component.reset()
        start = Target(self.image_size, lay.output, target_cells, lay.blocks[0].cell, lay.scale, 0.0)
        for component in (*self.features, self.label, self.solver, *optional, self.search, self.scale_estimator):
            component.start(start)
        self.search.reset(centre)
        self.scale_estimator.init(image, centre, lay.base_target, self.scale, self.limits)
        pos = centre + 1  # ECO's 1-based position
        sample_pos = round_half_away(pos)
        maps = [m[0] for m in self._samples(image, sample_pos, [self.scale])]
        xs = self._shifted([fs.half(x) for x in self._spectra(maps)], pos, sample_pos, self.scale)
        projections = [pca_projection(x, b.dim) for x, b in zip(maps, lay.blocks)]
        self.memory.insert([project(x, p) for x, p in zip(xs, projections)])
        if self.schedule is not None and not self.schedule.due(1):
            raise TrackingError(f"frame 1: schedule '{self.schedule.name}' skips the first frame, where the filter "
                                f"must be learnt")
        labels, regs = [b.label for b in lay.blocks], [b.reg for b in lay.blocks]
        self.memory.replace(0, self.solver.learn_first(xs, labels, projections, regs))
        self.position = pos

    # -- frame t ----------------------------------------------------------------------------
    @naming_the_frame(lambda tracker: tracker.frame)
    def update(self, image: np.ndarray) -> tuple[float, float, float, float]:
        """Frame t > 1: locate the target, return its box (x, y, w, h), and learn from it."""
        if self.frame == 0:
            raise TrackingError("update() called before init()")
        self.frame += 1
        image = check_image(image, self.frame)
        if image.shape[:2] != tuple(self.image_size):
            raise InputError(f"frame {self.frame}: the image is {image.shape[1]}x{image.shape[0]}, but the "
                             f"sequence's first frame was {self.image_size[1]}x{self.image_size[0]}")
        if not self.colour and image.ndim == 3:
            image = image[..., 2]
        if self._blank(image[::4, ::4]) is not None:
            self.last_response, self.last_search_box, self.last_distractors = None, None, np.zeros((0, 2))
            self.held_frames.append(self.frame)
            return self.box
        lay, blocks = self.layout, self.layout.blocks
        factors = np.array(self.scale_estimator.search_factors(), dtype=float)
        sample_pos = round_half_away(np.asarray(self.search.centre(), dtype=float) + 1)
        maps = self._samples(image, sample_pos, self.scale * factors)
        projected = [project(x, p) for x, p in zip(maps, self.solver.projections)]
        spectra = [x.astype(np.complex64) for x in self._spectra(projected)]
        scores = self.solver.scores(spectra, lay.output)
        if not np.all(np.isfinite(scores)):
            raise TrackingError(f"frame {self.frame}: the response is not finite (the filter overflowed)")
        dy, dx, best = fs.newton_maximum(scores, self.params.newton_iterations)
        detect_scale = self.scale * factors[best]
        pos = sample_pos + np.array([dy, dx]) * (lay.support / np.array(lay.output)) * detect_scale
        if self.params.clamp_position:
            pos = np.clip(pos, 1, np.array(image.shape[:2], dtype=float))
        self.position = pos
        self.scale = float(self.scale_estimator.update(image, pos - 1, detect_scale))
        self.search.observe(pos - 1)
        self.last_response = np.fft.fftshift(fs.sample(scores[best]))
        self.last_search_box = centre_size_to_box(sample_pos - 1, lay.support * detect_scale)
        sample = self._shifted([fs.half(x[best]) for x in spectra], pos, sample_pos, detect_scale)
        self.memory.insert(sample)
        if self.schedule is None or self.schedule.due(self.frame):
            self.solver.learn(sample, self.memory.samples, self.memory.weights, [b.label for b in blocks],
                              [b.reg for b in blocks])
        return self.box

    @property
    def box(self) -> tuple[float, float, float, float]:
        """Current (x, y, w, h), 0-based pixels (``tracker.box_output``)."""
        return reported_box(self.position - 1, self.layout.base_target * self.scale, self.params.box_output)

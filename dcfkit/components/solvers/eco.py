"""ECO's factorised convolution operator (Danelljan et al., CVPR 2017): a filter on the
continuous domain per feature block, applied to the block's channels compressed by a
projection matrix P (Eq. 5); P and the filter learnt jointly on the first frame (Gauss-Newton,
:mod:`.eco_joint`), then the filter alone by a few warm-started conjugate gradient steps on
the samples of a memory (Eq. 9, :mod:`.eco_cg`).

This solver does not fit the discrete loop's ``train(xf, yf, w2, theta, fft)``: its samples
are per-block Fourier series, not one grid's spectrum. A config naming it is run by
:class:`dcfkit.tracker.continuous.ContinuousLoop`, which calls :meth:`ECO.learn_first`,
:meth:`ECO.learn` and :meth:`ECO.scores`.
"""
from __future__ import annotations

import dataclasses

import numpy as np

from dcfkit.components.solvers.base import Solver
from dcfkit.components.solvers.eco_cg import inner, lhs_filter, pcg, preconditioner
from dcfkit.components.solvers.eco_joint import project, train_joint
from dcfkit.errors import TrackingError
from dcfkit.numerics.fourier_series import full
from dcfkit.params import param


@dataclasses.dataclass(frozen=True)
class ECOParams:
    """ECO-HC's learning parameters (testing_ECO_HC.m)."""

    cell_sizes: tuple[int, ...] = param((6, 4), "cell size (pixels) of each feature, in the order of features")
    compressed_dims: tuple[int, ...] = param((10, 3), "channels each feature is projected to (its P's columns)")
    gray_skip: tuple[str, ...] = param(("colornames",), "features left out on gray sequences (ECO's useForGray)")
    colour_skip: tuple[str, ...] = param(("intensity_table",), "features left out on colour sequences (ECO's "
                                         "useForColor)")
    learning_rate: float = param(0.009, "γ: rate of the preconditioner's sample energy and of the CG "
                                 "direction's decay (the memory's own rate should match)", gt=0, lt=1)
    interpolation_a: float = param(-0.75, "a of the cubic interpolation kernel", ge=-2, le=0)
    interpolation_centering: bool = param(True, "centre the kernel on each feature sample")
    projection_reg: float = param(1e-7, "λ of ‖P‖² (Eq. 6)", ge=0, le=1e3)
    init_gn_iterations: int = param(10, "Gauss-Newton steps on the first frame", ge=1, le=50)
    init_cg_iterations: int = param(150, "CG iterations on the first frame, over all Gauss-Newton steps",
                                    ge=1, le=2000)
    cg_iterations: int = param(5, "CG iterations per later training", ge=1, le=50)
    cg_forgetting_rate: float = param(50.0, "CG's last direction is kept with weight (1 - γ)^rate (large: dropped)",
                                      ge=0, le=1e6)
    fletcher_reeves: bool = param(False, "β by Fletcher-Reeves (else Polak-Ribière) after the first frame")
    precond_data_param: float = param(0.75, "weight of a channel's own energy in the preconditioner", ge=0, le=1)
    precond_reg_param: float = param(0.25, "weight of the regularization in the preconditioner", ge=0, le=1)
    precond_proj_param: float = param(40.0, "weight of P's part of the first frame's preconditioner",
                                      ge=1e-6, le=1e6)
    # bounded so that w² times the samples' energy stays far inside float32 for any target shape
    reg_window_min: float = param(1e-4, "the spatial regularization's least value (at the target's middle)",
                                  ge=1e-10, le=100)
    reg_window_edge: float = param(10e-3, "its value at the target's edge", ge=1e-10, le=100)
    reg_window_power: float = param(2.0, "the window's power of the distance from the middle", gt=0, le=4)
    reg_sparsity_threshold: float = param(0.05, "window DFT coefficients under this x the largest are dropped",
                                          ge=0, lt=1)

    def validate(self):
        """cell_sizes and compressed_dims of equal length."""
        if len(self.cell_sizes) != len(self.compressed_dims):
            return "cell_sizes and compressed_dims need one entry per feature each"
        if not self.cell_sizes:
            return "cell_sizes: at least one feature"
        if not all(1 <= c <= 64 for c in self.cell_sizes) or not all(1 <= d <= 1000 for d in self.compressed_dims):
            return "cell_sizes in [1, 64] and compressed_dims in [1, 1000]"


class ECO(Solver):
    """ECO's factorised convolution, learnt by Gauss-Newton then conjugate gradient."""

    name = "eco"
    terms: tuple[str, ...] = ()
    loop = "continuous"  # configs naming it run in dcfkit.tracker.continuous (continuous_loop)
    Params = ECOParams

    def reset(self) -> None:
        self.filters: list[np.ndarray] = []
        self.projections: list[np.ndarray] = []
        self.energy: list[np.ndarray] = []
        self.cg_state: dict | None = None

    def train(self, xf, yf, w2, theta, fft):
        raise TrackingError("solver 'eco' learns Fourier series of feature blocks: it runs in the continuous loop "
                            "(dcfkit.tracker.continuous), which a config naming it gets")

    def learn_first(self, xs: list[np.ndarray], yfs: list[np.ndarray], projections: list[np.ndarray],
                    regs: list[np.ndarray]) -> list[np.ndarray]:
        """Frame 1: ``xs`` the sample's blocks (C, H, Wh) complex64 (unprojected), the labels'
        half spectra, the initial (PCA) projections and the regularization filters. Learns P
        and the filter jointly; returns the sample projected by the learnt P."""
        self.energy = [(np.abs(z) ** 2).astype(np.float32) for z in (project(x, p) for x, p in zip(xs, projections))]
        self.filters, self.projections = train_joint(xs, yfs, projections, regs, self.energy, self._joint_opts())
        self.cg_state = None
        return [project(x, p) for x, p in zip(xs, self.projections)]

    def _joint_opts(self):
        p = self.params
        return _JointOpts(p.projection_reg, p.init_gn_iterations, p.init_cg_iterations, p.precond_data_param,
                          p.precond_reg_param, p.precond_proj_param)

    def learn(self, sample: list[np.ndarray], samples: list[np.ndarray], weights: np.ndarray,
              yfs: list[np.ndarray], regs: list[np.ndarray]) -> None:
        """A later training frame (ECO's train_filter): this frame's projected ``sample``
        updates the preconditioner's energy; CG from the last filter on the memory's
        ``samples`` (per block (N, D, H, Wh)) with their ``weights`` (N,)."""
        p = self.params
        rate = p.learning_rate
        self.energy = [((1 - rate) * e + rate * np.abs(x) ** 2).astype(np.float32) for e, x in zip(self.energy, sample)]
        w = weights.astype(np.float32)
        rhs = [(np.conj((w[:, None, None, None] * x).sum(axis=0)) * y).astype(np.complex64)
               for x, y in zip(samples, yfs)]
        diag = [preconditioner(e, r, p.precond_data_param, p.precond_reg_param) for e, r in zip(self.energy, regs)]
        forget = (1 - rate) ** p.cg_forgetting_rate
        self.filters, self.cg_state = pcg(lambda f: lhs_filter(f, samples, w, regs), rhs,
                                          lambda r: [ri / mi for ri, mi in zip(r, diag)], inner, self.filters,
                                          p.cg_iterations, p.fletcher_reeves, forget, self.cg_state)

    def scores(self, samples: list[np.ndarray], output: tuple[int, int]) -> np.ndarray:
        """(S, H, W) full centred spectra of the responses of the search ``samples`` (per block
        (S, D, H, W) full centred spectra, projected), summed over blocks on the ``output`` grid."""
        out = np.zeros((samples[0].shape[0],) + tuple(output), np.complex64)
        for x, f in zip(samples, self.filters):
            padded_into_full(out, (full(f)[None] * x).sum(axis=1))
        return out


def padded_into_full(target: np.ndarray, block: np.ndarray) -> None:
    """Add a full centred spectrum into a larger one at the same frequencies."""
    py = (target.shape[-2] - block.shape[-2]) // 2
    px = (target.shape[-1] - block.shape[-1]) // 2
    target[..., py:target.shape[-2] - py, px:target.shape[-1] - px] += block


@dataclasses.dataclass(frozen=True)
class _JointOpts:
    projection_reg: float
    init_gn_iterations: int
    init_cg_iterations: int
    precond_data_param: float
    precond_reg_param: float
    precond_proj_param: float


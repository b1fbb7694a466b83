"""Filter solvers (``solver:`` in a config): train each frame's filter and detect with it.

* :mod:`.base` -- the :class:`Solver` contract;
* :mod:`.strcf_bacf` -- the ADMM for the spatially and temporally regularized objective
  (``admm``, Eqs. 4–11) and its two solvers, ``admm_strcf`` (STRCF, DR²Track) and
  ``admm_bacf`` (BACF's running sample model); the module is not named ``admm``, the function
  this package exports under that name;
* :mod:`.arcf` -- ``admm_arcf``, BACF's with ARCF's aberrance repression term;
* :mod:`.autotrack` -- ``admm_autotrack``, STRCF's with AutoTrack's θ-step;
* :mod:`.kernels` -- the ADMM's per-frequency arithmetic, compiled (numba) on first use;
* :mod:`.kcf` -- ``kernel_ridge``: KCF's kernelized ridge regression (Gaussian, linear or
  polynomial kernel);
* :mod:`.dsst` -- ``ridge``: DSST's multichannel ridge regression in closed form;
* :mod:`.eco` -- ``eco``: ECO's factorised convolution (:mod:`.eco_joint`: the first frame's
  Gauss-Newton; :mod:`.eco_cg`: conjugate gradient and the regularization filter), run by
  the continuous loop (:mod:`dcfkit.tracker.continuous`).
* :mod:`.csr` -- ``admm_csr``: CSR-DCF's per-channel filter constrained to a mask.
"""
from __future__ import annotations

from dcfkit.components.solvers.arcf import ADMMArcf, ARCFParams
from dcfkit.components.solvers.autotrack import ADMMAutoTrack, AutoTrackParams
from dcfkit.components.solvers.base import Solver
from dcfkit.components.solvers.csr import ADMMCsr, CSRParams, csr_filter
from dcfkit.components.solvers.dsst import Ridge, RidgeParams
from dcfkit.components.solvers.eco import ECO, ECOParams
from dcfkit.components.solvers.kcf import KernelParams, KernelRidge, kernel_correlation
from dcfkit.components.solvers.strcf_bacf import (
    ADMMBacf,
    ADMMParams,
    ADMMStrcf,
    BACFParams,
    admm,
    penalties,
    schedule_problem,
    sherman_morrison_solve,
)

BUILTIN = (ADMMStrcf, ADMMBacf, ADMMArcf, ADMMAutoTrack, KernelRidge, Ridge, ECO, ADMMCsr)

__all__ = ["ADMMArcf", "ADMMAutoTrack", "ADMMBacf", "ADMMCsr", "ADMMParams", "ADMMStrcf", "ARCFParams",
           "AutoTrackParams", "BACFParams", "BUILTIN", "CSRParams", "ECO", "ECOParams", "KernelParams",
           "KernelRidge", "Ridge", "RidgeParams", "Solver", "admm", "csr_filter", "kernel_correlation",
           "penalties", "schedule_problem", "sherman_morrison_solve"]

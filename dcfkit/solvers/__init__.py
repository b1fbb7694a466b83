"""Filter solvers (``solver:`` in a config): train each frame's filter and detect with it.

* :mod:`.base` -- the :class:`Solver` contract;
* :mod:`.admm` -- ADMM for the spatially and temporally regularized objective (Eqs. 4–11):
  ``admm_strcf`` (STRCF, DR²Track) and ``admm_bacf`` (BACF's running sample model);
* :mod:`.kernels` -- the ADMM's per-frequency arithmetic, compiled (numba) on first use;
* :mod:`.kernel` -- ``kernel_ridge``: KCF's kernelized ridge regression (Gaussian, linear or
  polynomial kernel);
* :mod:`.ridge` -- ``ridge``: DSST's multichannel ridge regression in closed form.
"""
from __future__ import annotations

from .admm import ADMMBacf, ADMMParams, ADMMStrcf, BACFParams, admm, penalties, schedule_problem, \
    sherman_morrison_solve
from .base import Solver
from .kernel import KernelParams, KernelRidge, kernel_correlation
from .ridge import Ridge, RidgeParams

BUILTIN = (ADMMStrcf, ADMMBacf, KernelRidge, Ridge)

__all__ = ["ADMMBacf", "ADMMParams", "ADMMStrcf", "BACFParams", "BUILTIN", "KernelParams", "KernelRidge", "Ridge",
           "RidgeParams", "Solver", "admm", "kernel_correlation", "penalties", "schedule_problem",
           "sherman_morrison_solve"]

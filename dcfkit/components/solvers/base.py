"""The solver's contract: what the tracker gives a solver and what it gets back."""
from __future__ import annotations

import numpy as np

from dcfkit.components.base import Component, Contract
from dcfkit.contracts import array, finite_arrays
from dcfkit.numerics.response import response as linear_response


class Solver(Component, declares="solver"):
    """Trains the filter of one frame and, optionally, detects with it. State between frames
    lives in the solver instance.

    The tracker calls ``reset()`` at every ``init`` (a new target; also once on construction),
    then ``train`` once per training frame; on every later frame it calls ``response`` for the
    response maps of the search samples (Eq. 12) and ``observe`` with what the detection saw,
    before training. A solver declares its own ``Params`` (none by default); the ADMM
    solvers' are :class:`ADMMParams`.

    ``terms`` names the regularizers whose terms ``train`` solves with (w² for 'spatial', θ
    for 'temporal'); the tracker refuses a config that gives the solver a regularizer it
    has no term for, instead of ignoring it (KCF's and DSST's closed forms have neither).
    ``full_spectra`` says whether it also takes whole complex spectra (``tracker.spectra:
    full``, DR²Track's code); the others are given half spectra of real maps.
    """

    terms: tuple[str, ...] = ("spatial", "temporal")
    # whether train and response also work on whole complex spectra (tracker.spectra: full)
    full_spectra: bool = False
    # the filter of the last train's sample alone, before any average over frames (CSR-DCF's
    # H_new, which channel weights learn from); None: the filter train returned
    frame_filter: np.ndarray | None = None
    contract = Contract(required={"reset": (), "train": ("xf", "yf", "w2", "theta", "fft")},
                        optional={"response": ("hf", "samples", "shape", "fft"), "observe": ("detection",)},
                        # a response that is not finite is the tracker's to say: the filter overflowed
                        returns={"train": finite_arrays,
                                 "response": array(lambda args, s: (len(args[1]), *args[2]), finite=False)})

    def __init__(self, params=None):
        super().__init__(params)
        self.reset()

    def reset(self) -> None:
        """Forget everything learnt (called by the tracker's init)."""
        raise NotImplementedError

    def train(self, xf: np.ndarray, yf: np.ndarray, w2: np.ndarray, theta: float, fft) -> np.ndarray:
        """One frame: sample (C, H, Wr), label spectrum (H, Wr), w² (H, W), θ -> filter (C, H, Wr)."""
        raise NotImplementedError

    def response(self, hf: np.ndarray, samples: np.ndarray, shape: tuple[int, int], fft) -> np.ndarray:
        """Eq. (12): the last ``train``'s filter and (S, C, H, Wr) search samples -> (S, H, W)
        float32 response maps (circular layout). The linear correlation unless overridden (KCF's
        kernel)."""
        return linear_response(hf, samples, shape, fft)

    def observe(self, detection) -> None:
        """What the detection of this frame saw (a :class:`dcfkit.components.labels.base.Detection`), before the
        frame's ``train``; the built-in ADMM solvers keep nothing of it (ARCF's keeps the map)."""

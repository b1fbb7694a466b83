"""The scale kind: the scale factors searched, and the scale of each frame's target."""
from __future__ import annotations

import math

import numpy as np

from dcfkit.components.base import Component, Contract
from dcfkit.contracts import scalar, search_factors


def _note_limits(value, args, estimator) -> None:
    """``init``'s check: nothing to check in what it returns; it notes the limits the tracker
    gave, which ``update``'s scale must respect (:func:`_within_limits`)."""
    estimator.__dict__["_contract_limits"] = tuple(float(v) for v in args[4])


def _within_limits(value, args, estimator) -> str | None:
    """``update``'s scale: a number > 0, within the ``limits`` ``init`` was given."""
    problem = scalar(0, math.inf, above=True)(value, args, estimator)
    limits = estimator.__dict__.get("_contract_limits")
    tolerance = 1e-9  # the built-ins clip to the limits; a rounding may land a hair outside
    if problem is None and limits is not None and not (limits[0] * (1 - tolerance) <= float(value)
                                                       <= limits[1] * (1 + tolerance)):
        problem = f"{float(value)!r}, outside the limits [{limits[0]:g}, {limits[1]:g}] given to init"
    return problem


class ScaleEstimator(Component, declares="scale"):
    """The target's scale. The tracker calls ``init`` at every ``init`` (a new target),
    ``search_factors()`` at the start of every later frame, and ``update`` once the target is
    found on it (not on a held blank frame), which returns the new scale within ``limits``."""

    contract = Contract(optional={"init": ("image", "centre", "base_target", "scale", "limits"),
                                  "search_factors": (), "update": ("image", "centre", "scale")},
                        returns={"init": _note_limits, "search_factors": search_factors, "update": _within_limits})

    def init(self, image: np.ndarray, centre: np.ndarray, base_target: np.ndarray, scale: float,
             limits: tuple[float, float]) -> None:
        """First frame: target centre (y, x), size at scale 1 (h, w), current scale, (min, max) scale."""
        self.base_target = np.asarray(base_target, dtype=float)
        self.limits = limits

    def search_factors(self) -> np.ndarray:
        """Relative scales at which the translation filter is evaluated."""
        return np.ones(1)

    def update(self, image: np.ndarray, centre: np.ndarray, scale: float) -> float:
        """After translation: the new scale (``scale`` already includes the chosen search factor)."""
        return float(np.clip(scale, *self.limits))


def scale_factors(n: int, step: float) -> np.ndarray:
    """``n`` relative scales ``step`` apart, centred on 1: step ** (k - (n - 1) / 2)."""
    return step ** (np.arange(n) - (n - 1) / 2)


MAX_SCALES = 101  # n_scales of either estimator: beyond it the samples stop fitting in memory


MIN_LAM = 1e-10  # the DSST's λ, as the ADMM's penalty γ (solvers.PENALTY_RANGE)


def check_span(n: int, step: float) -> str | None:
    """The span both estimators share: at most x10 each way (beyond it the samples stop fitting
    in memory)."""
    if (n - 1) / 2 * math.log(step) > math.log(10):
        return (f"step={step:g} with n_scales={n}: the scales may span at most x10 each way "
                f"(step ** ((n_scales - 1) / 2) <= 10)")


def scale_limits(base_target: np.ndarray, base_region: np.ndarray, image_shape, initial: float | None = None,
                 min_pixels: float = 5.0, step: float | None = None) -> tuple[float, float]:
    """(min, max) scale: the search region keeps ≥ ``min_pixels`` px; the target fits in the image,
    unless it is larger at the ``initial`` scale (a box longer than the image keeps its size).
    With a ``step``, each limit is rounded inwards to a whole power of it, as the authors' codes
    do (``scale_step ^ ceil(log(max(5 ./ sz)) / log(scale_step))``, ``floor`` for the largest)."""
    lo = np.max(min_pixels / np.asarray(base_region, dtype=float))
    hi = np.min(np.asarray(image_shape[:2], dtype=float) / np.asarray(base_target, dtype=float))
    if step is not None:
        lo = step ** math.ceil(math.log(lo) / math.log(step))
        hi = step ** math.floor(math.log(hi) / math.log(step))
    if initial is not None:
        hi = max(hi, initial)
    return float(lo), float(max(hi, lo))

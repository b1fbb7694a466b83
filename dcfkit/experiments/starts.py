"""Whether a tracker can start from a box: the rule every experiment applies to its starts
(docs/evaluation.md, "Runs that cannot start")."""
from __future__ import annotations

from typing import NamedTuple

import numpy as np

from dcfkit.datasets import DatasetError, Sequence

__all__ = ["Plan", "plan_runs", "start_problem"]


def start_problem(box, image_size: tuple[int, int]) -> str | None:
    """Why no tracker can start from the 0-based ``box`` ``(x, y, w, h)`` in an image of
    ``image_size`` ``(height, width)``: NaN or infinite, no width or height, or no pixel of
    the image inside it (a phrase: "has no width"); None if one can."""
    x, y, w, h = (float(v) for v in np.asarray(box, dtype=np.float64).reshape(4))
    height, width = image_size
    if not np.isfinite([x, y, w, h]).all():
        return "is NaN or infinite"
    if w <= 0 or h <= 0:
        return f"has no {'width' if w <= 0 else 'height'}"
    if x >= width or y >= height or x + w <= 0 or y + h <= 0:
        return f"lies outside the {width}x{height} image"
    return None


class Plan(NamedTuple):
    """The runs of one sequence: those that start, and those left out (run name -> why)."""

    runs: list[Sequence]
    left_out: dict[str, str]


def plan_runs(seq: Sequence, candidates: list[tuple[Sequence, str]], experiment: str,
              image_size: tuple[int, int]) -> Plan:
    """The :class:`Plan` of ``candidates``, ``(run, what it is)``, in images of ``image_size``
    ``(height, width)`` (frame 1's: a sequence's frames share it); a :class:`DatasetError` if
    none can start."""
    runs, left_out = [], {}
    for run, what in candidates:
        problem = start_problem(run.init_box, image_size)
        if problem is None:
            runs.append(run)
        else:
            box = ", ".join(f"{v:g}" for v in run.init_box)
            left_out[run.name] = f"{experiment} run {run.name!r} ({what}) cannot start: its box ({box}) {problem}"
    if not runs:
        raise DatasetError(f"sequence {seq.name!r}: no {experiment} run can start; {next(iter(left_out.values()))}")
    return Plan(runs, left_out)

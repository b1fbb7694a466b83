"""How a run's speed was measured, so that fps is shown as a score only when it means one.

Runs that share the cores with other runs of the same command (``--jobs`` above 1, a dask
cluster, or the runs of a sequence tracked in lockstep: :mod:`dcfkit.running.lockstep`) are
timed while they compete for the CPU and its caches: a variant doing more work
read 36 fps against its base's 25 in such a pool. Each run's sidecar records ``timing``
(:func:`timing_record`); a report shows fps only for runs timed alone (:func:`fps_note` says
why the others are left out). Sidecars written before the record have no ``timing``: how they
were measured is not known.
"""
from __future__ import annotations

from typing import Iterable, Mapping

ALONE, SHARED, UNKNOWN = "alone", "shared", "unknown"
ADVICE = "fps is a score only when measured alone: python benchmarks/speed.py, or a one-pass dcfkit eval --jobs 1"


def timing_record(executor: str, workers: int | None) -> dict:
    """A run's ``timing``: the ``executor`` (``local`` or ``dask``), how many runs of the command
    ran at once (``workers``; None for a dask scheduler's cluster, whose size is not known here),
    and whether it ran ``alone``."""
    return {"executor": executor, "workers": workers, "alone": workers == 1}


def how_measured(timing) -> str:
    """:data:`ALONE`, :data:`SHARED` or :data:`UNKNOWN` (no record, or not one dcfkit writes)."""
    alone = timing.get("alone") if isinstance(timing, Mapping) else None
    if not isinstance(alone, bool):
        return UNKNOWN
    return ALONE if alone else SHARED


def combined(kinds: Iterable[str | None]) -> str | None:
    """How a mean over runs was measured: alone only if every run was; shared if any was;
    else unknown. None when no run has a time."""
    found = {k for k in kinds if k is not None}
    for kind in (SHARED, UNKNOWN, ALONE):
        if kind in found:
            return kind
    return None


def fps_note(rows: Iterable[Mapping], name: str = "tracker") -> str | None:
    """One line saying whose fps a table leaves out and why, or None when none is left out;
    ``rows`` are overall rows with ``fps_measured`` (:func:`combined`) and ``name``."""
    rows = list(rows)
    shared = [str(r[name]) for r in rows if r.get("fps_measured") == SHARED]
    unknown = [str(r[name]) for r in rows if r.get("fps_measured") == UNKNOWN]
    if not shared and not unknown:
        return None
    parts = []
    if shared:
        parts.append(f"{', '.join(shared)} (measured with other runs sharing the CPU: --jobs above 1, dask, "
                     f"or TRE's and SRE's runs of a sequence tracked in lockstep)")
    if unknown:
        parts.append(f"{', '.join(unknown)} (not known how measured: results from before dcfkit recorded it)")
    return f"fps not shown for {'; nor for '.join(parts)}. {ADVICE}."

"""Which loop runs a config: the discrete one (:class:`dcfkit.tracker.tracker.Tracker`), or
the continuous one for solvers that declare ``loop = "continuous"`` (ECO's)."""
from __future__ import annotations

from typing import Any, Mapping

from dcfkit.registry import get_registry


def continuous_loop(config: Mapping[str, Any]) -> type | None:
    """The continuous loop's class if ``config``'s solver runs in it, else None (an unknown
    solver too: the tracker's own checks name it)."""
    solver = config.get("solver") if isinstance(config, Mapping) else None
    name = solver.get("name") if isinstance(solver, Mapping) else None
    registry = get_registry()
    if not isinstance(name, str) or name not in registry.names("solver"):
        return None
    if getattr(registry.entry("solver", name).cls, "loop", "discrete") != "continuous":
        return None
    from dcfkit.tracker.continuous import ContinuousTracker  # cycle: it subclasses Tracker

    return ContinuousTracker

"""Warm start: the base config as trial 0 of every study, placed in the space (docs/search.md)."""
from __future__ import annotations

from typing import Any

from optuna.distributions import BaseDistribution, IntDistribution

from dcfkit.autosearch.space import SearchSpec, active, resolve
from dcfkit.config.overrides import get_dotted


def base_params(spec: SearchSpec) -> dict[str, Any]:
    """The base config as a point of the space: each dimension sampled under the base's choices
    at the base's value (a choice's label whose value leaves the base as it is; a number the
    base holds inside the range). Empty when some dimension has no such value: the base lies
    outside the space, and the trial that runs it is known to TPE by its score alone."""
    params: dict[str, Any] = {}
    for p in spec.parameters:
        if not active(p, params):
            continue
        if p.choices:
            found = [label for label, value in p.choices.items()
                     if resolve(spec.base, spec.parameters, {**params, p.key: label}) == spec.base]
        else:
            held = get_dotted(spec.base, p.key)
            kind = int if isinstance(p.distribution, IntDistribution) else float
            found = [kind(held)] if _inside(p.distribution, held) else []
        if not found:
            return {}
        params[p.key] = found[0]
    return params if resolve(spec.base, spec.parameters, params) == spec.base else {}


def _inside(distribution: BaseDistribution, value: Any) -> bool:
    """Whether a number ``value`` is one the range ``distribution`` samples."""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return False
    if isinstance(distribution, IntDistribution) and value != int(value):
        return False
    return distribution.low <= value <= distribution.high

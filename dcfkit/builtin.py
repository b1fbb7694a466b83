"""dcfkit's own components, registered through the same hook as any plugin."""
from __future__ import annotations

from . import features, labels, regularizers, scale, search, solvers
from .registry import hookimpl


@hookimpl
def dcfkit_register_components(registry):
    for module in (features, labels, regularizers, solvers, search, scale):
        for cls in module.BUILTIN:
            registry.register(cls)

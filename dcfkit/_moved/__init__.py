"""The modules that moved in 0.7, under their old names for one release (they go in 0.8).

``dcfkit.__path__`` lists this folder, so ``import dcfkit.results`` finds ``results.py`` here:
it warns, then puts the module's new home in its place, so old and new names are one module.
"""
from __future__ import annotations

import sys
import warnings
from types import ModuleType


def alias(old: str, module: ModuleType) -> None:
    """Make ``old`` (and its loaded submodules) name ``module``, with a DeprecationWarning."""
    warnings.warn(f"{old} moved to {module.__name__} in dcfkit 0.7; the old name goes in 0.8",
                  DeprecationWarning, stacklevel=3)
    prefix = module.__name__ + "."
    for name, loaded in list(sys.modules.items()):
        if name.startswith(prefix):
            sys.modules.setdefault(old + name[len(module.__name__):], loaded)
    sys.modules[old] = module

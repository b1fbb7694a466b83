"""dcfkit's own plugin, loaded through its entry point like any other: its components, and
how the registry makes benchmark layouts."""
from __future__ import annotations

import pluggy

from dcfkit.components import (
    channel_weights, features, labels, masks, memory, redetect, regularizers, reliability, scale, schedule, search,
    solvers,
)
from dcfkit.datasets.layout import new_layout

# dcfkit.registry.hookimpl, made here too: this module, which the registry loads, imports nothing of it
hookimpl = pluggy.HookimplMarker("dcfkit")


@hookimpl
def dcfkit_register_components(registry):
    registry.accept_layouts(new_layout)
    for family in (features, labels, regularizers, solvers, search, scale, memory, schedule, masks, channel_weights,
                   reliability, redetect):
        for cls in family.BUILTIN:
            registry.register(cls)

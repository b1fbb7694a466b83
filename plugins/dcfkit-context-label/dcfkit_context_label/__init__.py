"""dcfkit plugin: the ``context_aware`` label (Mueller et al., CVPR 2017)."""
from dcfkit.registry import hookimpl


@hookimpl
def dcfkit_register_components(registry):
    from .label import ContextAware  # imported on first use of the registry, not at dcfkit import

    registry.register(ContextAware)

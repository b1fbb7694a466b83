"""dcfkit: discriminative correlation filter trackers assembled from registered components."""
from __future__ import annotations

# part of every run key (dcfkit.store.provenance.run_key): bump it when boxes change (docs/changes.md)
__version__ = "0.17.1"

__all__ = ["__version__", "load_tracker", "load_config", "Tracker"]


def __getattr__(name):  # lazy: importing dcfkit does no work
    if name in ("load_tracker", "Tracker"):
        from dcfkit import tracker  # lazy: importing dcfkit loads no tracker code

        return getattr(tracker, name)
    if name == "load_config":
        from dcfkit.config import load_config  # lazy, as above

        return load_config
    raise AttributeError(f"module 'dcfkit' has no attribute {name!r}")

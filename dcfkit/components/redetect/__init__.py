"""Re-detection (``redetect:`` in a config; none by default): where to look for a target the
reliability component says is lost, and which candidate to take.

* :mod:`.base` -- the :class:`Redetect` contract;
* :mod:`.grid` -- ``grid``: search regions on a grid around the last reliable position, a few
  a frame, nearest first (a local-to-global search in the manner of LCT, Ma et al., CVPR 2015,
  with the tracker's own filter).

Where to add one: subclass :class:`~dcfkit.components.redetect.base.Redetect`."""
from __future__ import annotations

from dcfkit.components.redetect.base import Redetect
from dcfkit.components.redetect.grid import Grid, grid_offsets

BUILTIN = (Grid,)

__all__ = ["BUILTIN", "Grid", "Redetect", "grid_offsets"]

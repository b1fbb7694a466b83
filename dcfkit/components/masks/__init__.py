"""Spatial masks (``mask:`` in a config; none by default): where the filter may be non-zero,
learnt each training frame.

* :mod:`.base` -- the :class:`Mask` contract;
* :mod:`.segmentation` -- CSR-DCF's colour histograms, spatial prior and MRF posterior;
* :mod:`.csr` -- ``csr_segmentation``: CSR-DCF's spatial reliability map.
"""
from __future__ import annotations

from dcfkit.components.masks.base import Mask
from dcfkit.components.masks.csr import CSRSegmentation, box_mask

BUILTIN = (CSRSegmentation,)

__all__ = ["BUILTIN", "CSRSegmentation", "Mask", "box_mask"]

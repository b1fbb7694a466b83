"""Channel weights (``channel_weights:`` in a config; none by default): how much each feature
channel's response counts at detection.

* :mod:`.base` -- the :class:`ChannelWeights` contract;
* :mod:`.reliability` -- ``csr_reliability``: CSR-DCF's learning and detection reliability.
"""
from __future__ import annotations

from dcfkit.components.channel_weights.base import ChannelWeights
from dcfkit.components.channel_weights.reliability import CSRReliability, detection_reliability, maxima_values

BUILTIN = (CSRReliability,)

__all__ = ["BUILTIN", "CSRReliability", "ChannelWeights", "detection_reliability", "maxima_values"]

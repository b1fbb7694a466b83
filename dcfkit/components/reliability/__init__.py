"""Reliability (``reliability:`` in a config; none by default): how sure a detection is that it
found the target. A score of 1 is the component's threshold: at or above it the frame is
reliable. The score is the presence score the tracker writes (:mod:`dcfkit.tracker.confidence`);
gated learning (the ``reliable`` schedule) and re-detection (``redetect:``) act on the verdict.

* :mod:`.base` -- the :class:`Reliability` contract;
* :mod:`.measures` -- ``lmcf`` (peak and APCE against their history, Wang et al., CVPR 2017) and
  ``psr`` (MOSSE's peak-to-sidelobe ratio, Bolme et al., CVPR 2010).

Where to add one: subclass :class:`~dcfkit.components.reliability.base.Reliability`."""
from __future__ import annotations

from dcfkit.components.reliability.base import RELIABLE, Reliability, unreliable
from dcfkit.components.reliability.measures import LMCF, PSR, peak_to_sidelobe

BUILTIN = (LMCF, PSR)

__all__ = ["BUILTIN", "LMCF", "PSR", "RELIABLE", "Reliability", "peak_to_sidelobe", "unreliable"]

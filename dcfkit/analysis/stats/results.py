"""Typed statistics: a mean with its interval, a paired difference, its Holm-corrected p, and a
comparison of trackers with a baseline (:func:`dcfkit.analysis.statistics.versus_baseline`).

Each serialises to the keys report.json, summary.json and the others have always held
(:meth:`Interval.as_record`) and reads them back (:meth:`Interval.from_record`: a JSON file's
None for NaN included). ``extra`` holds the values of statistics added to the declaration
(:mod:`dcfkit.analysis.stats.columns`), serialised after the built-in ones.
"""
from __future__ import annotations

import dataclasses
from typing import Any, Mapping


@dataclasses.dataclass(frozen=True)
class Interval:
    """A mean over ``n`` sequences and its bootstrap confidence interval (NaN with fewer than two)."""

    mean: float
    ci_low: float
    ci_high: float
    n: int
    extra: Mapping[str, Any] = dataclasses.field(default_factory=dict, kw_only=True)

    def as_record(self) -> dict:
        """The fields as a dict, in their order (``mean``, ``ci_low``, ...), then ``extra``."""
        return {**{f.name: getattr(self, f.name) for f in dataclasses.fields(self) if f.name != "extra"},
                **self.extra}

    @classmethod
    def from_record(cls, record: Mapping):
        """The object :meth:`as_record` gave ``record``; keys that are no field go to ``extra``."""
        names = {f.name for f in dataclasses.fields(cls)} - {"extra"}
        return cls(**{k: record[k] for k in names}, extra={k: v for k, v in record.items() if k not in names})


@dataclasses.dataclass(frozen=True)
class Difference(Interval):
    """A paired difference A - B: its mean and interval, the Wilcoxon p, and the sequences
    where A scored higher (``won``), lower (``lost``) or the same (``tied``)."""

    wilcoxon_p: float
    won: int
    lost: int
    tied: int


@dataclasses.dataclass(frozen=True)
class Corrected(Difference):
    """A :class:`Difference` with its Wilcoxon p Holm-corrected across a family of comparisons
    (``holm_p``) and whether the comparison counts as ``significant``."""

    holm_p: float
    significant: bool

    @classmethod
    def of(cls, difference: Difference, holm_p: float, significant: bool) -> "Corrected":
        fields = {f.name: getattr(difference, f.name) for f in dataclasses.fields(Difference)}
        return cls(**fields, holm_p=holm_p, significant=significant)


@dataclasses.dataclass(frozen=True)
class Comparison:
    """Trackers compared with a ``baseline`` over ``sequences`` sequences: ``means`` (tracker ->
    score -> :class:`Interval`), ``differences`` (each other tracker -> score -> :class:`Corrected`)
    and ``non_finite`` (tracker -> score -> the sequences left out for a non-finite score; only
    those with any); ``method`` and ``correction`` say how they were computed."""

    method: str
    correction: str
    baseline: str
    sequences: int
    means: dict[str, dict[str, Interval]]
    differences: dict[str, dict[str, Corrected]]
    non_finite: dict[str, dict[str, list[str]]]

    @property
    def scores(self) -> list[str]:
        """The scores compared, in order."""
        return list(next(iter(self.means.values()), {}))

    def as_record(self) -> dict:
        """The plain data report.json holds: each interval and difference as its record."""
        return {"method": self.method, "correction": self.correction, "baseline": self.baseline,
                "sequences": self.sequences,
                "means": {t: {k: m.as_record() for k, m in found.items()} for t, found in self.means.items()},
                "differences": {t: {k: d.as_record() for k, d in found.items()}
                                for t, found in self.differences.items()},
                "non_finite": self.non_finite}

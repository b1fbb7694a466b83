"""The one declaration of the statistics every output shows: :data:`COLUMNS`, in order.

A :class:`Column` is one statistic of a tracker's scores (level :data:`MEAN`, read from an
:class:`~dcfkit.analysis.stats.results.Interval`) or of a pair's paired differences (level
:data:`DIFFERENCE`, read from a :class:`~dcfkit.analysis.stats.results.Difference`, Holm-corrected
as a :class:`~dcfkit.analysis.stats.results.Corrected` where a family is compared). Its
:class:`Cell` per format says its header and how it shows; a format it has no cell for does not
show it. The formats and the renderers that draw from them:

* ``text``: ``statistics.txt`` and the terminal (:func:`dcfkit.analysis.tables.statistics_lines`),
* ``pair``: ``dcfkit compare`` (:func:`dcfkit.analysis.tables.comparison_lines`),
* ``latex``: ``overall.tex`` and ``summary.tex`` (:func:`dcfkit.analysis.latex.comparison_table`),
* ``html``: the report pages' statistics table (:func:`dcfkit.analysis.report_html.sections.statistics_table`),
* ``search``: a search's ``summary.md`` (:func:`dcfkit.autosearch.summary.summary_lines`).

The JSON files and the flat tables (:func:`dcfkit.analysis.tables.statistics_rows`: text,
Markdown, CSV) hold each result's record, built-in fields then ``extra``. A statistic added here
gives a ``compute`` function (its own module): ``compute(x)`` of a tracker's finite scores
``(n,) float64`` (MEAN) or ``compute(a, b)`` of the paired finite scores (DIFFERENCE); its value
lands in the result's ``extra`` under the column's ``key`` (:func:`computed`), and every
renderer shows it where it has a cell.
"""
from __future__ import annotations

import dataclasses
import math
from typing import Any, Callable, Mapping

import numpy as np

MEAN, DIFFERENCE = "mean", "difference"
FORMATS = ("text", "pair", "latex", "html", "search")
LOWER_IS_BETTER = frozenset({"failures"})  # scores whose won and lost sequences are those with fewer


@dataclasses.dataclass(frozen=True)
class Cell:
    """How a column shows in one format. ``render(result, score)``: the cell (text; for ``html``
    the value the page draws), given the typed result and the score's key (``auc``); ``header``:
    its header, where ``{score}`` is the score's label and ``{baseline}`` the baseline's name (raw
    LaTeX in ``latex``; ``text`` and ``pair`` cells carry their words and separator themselves);
    ``place``: a format's columns go by (place, declaration order); ``key`` and ``kind``: the
    ``html`` column's key (``{score}``: the score's key) and type (``interval``: drawn as a bar)."""

    render: Callable[[Any, str], Any]
    header: str = ""
    place: int = 0
    key: str = ""
    kind: str = "num"


@dataclasses.dataclass(frozen=True)
class Column:
    """One statistic: its ``key`` (its record's key, when ``compute`` makes it), its ``level``
    (:data:`MEAN` or :data:`DIFFERENCE`), its ``cells`` (format -> :class:`Cell`) and, for one
    added to the built-ins, the ``compute`` function whose value goes in ``extra[key]``."""

    key: str
    level: str
    cells: Mapping[str, Cell]
    compute: Callable[..., Any] | None = None

    def __post_init__(self):
        if self.level not in (MEAN, DIFFERENCE):
            raise ValueError(f"statistic {self.key!r}: level must be {MEAN!r} or {DIFFERENCE!r}, got {self.level!r}")
        unknown = sorted(set(self.cells) - set(FORMATS))
        if unknown:
            raise ValueError(f"statistic {self.key!r}: no format {', '.join(unknown)} (formats: {', '.join(FORMATS)})")


def finite(value) -> bool:
    """Whether ``value`` is a finite number (a JSON file's None and NaN are not)."""
    return isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)


def number(value, form: str) -> str:
    """``value`` as ``form`` gives it; ``n/a`` when it is no finite number."""
    return format(value, form) if finite(value) else "n/a"


def interval_text(interval, signed: bool = False) -> str:
    """``0.452 [0.401, 0.498]``: a mean and its confidence interval (none: the mean alone)."""
    fmt = "{:+.3f}" if signed else "{:.3f}"
    bounds = (f" [{fmt.format(interval.ci_low)}, {fmt.format(interval.ci_high)}]"
              if math.isfinite(interval.ci_low) and math.isfinite(interval.ci_high) else "")
    return fmt.format(interval.mean) + bounds


def interval_cell(interval, signed: bool = False) -> str:
    r"""``0.452 {\scriptsize [0.401, 0.498]}`` (signed: in math mode, with real minus signs); ``--``
    for none or a mean that is no number."""
    if interval is None or not finite(interval.mean):
        return "--"
    show = (lambda v: f"${v:+.3f}$") if signed else (lambda v: f"{v:.3f}")
    text = show(interval.mean)
    if finite(interval.ci_low) and finite(interval.ci_high):
        text += rf" {{\scriptsize [{show(interval.ci_low)}, {show(interval.ci_high)}]}}"
    return text


def _latex_p(d, score: str) -> str:
    """The Wilcoxon p, ``$^{*}$`` where significant after Holm's correction."""
    p = d.wilcoxon_p
    text = "--" if not finite(p) else "$<$0.001" if p < 0.001 else f"{p:.3f}"
    return text + ("$^{*}$" if getattr(d, "significant", False) and finite(p) else "")


def _latex_wins(d, score: str) -> str:
    """Won/tied/lost; of a score in :data:`LOWER_IS_BETTER` the won are those with fewer."""
    won, lost = (d.lost, d.won) if score in LOWER_IS_BETTER else (d.won, d.lost)
    return f"{won}/{d.tied}/{lost}"


def bar(interval) -> list:
    """[mean, low, high, significant] of an interval, as the HTML page draws it (None where undefined)."""
    value = lambda v: v if v is not None and math.isfinite(v) else None  # noqa: E731
    return [value(interval.mean), value(interval.ci_low), value(interval.ci_high),
            bool(getattr(interval, "significant", False))]


COLUMNS: list[Column] = [
    Column("interval", MEAN, {
        "text": Cell(lambda m, score: interval_text(m)),
        "pair": Cell(lambda m, score: interval_text(m)),
        "latex": Cell(lambda m, score: interval_cell(m), header="Mean [CI]"),
        "html": Cell(lambda m, score: bar(m), header="{score}", key="{score}_ci", kind="interval"),
        "search": Cell(lambda m, score: number(m.mean, ".4f"), header="{score}")}),
    Column("difference", DIFFERENCE, {
        "text": Cell(lambda d, score: interval_text(d, signed=True)),
        "pair": Cell(lambda d, score: interval_text(d, signed=True)),
        "latex": Cell(lambda d, score: interval_cell(d, signed=True), header=r"$\Delta$ [CI]"),
        "html": Cell(lambda d, score: bar(d), header="{score} \u2212 {baseline}", key="d_{score}", kind="interval"),
        "search": Cell(lambda d, score: number(d.mean, "+.4f"), header="search \u2212 baseline")}),
    Column("difference_ci", DIFFERENCE, {
        "search": Cell(lambda d, score: f"[{number(d.ci_low, '+.4f')}, {number(d.ci_high, '+.4f')}]",
                       header="95% CI")}),
    Column("wilcoxon_p", DIFFERENCE, {
        "text": Cell(lambda d, score: f", Wilcoxon p {d.wilcoxon_p:.3g}"),
        "pair": Cell(lambda d, score: f"   Wilcoxon p {d.wilcoxon_p:.3g}"),
        "latex": Cell(_latex_p, header="$p$"),
        "search": Cell(lambda d, score: number(d.wilcoxon_p, ".3f"), header="Wilcoxon p", place=1)}),
    Column("holm_p", DIFFERENCE, {
        "text": Cell(lambda d, score: f" (Holm {d.holm_p:.3g})"),
        "html": Cell(lambda d, score: d.holm_p, header="{score} Holm p", key="{score}_holm_p"),
        "search": Cell(lambda d, score: number(d.holm_p, ".3f"), header="Holm p", place=1)}),
    Column("significant", DIFFERENCE, {
        "text": Cell(lambda d, score: " *" if d.significant else ""),
        "search": Cell(lambda d, score: "yes" if d.significant else "no", header="beaten", place=1)}),
    Column("won_lost_tied", DIFFERENCE, {
        "text": Cell(lambda d, score: f", won {d.won}, lost {d.lost}, tied {d.tied}", place=1),
        "pair": Cell(lambda d, score: f"   won {d.won}, lost {d.lost}, tied {d.tied} of {d.n}"),
        "latex": Cell(_latex_wins, header="W/T/L"),
        "search": Cell(lambda d, score: f"{d.won} / {d.lost} / {d.tied}", header="won / lost / tied")}),
]


def register(column: Column) -> Column:
    """Add ``column`` to :data:`COLUMNS` (after those there); a ValueError if its key is taken."""
    if any(c.key == column.key for c in COLUMNS):
        raise ValueError(f"statistic {column.key!r} is declared already")
    COLUMNS.append(column)
    return column


def shown(level: str, fmt: str) -> list[tuple[Column, Cell]]:
    """The columns of ``level`` that ``fmt`` shows, with their cells, in the format's order."""
    found = [(i, c, c.cells[fmt]) for i, c in enumerate(COLUMNS) if c.level == level and fmt in c.cells]
    return [(c, cell) for _, c, cell in sorted(found, key=lambda f: (f[2].place, f[0]))]


def cells(level: str, fmt: str, result, score: str) -> list:
    """The cells of ``result`` (a typed result of ``level``) in ``fmt``, for the score ``score``."""
    return [cell.render(result, score) for _, cell in shown(level, fmt)]


def headers(level: str, fmt: str, score: str = "", baseline: str = "") -> list[str]:
    """The headers of the columns of ``level`` in ``fmt``, ``{score}`` and ``{baseline}`` filled in."""
    return [fill(cell.header, score=score, baseline=baseline) for _, cell in shown(level, fmt)]


def fill(template: str, **names: str) -> str:
    """``template`` with each ``{name}`` replaced (not str.format: LaTeX headers hold braces)."""
    for name, value in names.items():
        template = template.replace("{" + name + "}", value)
    return template


def computed(level: str, *scores: np.ndarray) -> dict:
    """key -> value of each added statistic of ``level`` (those with a ``compute``) on ``scores``."""
    return {c.key: c.compute(*scores) for c in COLUMNS if c.level == level and c.compute is not None}

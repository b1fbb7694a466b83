"""Score tables as text, Markdown or CSV."""
from __future__ import annotations

import csv
import io
import math
from typing import Mapping
from typing import Sequence as Seq

from dcfkit.analysis.latex import comparison_table, latex_table
from dcfkit.analysis.setting import experiment_line
from dcfkit.analysis.stats.columns import DIFFERENCE, MEAN, cells
from dcfkit.analysis.stats.results import Comparison
from dcfkit.errors import printable, shown
from dcfkit.experiments import Experiment, get_experiment
from dcfkit.protocols import DEFAULT, Protocol, get_protocol

_TABLES = {  # the columns before and after a protocol's scores (Protocol.score_keys)
    "overall": (("tracker",), ("fps", "sequences", "missing")),
    "per_sequence": (("tracker", "sequence"), ("fps", "frames")),
    "per_attribute": (("attribute", "name", "sequences", "tracker"), ()),
}


def columns(table: str, protocol: str | Protocol = DEFAULT) -> tuple[str, ...]:
    """Columns of the ``overall``, ``per_sequence`` or ``per_attribute`` table under ``protocol``."""
    lead, tail = _TABLES[table]
    return lead + get_protocol(protocol).score_keys + tail


OVERALL_COLUMNS = columns("overall")
SEQUENCE_COLUMNS = columns("per_sequence")
ATTRIBUTE_COLUMNS = columns("per_attribute")


def _cell(key: str, value, full: bool = False) -> str:
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return "" if full else "-"
    if isinstance(value, float):
        if full:
            return repr(value)
        return f"{value:.1f}" if key == "fps" else f"{value:.3f}"
    if full:
        return str(value)
    # a sequence or tracker is named by a folder, whose name may hold a line break or a '|'
    return printable(value)


def format_rows(rows: Seq[Mapping], fmt: str = "table", columns: Seq[str] | None = None) -> str:
    """Rows as an aligned text table (``"table"``), ``"markdown"`` or ``"csv"``.

    Floats are shown with 3 decimals (fps with 1) in table/markdown; CSV keeps full
    precision and leaves missing values empty.
    """
    if fmt not in ("table", "markdown", "csv"):
        raise ValueError(f"format must be table, markdown or csv, got {shown(fmt)}")
    if columns is None:
        columns = list(rows[0]) if rows else []
    if fmt == "csv":
        buf = io.StringIO()
        writer = csv.writer(buf, lineterminator="\n")
        writer.writerow(columns)
        for row in rows:
            writer.writerow([_cell(c, row.get(c), full=True) for c in columns])
        return buf.getvalue()
    cells = [[_cell(c, row.get(c)) for c in columns] for row in rows]
    numeric = [all(_is_number(row.get(c)) for row in rows) and bool(rows) for c in columns]
    if fmt == "markdown":
        lines = ["| " + " | ".join(columns) + " |",
                 "|" + "|".join("---:" if n else ":---" for n in numeric) + "|"]
        lines += ["| " + " | ".join(c.replace("|", "\\|") for c in r) + " |" for r in cells]
        return "\n".join(lines) + "\n"
    widths = [max([len(c)] + [len(r[i]) for r in cells]) for i, c in enumerate(columns)]

    def line(values):
        return "  ".join(v.rjust(w) if n else v.ljust(w)
                         for v, w, n in zip(values, widths, numeric)).rstrip()

    out = [line(columns), "  ".join("-" * w for w in widths)] + [line(r) for r in cells]
    return "\n".join(out) + "\n"


def _is_number(value) -> bool:
    return value is None or (isinstance(value, (int, float)) and not isinstance(value, bool))


#: how scores are named in text (a score key of :class:`~dcfkit.protocols.Protocol` -> its name)
NAMES_SHOWN = 10  # the most sequence names a line lists (a benchmark may have 30,000)

SCORE_LABELS = {"ao": "AO", "sr50": "SR@0.5", "sr75": "SR@0.75", "auc": "AUC", "precision": "precision",
                "norm_precision": "normalized precision"}


def score_line(row: Mapping, protocol: str | Protocol = DEFAULT) -> str:
    """One overall row as ``precision 0.891, AUC 0.520 on 6 sequences (protocol otb)``."""
    proto = get_protocol(protocol)
    scores = ", ".join(f"{SCORE_LABELS[k]} {_cell(k, row[k])}" for k in proto.score_keys)
    return f"{scores} on {row['sequences']} sequences (protocol {proto.name})"


def format_table(rows: Seq[Mapping], fmt: str, columns: Seq[str], protocol: str | Protocol = DEFAULT,
                 statistics: Mapping | None = None, *, experiment: str | Experiment | None = None,
                 max_frames: int | None = None, datasets: Mapping[str, int] | None = None) -> str:
    """:func:`format_rows` naming the scoring protocol and, if given, the ``experiment`` and the
    ``--max-frames`` cut (:mod:`dcfkit.analysis.setting`): first lines (``table``, ``markdown``),
    last columns ``protocol``, ``experiment`` and ``max_frames`` (``csv``, so the file stays one
    table), or the caption of a LaTeX table (``latex``: with ``statistics``, the comparison
    table of :func:`~dcfkit.analysis.latex.comparison_table`, naming the ``datasets``)."""
    proto = get_protocol(protocol)
    setting = {} if experiment is None else {"experiment": get_experiment(experiment).name}
    if max_frames is not None:
        setting["max_frames"] = max_frames
    if fmt == "latex":
        lines = [experiment_line(experiment, max_frames)] if experiment is not None else []
        if statistics:
            return comparison_table(statistics, [*lines, proto.describe()], datasets=datasets)
        return latex_table(rows, columns, proto, lines)
    if fmt == "csv":
        return format_rows([{**r, "protocol": proto.name, **setting} for r in rows], fmt,
                           (*columns, "protocol", *setting))
    head = f"{experiment_line(experiment, max_frames)}\n" if experiment is not None else ""
    return f"{head}{proto.describe()}\n\n" + format_rows(rows, fmt, columns)


def comparison_lines(statistics: Mapping, names: tuple[str, str] = ("results", "reference")) -> list[str]:
    """One line per score of :func:`dcfkit.analysis.compare.score_statistics`: both means and
    the difference with the declared statistics (:mod:`dcfkit.analysis.stats.columns`, format
    ``pair``: intervals, the Wilcoxon p, won/lost/tied), and the sequences left out for a
    non-finite score."""
    lines = [f"statistics: {statistics['method']}"]
    for score in ("auc", "precision"):
        s = statistics[score]
        mean = {side: "".join(cells(MEAN, "pair", s[side], score)) for side in ("results", "reference")}
        lines.append(f"  {SCORE_LABELS.get(score, score):<9} {names[0]} {mean['results']}   "
                     f"{names[1]} {mean['reference']}   {names[0]} - {names[1]} "
                     + "".join(cells(DIFFERENCE, "pair", s["difference"], score)))
        if s.get("non_finite"):
            lines.append(f"  {'':<9} left out, {non_finite_text(s['non_finite'], SCORE_LABELS.get(score, score))}")
    return lines


def non_finite_text(sequences: Seq[str], score: str) -> str:
    """``a non-finite AUC (no frame counted) in 2 sequences (a, b)``, ten names at most."""
    names = ", ".join(printable(name) for name in sequences[:NAMES_SHOWN])
    more = f", and {len(sequences) - NAMES_SHOWN:,} more" if len(sequences) > NAMES_SHOWN else ""
    return (f"a non-finite {score} (no frame counted) in {len(sequences):,} "
            f"sequence{'s' if len(sequences) != 1 else ''} ({names}{more})")


def noise_floor_line(floor: Mapping, sequences: int) -> str:
    """What :func:`dcfkit.analysis.compare.noise_floor` found, in one sentence (no verdict on a
    mean that is not a number)."""
    head = (f"noise floor: a last-bit change in the arithmetic moved one sequence by up to {floor['auc_sequence']:.3f} "
            f"AUC and a mean of eight by up to {floor['auc_mean_of_8']:.3f} ({floor['source']}); ")
    left = floor.get("non_finite") or []
    if floor["exceeds"] is None:
        return head + f"no verdict: no sequence has a finite AUC difference ({non_finite_text(left, 'AUC')})"
    verdict = "exceeds it" if floor["exceeds"] else "is within it: not a finding"
    kept = sequences - len(left)
    over = f" over the {kept:,} sequence{'s' if kept != 1 else ''} with one (left out, {non_finite_text(left, 'AUC')})"
    return (f"{head}the mean AUC difference{over if left else ''}, {floor['mean_auc_difference']:+.3f}, {verdict}; "
            f"{len(floor['sequences_beyond'])} of {sequences} sequences differ by more than "
            f"{floor['auc_sequence']:.3f}")


def statistics_lines(statistics: Comparison | Mapping) -> list[str]:
    """A :class:`~dcfkit.analysis.stats.results.Comparison` as text: each tracker's means, the
    sequences left out of them for a non-finite score, then each difference from the baseline,
    with the statistics declared for ``text`` (:mod:`dcfkit.analysis.stats.columns`)."""
    if not statistics:
        return []
    means, width = statistics.means, max(len(t) for t in statistics.means)
    over, left_out = statistics_scope(statistics)
    lines = [f"statistics over {over} sequences: {statistics.method}; {statistics.correction}"]
    lines += [f"  {t:<{width}}  " + "   ".join(f"{SCORE_LABELS.get(k, k)} " + "".join(cells(MEAN, "text", m[k], k))
                                               for k in statistics.scores) for t, m in means.items()]
    lines += [f"  {line}" for line in left_out]
    for tracker, found in statistics.differences.items():
        for key in statistics.scores:
            lines.append(f"  {tracker} - {statistics.baseline}: {SCORE_LABELS.get(key, key)} "
                         + "".join(cells(DIFFERENCE, "text", found[key], key)))
    return lines


def statistics_scope(statistics: Comparison) -> tuple[str, list[str]]:
    """(how many sequences the statistics of :func:`statistics_lines` are over: ``5``, or ``3 of
    the 5`` when a non-finite score left two out of every one, and ``left out of ...`` phrases
    naming the sequences a non-finite score left out)."""
    left_out = _left_out(statistics, statistics.scores)
    everywhere = left_out.get("every mean and difference", [])
    over = f"{statistics.sequences - len(everywhere)} of the {statistics.sequences}" if everywhere else \
        f"{statistics.sequences}"
    return over, [f"left out of {where}: {non_finite_text(names, 'score')}" for where, names in left_out.items()]


def statistics_rows(statistics: Comparison) -> tuple[list[dict], list[str]]:
    """(rows, columns) of a :class:`~dcfkit.analysis.stats.results.Comparison` as one flat table
    for :func:`format_rows` (text, Markdown, CSV): a row per tracker and score, its mean's record
    (``mean``, ``ci_low``, ...) then its difference's, each key prefixed ``d_`` (none for the
    baseline), the added statistics included."""
    rows = []
    for tracker, found in statistics.means.items():
        for key, mean in found.items():
            difference = statistics.differences.get(tracker, {}).get(key)
            rows.append({"tracker": tracker, "score": key, **mean.as_record(),
                         **{f"d_{k}": v for k, v in (difference.as_record() if difference else {}).items()}})
    names = list(dict.fromkeys(k for row in rows for k in row))
    return rows, names


STATISTICS_FILES = ("statistics.txt", "statistics.md", "statistics.csv")


def statistics_files(statistics: Comparison, head: Seq[str], setting: Mapping[str, object]) -> dict[str, str]:
    """The statistics of a report as :data:`STATISTICS_FILES` (name -> text): the ``head`` lines
    (experiment, protocol or rule; as given in ``.txt``, blank ones left out in ``.md``), then :func:`statistics_lines` (``.txt``) or the flat table of
    :func:`statistics_rows` (``.md``); the ``.csv`` is that table alone, with the ``setting``
    (``protocol``, ``experiment``, ...) as its last columns, so that it stays one table."""
    rows, names = statistics_rows(statistics) if statistics else ([], ["tracker", "score"])  # {}: no tracker
    lead = "".join(f"{line}\n" for line in head if line) + "\n" if any(head) else ""
    method = (f"\nd_: the paired difference from {statistics.baseline}. Over {statistics_scope(statistics)[0]} "
              f"sequences: {statistics.method}; {statistics.correction}\n" if statistics else "")
    return {"statistics.txt": "\n".join([*head, *statistics_lines(statistics)]) + "\n",
            "statistics.md": lead + format_rows(rows, "markdown", names) + method,
            "statistics.csv": format_rows([{**row, **setting} for row in rows], "csv", [*names, *setting])}


def _left_out(statistics: Comparison, keys: Seq[str]) -> dict[str, list[str]]:
    """Where -> the sequences left out for a non-finite score: one entry, ``every mean and
    difference``, when the same sequences are left out of each tracker's every score (a
    sequence no tracker could be scored on), else one per list of sequences naming its scores."""
    groups: dict[tuple, list[str]] = {}
    for tracker, found in statistics.non_finite.items():
        for key, names in found.items():
            groups.setdefault(tuple(names), []).append(f"{tracker}'s {SCORE_LABELS.get(key, key)}")
    if len(groups) == 1 and len(next(iter(groups.values()))) == len(statistics.means) * len(keys):
        return {"every mean and difference": list(next(iter(groups)))}
    return {", ".join(where): list(names) for names, where in groups.items()}

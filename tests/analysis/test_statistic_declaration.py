"""A statistic is added in two places, its compute function and its column in the declaration
(dcfkit.analysis.stats.columns), and shows in every output: statistics.txt's text, compare's
lines, the flat tables (text, Markdown, CSV), the LaTeX comparison table, the HTML page's
statistics table, a search's summary.md and the JSON files. No renderer is edited here."""
from __future__ import annotations

import json

import numpy as np
import pytest

from dcfkit.analysis.compare import score_statistics
from dcfkit.analysis.latex import comparison_table
from dcfkit.analysis.report import json_ready
from dcfkit.analysis.report_html.sections import statistics_table
from dcfkit.analysis.stats import columns
from dcfkit.analysis.stats.columns import DIFFERENCE, MEAN, Cell, Column
from dcfkit.analysis.statistics import versus_baseline
from dcfkit.analysis.tables import comparison_lines, format_rows, statistics_lines, statistics_rows
from dcfkit.autosearch import summary as search

SEQUENCES = [f"s{i}" for i in range(6)]
AUC = {"base": [0.61, 0.55, 0.70, 0.42, 0.66, 0.58], "other": [0.60, 0.50, 0.71, 0.40, 0.60, 0.52],
       "third": [0.30, 0.35, 0.20, 0.41, 0.22, 0.33]}


def median_difference(a: np.ndarray, b: np.ndarray) -> float:
    """The toy statistic's module: the median of the paired differences a - b."""
    return float(np.median(a - b))


def spread(x: np.ndarray) -> float:
    """A toy statistic of one tracker's scores: the highest minus the lowest."""
    return float(np.ptp(x))


def toy(result, key: str) -> str:
    return f"{result.extra[key]:+.4f}"


TOY = Column("toy_median", DIFFERENCE, {
    "text": Cell(lambda d, score: f", toy median {toy(d, 'toy_median')}"),
    "pair": Cell(lambda d, score: f"   toy median {toy(d, 'toy_median')}"),
    "latex": Cell(lambda d, score: toy(d, "toy_median"), header="Toy"),
    "html": Cell(lambda d, score: d.extra["toy_median"], header="{score} toy median", key="{score}_toy"),
    "search": Cell(lambda d, score: toy(d, "toy_median"), header="toy median", place=1)}, compute=median_difference)
SPREAD = Column("toy_spread", MEAN, {
    "text": Cell(lambda m, score: f" spread {toy(m, 'toy_spread')}"),
    "latex": Cell(lambda m, score: toy(m, "toy_spread"), header="Spread"),
    "html": Cell(lambda m, score: m.extra["toy_spread"], header="{score} spread", key="{score}_spread")},
    compute=spread)


@pytest.fixture
def declared(monkeypatch):
    """The declaration with the two toy statistics registered (the built-ins restored after)."""
    monkeypatch.setattr(columns, "COLUMNS", list(columns.COLUMNS))
    columns.register(TOY)
    columns.register(SPREAD)


def comparison():
    rows = [{"tracker": t, "sequence": s, "auc": v} for t, values in AUC.items() for s, v in zip(SEQUENCES, values)]
    return versus_baseline(rows, list(AUC), ("auc",), "base")


def expected(tracker: str) -> str:
    return f"{np.median(np.subtract(AUC[tracker], AUC['base'])):+.4f}"


def test_a_declared_statistic_shows_in_the_text_latex_html_and_json(declared):
    st = comparison()
    lines = statistics_lines(st)
    for tracker in ("other", "third"):
        line = next(line for line in lines if line.startswith(f"  {tracker} - base: AUC "))
        assert f"(Holm {st.differences[tracker]['auc'].holm_p:.3g}), toy median {expected(tracker)}, won " in line
    assert f"AUC {st.means['third']['auc'].mean:.3f} [" in lines[3] and f" spread {np.ptp(AUC['third']):+.4f}" in lines[3]

    latex = comparison_table(st, ["setting"])
    assert r"\multicolumn{6}{c}{AUC}" in latex and r"Mean [CI] & Spread & $\Delta$ [CI] & $p$ & W/T/L & Toy \\" in latex
    row = next(line for line in latex.splitlines() if line.startswith("third & "))
    assert row.endswith(f" & {expected('third')} \\\\") and row.count(" & ") == 6
    assert next(line for line in latex.splitlines() if line.startswith("base & ")).endswith(r"-- & -- & -- & -- \\")

    table = statistics_table(st, list(AUC))
    keys = [c["key"] for c in table["columns"]]
    assert keys == ["tracker", "auc_ci", "auc_spread", "d_auc", "auc_holm_p", "auc_toy"]
    assert table["columns"][-1]["label"] == "AUC toy median"
    assert [row[-1] for row in table["rows"]] == [None] + [pytest.approx(float(expected(t))) for t in ("other", "third")]

    record = json.loads(json.dumps(json_ready(st)))
    assert record["differences"]["third"]["auc"]["toy_median"] == pytest.approx(float(expected("third")))
    assert list(record["differences"]["third"]["auc"])[-3:] == ["holm_p", "significant", "toy_median"]
    assert record["means"]["base"]["auc"]["toy_spread"] == pytest.approx(np.ptp(AUC["base"]))


def test_a_declared_statistic_shows_in_the_flat_tables(declared):
    rows, names = statistics_rows(comparison())
    for fmt in ("table", "markdown", "csv"):
        text = format_rows(rows, fmt, names)
        assert "d_toy_median" in text.splitlines()[0] and "toy_spread" in text.splitlines()[0]
    csv = format_rows(rows, "csv", names).splitlines()
    third = dict(zip(csv[0].split(","), csv[3].split(",")))
    assert third["tracker"] == "third" and float(third["d_toy_median"]) == pytest.approx(float(expected("third")))
    assert float(third["toy_spread"]) == pytest.approx(np.ptp(AUC["third"]))


def test_a_declared_statistic_shows_in_compare_and_the_search_summary(declared):
    rows = [{"sequence": s, "auc": a, "auc_ref": b, "d_auc": a - b, "precision": a, "precision_ref": b,
             "d_precision": a - b} for s, a, b in zip(SEQUENCES, AUC["other"], AUC["base"])]
    lines = comparison_lines(score_statistics(rows)["statistics"], ("ours", "theirs"))
    assert lines[1].endswith(f", tied 0 of 6   toy median {expected('other')}")

    held = {s: {"auc": v} for s, v in zip(SEQUENCES, AUC["other"])}
    baselines = {"base": {s: {"auc": v} for s, v in zip(SEQUENCES, AUC["base"])},
                 "third": {s: {"auc": v} for s, v in zip(SEQUENCES, AUC["third"])}}
    summary = json.loads(json.dumps(search.finite({  # as summary.json holds it
        "name": "toy", "experiments": ["ope"], "trials_per_study": 1, "sequences": SEQUENCES, "unscored": [],
        "folds": [], "held_out": {"auc": search.mean_interval(AUC["other"]).as_record()},
        "baselines": {n: {"auc": search.mean_interval([s[k]["auc"] for k in SEQUENCES]).as_record()}
                      for n, s in baselines.items()},
        "comparisons": search._compare(SEQUENCES, held, baselines), "method": "m", "correction": "c",
        "beats_every_baseline": False, "final": {"trial": 0, "params": {}, "auc": 0.5}})))
    lines = search.summary_lines(summary)
    head = next(line for line in lines if line.startswith("| baseline |"))
    assert head.endswith("| Wilcoxon p | Holm p | beaten | toy median |")
    third = next(line for line in lines if line.startswith("| third |"))
    toy_median = np.median(np.subtract(AUC["other"], AUC["third"]))
    assert third.endswith(f"| {toy_median:+.4f} |") and third.count(" | ") == len(head.split(" | ")) - 1


def test_a_statistic_is_declared_once():
    with pytest.raises(ValueError, match="statistic 'holm_p' is declared already"):
        columns.register(Column("holm_p", DIFFERENCE, {}))
    with pytest.raises(ValueError, match="no format pdf"):
        Column("toy", MEAN, {"pdf": Cell(str)})

"""Where the long-term measures appear beside ``longterm.*``: the HTML report's section (its table,
the trackers left out, the precision-recall plot) and ``dcfkit report --format markdown|csv|latex``.

The results are those of ``test_longterm`` (tracker ``x`` with confidences, ``y`` without, ``z``
with a malformed file), ``x`` renamed to a hostile name: text that must stay text."""
from __future__ import annotations

import re
import shutil

import pytest
from test_latex import check_structure, compile_latex
from test_longterm import GT, _results, _sequence, _write
from test_report_html import HOSTILE_NAME, URL, open_page, page_data

from dcfkit import cli
from dcfkit.analysis.report_html import evaluation_sections
from dcfkit.analysis.scoring import evaluate
from dcfkit.experiments import runs_by_sequence
from dcfkit.store.results import import_results

X = HOSTILE_NAME  # a folder name: no slash
# x's averaged curves (hand-computed in test_longterm's report test), highest threshold first:
# tau      inf .9  .8  .7  .6    .5     .4     .3     .2   .1     -inf
# Re       0   .1  .2  .3  .3    23/60  28/60  28/60  .55  19/30  19/30
# Pr       1   1   1   1   .875  .875   .875   .8     .8   .8     .8
RECALL = [0, .1, .2, .3, .3, 23 / 60, 28 / 60, 28 / 60, .55, 19 / 30, 19 / 30]
PRECISION = [1, 1, 1, 1, .875, .875, .875, .8, .8, .8, .8]


@pytest.fixture
def report(tmp_path, monkeypatch):
    """``run(*args)``: ``dcfkit report`` of x (hostile name), y and z on two sequences, ``a`` with
    an absent frame; returns the report folder."""
    import dcfkit.cli.evaluate  # to stub the dataset

    _results(tmp_path / "out", malformed=True)
    (tmp_path / "out" / "x").rename(tmp_path / "out" / X)
    sequences = [_sequence(tmp_path / "data", "a", (3,)), _sequence(tmp_path / "data", "b", ())]
    monkeypatch.setattr(dcfkit.cli.evaluate, "load_datasets", lambda *a, **k: sequences)

    def run(*args):
        assert cli.main(["report", str(tmp_path / "out"), "--root", str(tmp_path), *args]) == 0
        return tmp_path / "out_report"
    run.sequences = sequences
    return run


def section(html: str, section_id: str = "long-term") -> dict | None:
    return next((s for s in page_data(html)["sections"] if s["id"] == section_id), None)


def test_the_html_report_shows_the_long_term_table_left_out_and_curves(report):
    folder = report("--html")
    html = (folder / "report.html").read_text(encoding="utf-8")
    assert "<img" not in html and "<script>alert" not in html and not URL.search(html)
    trackers = page_data(html)["trackers"]
    found = section(html)
    assert found["title"] == "Long-term measures" and "tracking precision Pr, recall Re" in found["note"]
    table, left_out, plot = found["parts"]
    assert [c["label"] for c in table["columns"]] == ["tracker", "F", "Pr", "Re", "\u03c4 at max F", "sequences",
                                                     "sequences with absent frames"]
    (row,) = table["rows"]
    assert trackers[row[0]] == X and row[1:] == pytest.approx([30.4 / 43, .8, 19 / 30, .1, 2, 1], abs=1e-4)
    why = {trackers[t]: reason for t, reason in left_out["rows"]}
    assert set(why) == {"y", "z"} and "y/a.confidence (results imported" in why["y"]
    assert "z/a.confidence, line 3: '0.5;1'" in why["z"]
    (chart,) = plot["charts"]
    (series,) = chart["series"]
    assert series["label"] == f"{X} [0.707]" and trackers[series["t"]] == X
    assert series["x"] == pytest.approx(RECALL, abs=1e-4) and series["y"] == pytest.approx(PRECISION, abs=1e-4)
    assert series["point"] == pytest.approx([19 / 30, .8], abs=1e-4)
    assert chart["xlabel"] == "Tracking recall (Re)" and chart["ylabel"] == "Tracking precision (Pr)"


def test_no_long_term_section_without_scores_and_the_ope_only_line_for_sre(tmp_path, report, monkeypatch):
    """Imported results only (no confidences): no section; an ablation's evaluation (no
    ``long_term``): none either; SRE: the section is the line saying the measures are OPE's."""
    for name in (X, "z"):
        shutil.rmtree(tmp_path / "out" / name)
    html = (report("--html") / "report.html").read_text(encoding="utf-8")
    assert section(html) is None and section(html, "overall") is not None
    results = {"y": import_results(tmp_path / "out" / "y")}
    assert all(s["id"] != "long-term" for s in evaluation_sections(evaluate(results, report.sequences),
                                                                   report.sequences, results, ["y"]))
    for runs in runs_by_sequence(report.sequences, "sre").values():
        for run in runs:
            _write(tmp_path / "out" / "y" / "sre", run.name, GT[:len(run)], "nan,nan\n" + "0.5,1\n" * (len(run) - 1))
    found = section((report("--html", "--experiment", "sre") / "sre" / "report.html").read_text(encoding="utf-8"))
    assert found["parts"] == [] and found["note"].startswith(
        "Long-term measures are computed for one-pass runs (OPE) only, not for SRE")


def test_the_long_term_section_draws_in_chromium(report):
    """The table's text, the hostile name as text, a curve and its max-F dot; no error, no request."""
    pytest.importorskip("playwright.sync_api", reason="playwright is not installed")
    if shutil.which("chromium") is None:
        pytest.skip("no Chromium on PATH")
    from playwright.sync_api import sync_playwright  # optional: skipped above without it

    from test_report_html import CHROMIUM_ARGS  # the same launch as the other page tests
    path = report("--html") / "report.html"
    with sync_playwright() as playwright:
        browser = playwright.chromium.launch(executable_path=shutil.which("chromium"), args=CHROMIUM_ARGS)
        page, problems = open_page(browser, path)
        rows = page.locator("#long-term-table tbody tr").all_inner_texts()
        assert [r.split("\t") for r in rows] == [[X, "0.707", "0.800", "0.633", "0.100", "2", "1"]]
        assert page.locator("#long-term-left-out-table tbody tr").count() == 2
        chart = page.locator("#long-term svg.chart")
        assert chart.locator("path.line").first.bounding_box()["width"] > 50
        assert chart.locator("circle.point").count() == 1 and X in page.locator("#long-term .legend").inner_text()
        assert not problems, problems
        browser.close()


def test_markdown_prints_the_long_term_markdown_after_the_overall_table(report, capsys):
    folder = report("--format", "markdown")
    out = capsys.readouterr().out
    longterm = (folder / "longterm.md").read_text()
    # the overall table unchanged, then longterm.md but its first line (the experiment, stdout's first)
    assert out == (folder / "overall.md").read_text() + "\n" + longterm.split("\n", 1)[1]
    assert f"| {X} | 0.707 | 0.800 | 0.633 | 0.100 | 2 | 1 |" in out and "no long-term scores for y" in out


def test_csv_keeps_stdout_one_table_and_prints_the_long_term_csv_on_stderr(report, capsys):
    folder = report("--format", "csv")
    captured = capsys.readouterr()
    assert captured.out == (folder / "overall.csv").read_text()
    assert captured.err.endswith((folder / "longterm.csv").read_text())
    assert "tracker,f,precision,recall,threshold,sequences,absent\n" in captured.err


def test_latex_prints_a_long_term_table_after_the_overall_one(report, capsys, tmp_path):
    folder = report("--format", "latex")
    out = capsys.readouterr().out
    overall = (folder / "overall.tex").read_text()
    assert out.startswith(overall + "\n")
    table = out[len(overall) + 1:]
    check_structure(table)
    assert "Tracker & F & Pr & Re & $\\tau$ & Seq. & Absent \\\\" in table
    row = table.split("\\midrule\n")[1].splitlines()[0]
    assert row == (r"\textless{}img src=x onerror=alert(1)\textgreater{}\textless{}script\textgreater{}alert(2) & "
                   r"\textbf{0.707} & \textbf{0.800} & \textbf{0.633} & 0.100 & 2 & 1 \\")
    caption = re.search(r"\\caption\{(.*)\}\n", table).group(1)
    assert caption.startswith("Experiment OPE") and "Not scored (confidences missing or unreadable): y, z." in caption
    compile_latex(out, tmp_path)


@pytest.mark.parametrize("fmt, stream, said", [("markdown", "out", "\nlong-term measures are computed"),
                                               ("csv", "err", "long-term measures are computed")])
def test_markdown_and_csv_of_an_sre_report_say_the_measures_are_ope_only(tmp_path, report, capsys, fmt, stream,
                                                                          said):
    """(LaTeX says nothing: a paper's table takes no notes, and stdout stays the .tex file.)"""
    for runs in runs_by_sequence(report.sequences, "sre").values():
        for run in runs:
            _write(tmp_path / "out" / "y" / "sre", run.name, GT[:len(run)], "nan,nan\n" + "0.5,1\n" * (len(run) - 1))
    report("--experiment", "sre", "--trackers", "y", "--format", fmt)
    assert said + " for one-pass runs (OPE) only, not for SRE" in getattr(capsys.readouterr(), stream)


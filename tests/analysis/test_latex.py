"""LaTeX tables: marks of the best and second values, escaping, the captions, and the comparison
table a paper can take (scores with intervals, differences, Wilcoxon p, won/tied/lost), checked
for structure and, where pdflatex is installed, compiled."""
from __future__ import annotations

import re
import shutil
import subprocess

import numpy as np
import pytest
from scipy import stats

from dcfkit.analysis.latex import comparison_table, escape, latex_table
from dcfkit.analysis.statistics import versus_baseline
from dcfkit.analysis.tables import format_table

ROWS = [{"tracker": "a_b & c", "auc": 0.61, "precision": 0.90, "fps": 100.0},
        {"tracker": "d", "auc": 0.64, "precision": 0.90, "fps": 50.0},
        {"tracker": "e", "auc": 0.50, "precision": 0.85, "fps": None}]
COLUMNS = ("tracker", "auc", "precision", "fps")

# per-sequence scores of three trackers on eight sequences (hand-made: base best, "x_1" worse on 6)
BASE = [0.61, 0.55, 0.70, 0.42, 0.66, 0.58, 0.49, 0.73]
OTHER = [0.60, 0.50, 0.71, 0.40, 0.60, 0.58, 0.45, 0.70]
THIRD = [0.30, 0.35, 0.20, 0.41, 0.22, 0.33, 0.28, 0.25]


def body(text: str) -> list[list[str]]:
    rows = text.split("\\midrule\n")[1].split("\n\\bottomrule")[0].splitlines()
    return [[c.strip() for c in row.removesuffix(r" \\").split(" & ")] for row in rows]


def check_structure(text: str) -> None:
    """What pdflatex would choke on: unbalanced braces, math shifts or environments, a row of
    another width than the tabular's column spec, or a command booktabs and LaTeX lack."""
    plain = re.sub(r"\\[{}$&%#_]", "", text)
    assert plain.count("{") == plain.count("}") and plain.count("$") % 2 == 0
    assert re.findall(r"\\begin\{(\w+)\}", text) == re.findall(r"\\end\{(\w+)\}", text)[::-1]
    known = {"begin", "end", "centering", "caption", "toprule", "midrule", "bottomrule", "cmidrule", "multicolumn",
             "scriptsize", "textbf", "underline", "Delta", "textless", "textgreater", "textbackslash",
             "textasciitilde", "textasciicircum", "small", "setlength", "tabcolsep", "resizebox", "ifdim", "width",
             "linewidth", "else", "fi", "tau", "infty"}
    assert set(re.findall(r"\\([A-Za-z]+)", text)) <= known
    width = len(re.search(r"\\begin\{tabular\}\{(\w+)\}", text).group(1))
    rows = text.split("\\toprule\n")[1].split("\n\\bottomrule")[0].splitlines()
    for row in rows:
        if row.endswith(r"\\"):
            spans = [int(n) for n in re.findall(r"\\multicolumn\{(\d+)\}", row)]
            cells = len(re.findall(r"(?<!\\)&", row)) + 1
            assert cells - len(spans) + sum(spans) == width, row


def compile_latex(text: str, tmp_path) -> None:
    """Compile ``text`` in a minimal two-column paper (booktabs and graphicx) when pdflatex is
    installed: no error, and no table wider than the page (an overfull box)."""
    if shutil.which("pdflatex") is None:
        pytest.skip("pdflatex is not installed; the structure is checked by check_structure")
    (tmp_path / "t.tex").write_text("\\documentclass[twocolumn]{article}\n\\usepackage{booktabs}\n"
                                    "\\usepackage{graphicx}\n\\begin{document}\n"
                                    f"{text}\\end{{document}}\n")
    done = subprocess.run(["pdflatex", "-interaction=nonstopmode", "-halt-on-error", "t.tex"], cwd=tmp_path,
                          capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stdout[-2000:]
    assert "Overfull \\hbox" not in done.stdout, done.stdout[-2000:]


def test_best_bold_second_underlined_ties_share_and_other_columns_plain():
    rows = body(latex_table(ROWS, COLUMNS, "otb"))
    assert [r[1] for r in rows] == [r"\underline{0.610}", r"\textbf{0.640}", "0.500"]
    assert [r[2] for r in rows] == [r"\textbf{0.900}", r"\textbf{0.900}", r"\underline{0.850}"]  # a tie: both best
    assert [r[3] for r in rows] == ["100.0", "50.0", "--"]  # fps is no score: unmarked; missing is --
    assert rows[0][0] == r"a\_b \& c"


def test_booktabs_frame_caption_and_alignment():
    text = latex_table(ROWS, COLUMNS, "pysot", ["experiment OPE (one pass)"])
    assert re.search(r"\\begin\{tabular\}\{lrrr\}\n\\toprule\nTracker & AUC & Precision & FPS \\\\\n\\midrule", text)
    caption = re.search(r"\\caption\{(.*)\}", text).group(1)
    assert caption.startswith("Experiment OPE (one pass). Protocol pysot")
    assert caption.endswith("Best in bold, second underlined.")
    assert text.endswith("\\end{tabular}\n\\end{table}\n")
    check_structure(text)


def per_sequence(**scores) -> list[dict]:
    return [{"tracker": t, "sequence": f"s{i}", "auc": v, "precision": 1 - v}
            for t, values in scores.items() for i, v in enumerate(values)]


def comparison(setting=("experiment TRE (temporal robustness)", "protocol otb: OTB toolkit")) -> str:
    statistics = versus_baseline(per_sequence(base=BASE, x_1=OTHER, third=THIRD), ["base", "x_1", "third"],
                                 ("auc", "precision"))
    return comparison_table(statistics, list(setting))


def test_the_comparison_table_holds_differences_p_and_won_tied_lost():
    """Against the hand-made scores: x_1's mean difference, its Wilcoxon p from scipy directly,
    and the sequences won, tied and lost counted by hand (dcfkit <= 0.9: only means and intervals,
    while the caption promised the rest)."""
    rows = {r[0]: r for r in body(comparison())}
    assert list(rows) == ["base", r"x\_1", "third"]
    assert rows["base"][2:5] == ["--", "--", "--"]  # the baseline's own difference
    d = np.subtract(OTHER, BASE)
    delta = rows[r"x\_1"][2]
    assert delta.startswith(f"${d.mean():+.3f}$ {{\\scriptsize [$-")
    p, p_third = stats.wilcoxon(d[d != 0]).pvalue, stats.wilcoxon(np.subtract(THIRD, BASE)).pvalue
    assert max(2 * p_third, p) < 0.05  # Holm's step-down: significant, starred
    assert rows[r"x\_1"][3] == f"{p:.3f}$^{{*}}$"
    assert rows[r"x\_1"][4] == "1/1/6"  # better on s2, the same on s5, worse on six
    assert rows["third"][3].endswith("$^{*}$") and rows["third"][4] == "0/0/8"  # Holm-significant
    assert rows["base"][1].startswith(f"{np.mean(BASE):.3f} {{\\scriptsize [")
    assert rows[r"x\_1"][5].startswith(f"{1 - np.mean(OTHER):.3f}")  # precision: 1 - auc here
    assert rows[r"x\_1"][8] == "6/1/1"


def test_the_comparison_caption_names_experiment_protocol_sequences_and_method():
    text = comparison()
    caption = re.search(r"\\caption\{(.*)\}\n", text).group(1)
    assert caption.startswith("Experiment TRE (temporal robustness). Protocol otb: OTB toolkit. "
                              "Means over the 8 sequences every tracker ran. 95\\% BCa bootstrap")
    assert "Wilcoxon signed-rank" in caption and "Holm" in caption and "difference from base" in caption
    assert "\\multicolumn{4}{c}{AUC} & \\multicolumn{4}{c}{Precision}" in text
    check_structure(text)


def test_fewer_failures_win_and_lead_columns_come_first():
    rows = [{"tracker": t, "sequence": f"s{i}", "accuracy": 0.5, "failures": v}
            for t, values in {"a": [1, 2, 3], "b": [2, 2, 5]}.items() for i, v in enumerate(values)]
    statistics = versus_baseline(rows, ["a", "b"], ("accuracy", "failures"))
    text = comparison_table(statistics, ["experiment RESET"], lead=[("EAO [CI]", {"a": "0.300", "b": "0.200"})])
    found = {r[0]: r for r in body(text)}
    assert found["b"][1] == "0.200" and found["b"][9] == "0/1/2"  # more failures on two sequences: lost
    check_structure(text)


def test_format_table_gives_the_comparison_with_statistics_and_names_a_cut():
    statistics = versus_baseline(per_sequence(base=BASE, x_1=OTHER), ["base", "x_1"], ("auc", "precision"))
    text = format_table([], "latex", (), "otb", statistics, experiment="sre", max_frames=40)
    assert r"\caption{Experiment SRE (spatial robustness" in text and "(-{}-max-frames 40)" in text
    assert "W/T/L" in text


def test_the_caption_names_the_pooled_datasets():
    statistics = versus_baseline(per_sequence(base=BASE, x_1=OTHER), ["base", "x_1"], ("auc", "precision"))
    text = format_table([], "latex", (), "otb", statistics, experiment="ope",
                        datasets={"uav123_10fps": 6, "dtb70": 1, "uavdt": 1})
    assert r"every tracker ran (uav123\_10fps 6, dtb70 1, uavdt 1)." in text
    check_structure(text)


def test_the_tables_compile(tmp_path):
    compile_latex(comparison() + latex_table(ROWS, COLUMNS, "otb"), tmp_path)


def test_escape_covers_latex_specials():
    assert escape(r"50% of $x_1 {a} #2 ~^\ <> --") == \
        r"50\% of \$x\_1 \{a\} \#2 \textasciitilde{}\textasciicircum{}\textbackslash{} \textless{}\textgreater{} -{}-"

"""LaTeX tables: marks of the best and second values, escaping, the caption, the intervals."""
from __future__ import annotations

import re

from dcfkit.analysis.latex import escape, latex_table
from dcfkit.analysis.statistics import METHOD

ROWS = [{"tracker": "a_b & c", "auc": 0.61, "precision": 0.90, "fps": 100.0},
        {"tracker": "d", "auc": 0.64, "precision": 0.90, "fps": 50.0},
        {"tracker": "e", "auc": 0.50, "precision": 0.85, "fps": None}]
COLUMNS = ("tracker", "auc", "precision", "fps")


def body(text: str) -> list[list[str]]:
    rows = text.split("\\midrule\n")[1].split("\n\\bottomrule")[0].splitlines()
    return [[c.strip() for c in row.removesuffix(r" \\").split(" & ")] for row in rows]


def test_best_bold_second_underlined_ties_share_and_other_columns_plain():
    rows = body(latex_table(ROWS, COLUMNS, "otb"))
    assert [r[1] for r in rows] == [r"\underline{0.610}", r"\textbf{0.640}", "0.500"]
    assert [r[2] for r in rows] == [r"\textbf{0.900}", r"\textbf{0.900}", r"\underline{0.850}"]  # a tie: both best
    assert [r[3] for r in rows] == ["100.0", "50.0", "--"]  # fps is no score: unmarked; missing is --
    assert rows[0][0] == r"a\_b \& c"


def test_booktabs_frame_caption_and_alignment():
    text = latex_table(ROWS, COLUMNS, "pysot")
    assert re.search(r"\\begin\{tabular\}\{lrrr\}\n\\toprule\nTracker & AUC & Precision & FPS \\\\\n\\midrule", text)
    caption = re.search(r"\\caption\{(.*)\}", text).group(1)
    assert caption.startswith("protocol pysot") and caption.endswith("Best in bold, second underlined.")
    assert text.endswith("\\end{tabular}\n\\end{table}\n")


def test_intervals_in_brackets_and_the_method_in_the_caption():
    statistics = {"method": METHOD, "means": {"d": {"auc": {"mean": 0.64, "ci_low": 0.6, "ci_high": 0.7, "n": 6}}}}
    text = latex_table(ROWS, COLUMNS, "otb", statistics)
    assert r"\textbf{0.640} {\scriptsize [0.600, 0.700]}" in text
    assert r"In brackets: 95\% BCa bootstrap" in text


def test_escape_covers_latex_specials():
    assert escape(r"50% of $x_1 {a} #2 ~^\ ") == \
        r"50\% of \$x\_1 \{a\} \#2 \textasciitilde{}\textasciicircum{}\textbackslash{} "

"""`report`'s console platform line stays bounded when platform records differ per sequence, and
the HTML statistics note names the sequences a non-finite score left out, as the text report does."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from dcfkit import cli
from dcfkit.analysis.report_html.sections import statistics_table
from dcfkit.analysis.statistics import versus_baseline
from dcfkit.analysis.tables import statistics_lines
from dcfkit.datasets import Sequence
from dcfkit.store.results import ResultStore

GT = np.array([[10, 10, 10, 10]] * 5, dtype=float)


def sequence(name: str) -> Sequence:
    return Sequence(name=name, frames=tuple(Path(f"{k:05d}.jpg") for k in range(len(GT))),
                    ground_truth=GT.copy(), attributes={}, dataset="test")


def test_the_platform_line_of_report_lists_ten_records_and_counts_the_others(tmp_path, monkeypatch, capsys):
    """14 sequences, each run under another platform record: one line of ten records, each with its
    count, and "and 4 more" (a line per record would be 30,000 entries on TrackingNet)."""
    n = 14
    seqs = [sequence(f"s{k:02d}") for k in range(n)]
    (tmp_path / "out" / "kcf").mkdir(parents=True)
    store = ResultStore(tmp_path / "out" / "kcf")
    for k, seq in enumerate(seqs):
        store.write(seq, GT, {"run_key": "k", "platform": {"arch": "x86_64", "cpu": f"CPU {k:02d}"}})
    import dcfkit.cli.evaluate

    monkeypatch.setattr(dcfkit.cli.evaluate, "load_datasets", lambda *a, **k: seqs)
    assert cli.main(["report", str(tmp_path / "out"), "--root", str(tmp_path), "--report-dir",
                     str(tmp_path / "report")]) == 0
    lines = [line for line in capsys.readouterr().out.splitlines() if line.startswith("kcf platform: ")]
    assert len(lines) == 1
    entries = lines[0].removeprefix("kcf platform: ").split("; ")
    assert len(entries) == 11 and entries[-1] == "and 4 more"
    assert all(e.endswith(f"(1 of {n} sequences)") and "CPU" in e for e in entries[:10])


def test_the_html_statistics_note_names_what_a_non_finite_score_left_out():
    rows = [{"tracker": t, "sequence": s, "auc": float("nan") if s in ("d", "e") else 0.5 + 0.1 * (t == "a") + 0.01 * i,
             "precision": float("nan") if s in ("d", "e") else 0.6 + 0.01 * i}
            for t in ("a", "b") for i, s in enumerate("abcde")]
    stats = versus_baseline(rows, ["a", "b"], ("auc", "precision"))
    note = statistics_table(stats, ["a", "b"])["note"]
    text = statistics_lines(stats)
    assert text[0].startswith("statistics over 3 of the 5 sequences")
    assert note.startswith("Over 3 of the 5 sequences every tracker ran: ")
    left = "left out of every mean and difference: a non-finite score (no frame counted) in 2 sequences (d, e)"
    assert f"  {left}" in text and f"Left out of every mean and difference: {left.split(': ', 1)[1]}." in note


def test_the_html_statistics_note_without_non_finite_scores():
    rows = [{"tracker": t, "sequence": s, "auc": 0.5 + 0.1 * (t == "a") + 0.01 * i, "precision": 0.6}
            for t in ("a", "b") for i, s in enumerate("abc")]
    note = statistics_table(versus_baseline(rows, ["a", "b"], ("auc", "precision")), ["a", "b"])["note"]
    assert note.startswith("Over 3 sequences every tracker ran: ") and "left out" not in note.lower()

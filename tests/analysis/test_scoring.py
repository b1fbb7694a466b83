"""evaluate(): its statistics over sequences, against scipy on the per-sequence scores."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from scipy import stats

from dcfkit import cli
from dcfkit.analysis.scoring import evaluate
from dcfkit.datasets import Sequence

GT = np.array([[20.0, 20.0, 10.0, 10.0]] * 10)


def sequence(name: str) -> Sequence:
    return Sequence(name=name, frames=tuple(Path(f"{k:05d}.jpg") for k in range(10)), ground_truth=GT.copy(),
                    attributes={}, dataset="test")


def shifted(px: float) -> np.ndarray:
    boxes = GT.copy()
    boxes[1:, 0] += px
    return boxes


SEQUENCES = [sequence(n) for n in "abcde"]
RESULTS = {"near": {s.name: shifted(k) for k, s in enumerate(SEQUENCES)},          # 0..4 px off
           "far": {s.name: shifted(2 * k + 1) for k, s in enumerate(SEQUENCES)},   # 1..9 px off
           "same": {s.name: shifted(k) for k, s in enumerate(SEQUENCES)}}          # as near


def test_each_tracker_has_its_interval_and_each_other_its_paired_difference_from_the_best():
    ev = evaluate(RESULTS, SEQUENCES)
    st = ev.statistics
    auc = {t: np.array([r["auc"] for r in ev.per_sequence if r["tracker"] == t]) for t in RESULTS}
    best = ev.overall[0]["tracker"]
    assert st["baseline"] == best in ("near", "same") and st["sequences"] == 5
    ci = stats.bootstrap((auc["far"],), np.mean, method="BCa", rng=np.random.default_rng(0)).confidence_interval
    assert st["means"]["far"]["auc"] == pytest.approx({"mean": auc["far"].mean(), "ci_low": ci.low,
                                                        "ci_high": ci.high, "n": 5})
    far = st["differences"]["far"]["auc"]
    assert far["mean"] == pytest.approx((auc["far"] - auc[best]).mean())
    assert far["wilcoxon_p"] == pytest.approx(stats.wilcoxon(auc["far"] - auc[best]).pvalue)
    assert (far["won"], far["lost"]) == (0, int(np.sum(auc["far"] < auc[best])))
    other = "same" if best == "near" else "near"
    tie = st["differences"][other]["auc"]
    assert (tie["mean"], tie["wilcoxon_p"], tie["tied"], tie["significant"]) == (0, 1.0, 5, False)
    # Holm over the two comparisons: the tie's p of 1 leaves far's p doubled
    assert far["holm_p"] == pytest.approx(min(1.0, 2 * far["wilcoxon_p"]))
    assert ev.as_record()["statistics"] == st


def test_report_prints_and_writes_the_statistics(tmp_path, monkeypatch, capsys):
    import dcfkit.cli.evaluate

    for tracker, by_sequence in RESULTS.items():
        folder = tmp_path / "out" / tracker
        folder.mkdir(parents=True)
        for name, boxes in by_sequence.items():
            (folder / f"{name}.txt").write_text("".join(f"{x + 1:.3f},{y + 1:.3f},{w:.3f},{h:.3f}\n"
                                                        for x, y, w, h in boxes))
    monkeypatch.setattr(dcfkit.cli.evaluate, "load_dataset", lambda *a, **k: SEQUENCES)
    assert cli.main(["report", str(tmp_path / "out"), "--root", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    assert "statistics over 5 sequences: 95% BCa bootstrap" in out and "far - " in out and "(Holm " in out
    written = (tmp_path / "out" / "report" / "statistics.txt").read_text()
    assert written.splitlines()[0] == out.split("\n\n")[-2].splitlines()[0]

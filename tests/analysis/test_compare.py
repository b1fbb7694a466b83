"""dcfkit compare: a hand-made pair of result folders, bad input, and the authors' results
(skipped without ../shared/data)."""
from __future__ import annotations

import dataclasses
import json
from pathlib import Path

import numpy as np
import pytest

from dcfkit import cli
from dcfkit.analysis.compare import PLATFORM_NOISE, compare_folders, first_divergence, series_iou
from dcfkit.datasets import DatasetError, Sequence
from dcfkit.store import platforms
from dcfkit.store.results import ResultStore

GT = np.array([[10, 10, 10, 10]] * 5, dtype=float)  # 0-based in memory; files hold x + 1


def sequence(name: str, n: int = 5) -> Sequence:
    return Sequence(name=name, frames=tuple(Path(f"{k:05d}.jpg") for k in range(n)),
                    ground_truth=GT[:n].copy(), attributes={}, dataset="test")


def write(folder: Path, name: str, rows) -> None:
    folder.mkdir(exist_ok=True)
    (folder / f"{name}.txt").write_text("".join(",".join(f"{v:g}" for v in r) + "\n" for r in rows))


# 1-based boxes of the two folders. Sequence "a": frame 3 moves 1 px (not apart at 2 px),
# frame 4 moves 3 px in x (apart: diverges at frame 4), frame 5 moves 5 px. IoU with
# [11, 21) x [11, 21): frames 1, 2 identical (1), frame 3: 9x10 / (200 - 90) = 90/110,
# frame 4: 7x10 / 130, frame 5: 5x10 / 150.
A_RESULTS = [[11, 11, 10, 10], [11, 11, 10, 10], [12, 11, 10, 10], [14, 11, 10, 10], [16, 11, 10, 10]]
A_REFERENCE = [[11, 11, 10, 10]] * 5
A_IOU = (1 + 1 + 90 / 110 + 70 / 130 + 50 / 150) / 5
# Sequence "b": identical, including a NaN row (agreeing: IoU 1, not diverged).
B_BOTH = [[11, 11, 10, 10], [11, 11, 10, 10], [float("nan")] * 4, [11, 11, 10, 10], [11, 11, 10, 10]]


@pytest.fixture
def folders(tmp_path):
    ours, theirs = tmp_path / "ours", tmp_path / "theirs"
    write(ours, "a", A_RESULTS)
    write(theirs, "a", A_REFERENCE)
    write(ours, "b", B_BOTH)
    write(theirs, "b", B_BOTH)
    write(ours, "only_ours", A_REFERENCE)
    write(theirs, "only_theirs", A_REFERENCE)
    write(ours, "c", A_REFERENCE)   # in both folders, not in the dataset
    write(theirs, "c", A_REFERENCE)
    (ours / "a_time.txt").write_text("0.1\n")  # timing files are not results
    return ours, theirs


def test_hand_made_pair(folders):
    ours, theirs = folders
    res = compare_folders(ours, theirs, [sequence("a"), sequence("b")], divergence_px=2)
    a, b = res["rows"]
    assert a["sequence"] == "a" and a["iou"] == pytest.approx(A_IOU) and a["diverges_at"] == 4
    assert b["iou"] == 1 and b["diverges_at"] is None and res["diverged"] == 1
    # the reference is perfect on a: precision 1, AUC 20/21 (otb). Ours: centre errors
    # 0, 0, 1, 3, 5 px (precision 1); overlaps 1, 1, .818, .538, .333 pass 20, 20, 17, 11, 7
    # of the 21 thresholds
    assert a["precision"] == a["precision_ref"] == 1 and a["d_precision"] == 0
    assert a["auc_ref"] == pytest.approx(20 / 21) and a["auc"] == pytest.approx(75 / 105)
    assert a["d_auc"] == pytest.approx(75 / 105 - 20 / 21)
    # b: the NaN row is repaired from frame 2 in both (otb), so both score a perfect sequence
    assert b["auc"] == b["auc_ref"] == pytest.approx(20 / 21)
    assert res["mean"]["sequence"] == "mean" and res["mean"]["frames"] == 10
    assert res["mean"]["auc"] == pytest.approx((75 / 105 + 20 / 21) / 2)
    assert res["mean"]["iou"] == pytest.approx((A_IOU + 1) / 2)
    assert res["left_out"] == {"only_in_results": ["only_ours"], "only_in_reference": ["only_theirs"],
                               "not_in_dataset": ["c"], "incomplete": [], "damaged": []}
    assert res["protocol"] == "otb"
    # a looser threshold: frame 4 is 3 px off, frame 5 is 5 px off
    assert compare_folders(ours, theirs, [sequence("a")], divergence_px=4)["rows"][0]["diverges_at"] == 5
    assert compare_folders(ours, theirs, [sequence("a")], divergence_px=5)["rows"][0]["diverges_at"] is None


def test_series_helpers():
    nan = [float("nan")] * 4
    a = [[0, 0, 10, 10], nan, nan, [0, 0, 0, 10], [0, 0, 10, 10]]
    b = [[0, 0, 10, 10], nan, [0, 0, 10, 10], [0, 0, 0, 10], [5, 0, 10, 10]]
    # identical rows (also NaN or empty ones) count 1; a NaN on one side 0; else the IoU (50/150)
    np.testing.assert_allclose(series_iou(a, b), [1, 1, 0, 1, 1 / 3])
    assert first_divergence(a, b, 2.0) == 3  # 1-based: a NaN on one side only is apart
    assert first_divergence(a[:2], b[:2], 0.0) is None


def test_cli_formats(folders, tmp_path, capsys, monkeypatch):
    ours, theirs = folders
    import dcfkit.cli.evaluate

    monkeypatch.setattr(dcfkit.cli.evaluate, "load_datasets", lambda *a, **k: [sequence("a"), sequence("b")])
    base = ["compare", str(ours), str(theirs), "--root", str(tmp_path)]
    assert cli.main(base) == 0
    out = capsys.readouterr().out
    assert out.startswith("protocol otb: OTB / UAV123 MATLAB toolkit")
    assert "1 of 2 sequences diverge (centres more than 2 px apart)" in out
    assert "left out: only in ours: only_ours; only in theirs: only_theirs; not in dataset: c" in out
    # each side by its folder's name (dcfkit <= 0.9: 'results' and 'reference')
    assert f"\nours (RESULTS): {ours}\ntheirs (REFERENCE): {theirs}\n" in out
    assert "precision, auc: ours; precision_ref, auc_ref: theirs; d_ = ours minus theirs" in out
    assert cli.main(base + ["--format", "csv", "--protocol", "pysot", "--divergence-px", "4"]) == 0
    captured = capsys.readouterr()
    assert "left out: only in ours: only_ours;" in captured.err  # notes beside the CSV, not in it
    lines = captured.out.splitlines()
    assert len(lines) == 4 and lines[0] == ("sequence,frames,precision,precision_ref,d_precision,auc,auc_ref,d_auc,iou,"
                        "diverges_at,protocol")
    assert lines[1].startswith("a,5,") and lines[1].endswith(",5,pysot") and lines[3].startswith("mean,10,")
    assert cli.main(base + ["--format", "json", "--protocol", "got10k"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["protocol"] == "got10k" and data["rows"][0]["diverges_at"] == 4
    assert cli.main(base + ["--format", "markdown"]) == 0
    assert "| sequence | frames | precision |" in capsys.readouterr().out


@pytest.mark.parametrize("case,message", [
    ("missing", "results folder not found: .*nowhere"),
    ("columns", r"theirs/a.txt, line 2: expected 4 numbers 'x,y,w,h'"),
    ("lines", r"sequence 'a': .*ours/a.txt has 5 lines but .*theirs/a.txt has 4"),
    ("frames", r"sequence 'a': .*ours/a.txt and .*theirs/a.txt have 5 lines but the sequence has 6 frames"),
    ("nothing", "no sequence has results in both"),
])
def test_bad_input_is_one_line_naming_what(folders, tmp_path, capsys, monkeypatch, case, message):
    ours, theirs = folders
    seqs = [sequence("a")]
    if case == "missing":
        theirs = tmp_path / "nowhere"
    elif case == "columns":
        (theirs / "a.txt").write_text("11,11,10,10\n11,11,10\n11,11,10,10\n11,11,10,10\n11,11,10,10\n")
    elif case == "lines":
        write(theirs, "a", A_REFERENCE[:4])
    elif case == "frames":
        seqs = [dataclasses.replace(sequence("a"), frames=tuple(Path(f"{k}.jpg") for k in range(6)),
                                    ground_truth=np.tile(GT[:1], (6, 1)))]
    elif case == "nothing":
        seqs = [sequence("zzz")]
    with pytest.raises(DatasetError, match=message):
        compare_folders(ours, theirs, seqs)
    import dcfkit.cli.evaluate

    monkeypatch.setattr(dcfkit.cli.evaluate, "load_datasets", lambda *a, **k: seqs)
    assert cli.main(["compare", str(ours), str(theirs), "--root", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert err.startswith("dcfkit compare: error: ") and "Traceback" not in err and len(err.splitlines()) == 1


def test_divergence_px_must_be_a_distance(folders, capsys):
    ours, theirs = folders
    with pytest.raises(SystemExit):
        cli.main(["compare", str(ours), str(theirs), "--root", ".", "--divergence-px", "-1"])
    assert "expected a distance in pixels >= 0, got '-1'" in capsys.readouterr().err


# --------------------------------------------------------------------------- the authors' results


@pytest.fixture(scope="module")
def uav(shared_data):
    from dcfkit.datasets import load_dataset

    return load_dataset("uav123_10fps", shared_data / "UAV123_10fps")


def test_reference_results_against_themselves_and_another_tracker(shared_data, uav):
    refs = shared_data / "reference_results"
    bacf = refs / "BACF" / "UAV123_10fps"
    same = compare_folders(bacf, bacf, uav)
    assert len(same["rows"]) == 6 and same["diverged"] == 0
    assert all(r["d_auc"] == 0 and r["d_precision"] == 0 and r["iou"] == 1 and r["diverges_at"] is None
               for r in same["rows"] + [same["mean"]])
    other = compare_folders(bacf, refs / "ARCF-HC" / "UAV123_10fps", uav)
    assert other["diverged"] >= 1 and other["mean"]["iou"] < 1
    assert all(r["diverges_at"] is None or 2 <= r["diverges_at"] <= r["frames"] for r in other["rows"])


def test_a_damaged_dcfkit_result_is_left_out_not_compared(tmp_path):
    from dcfkit.store.results import ResultStore

    seqs = [sequence("a"), sequence("b")]
    ours, theirs = tmp_path / "ours", tmp_path / "theirs"
    for seq in seqs:
        ours.mkdir(exist_ok=True)
        ResultStore(ours).write(seq, GT, {"run_key": "k"})  # as dcfkit eval stores them
        write(theirs, seq.name, GT + [1, 1, 0, 0])
    txt = ours / "b.txt"
    txt.write_bytes(txt.read_bytes()[:-6])  # the last height loses its decimals
    res = compare_folders(ours, theirs, seqs)
    assert [r["sequence"] for r in res["rows"]] == ["a"] and res["left_out"]["damaged"] == ["b"]
    assert res["rows"][0]["iou"] == 1.0


def test_the_comparison_carries_its_uncertainty(folders, tmp_path, capsys, monkeypatch):
    ours, theirs = folders
    seqs = [sequence("a"), sequence("b")]
    res = compare_folders(ours, theirs, seqs)
    d_auc = [r["d_auc"] for r in res["rows"]]  # a: 75/105 - 20/21 < 0; b: 0
    assert res["auc_difference"]["mean"] == pytest.approx(np.mean(d_auc))
    assert set(res["auc_difference"]) == {"mean", "ci_low", "ci_high"} == set(res["precision_difference"])
    assert res["wilcoxon_p"] == 1.0 and res["precision_wilcoxon_p"] == 1.0  # one non-zero difference, or none
    auc = res["statistics"]["auc"]
    assert (auc["difference"].won, auc["difference"].lost, auc["difference"].tied) == (0, 1, 1)
    assert auc["results"].mean == pytest.approx(res["mean"]["auc"]) and auc["reference"].n == 2
    assert "bootstrap" in res["statistics"]["method"]
    import dcfkit.cli.evaluate

    monkeypatch.setattr(dcfkit.cli.evaluate, "load_datasets", lambda *a, **k: seqs)
    assert cli.main(["compare", str(ours), str(theirs), "--root", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    assert "statistics: 95% BCa bootstrap" in out
    assert f"AUC       ours {auc['results'].mean:.3f} [" in out and "won 0, lost 1, tied 1 of 2" in out
    assert cli.main(["compare", str(ours), str(theirs), "--root", str(tmp_path), "--format", "json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["auc_difference"] == pytest.approx(res["auc_difference"]) and data["wilcoxon_p"] == 1.0


def test_compare_says_whether_a_difference_exceeds_the_measured_platform_noise(folders, tmp_path, capsys,
                                                                                monkeypatch):
    ours, theirs = folders
    seqs = [sequence("a"), sequence("b")]
    floor = compare_folders(ours, theirs, seqs)["noise_floor"]
    # a: 75/105 - 20/21 = -0.238 beyond 0.012; b: identical. Mean -0.119: beyond
    assert floor["sequences_beyond"] == ["a"] and floor["exceeds"]
    assert floor["mean_auc_difference"] == pytest.approx((75 / 105 - 20 / 21) / 2)
    write(ours, "b", [[11, 11, 10, 10], [11, 11, 10, 10], [float("nan")] * 4, [11, 11, 10, 10], [11.1, 11, 10, 10]])
    near = compare_folders(ours, theirs, [sequence("b")])["noise_floor"]  # one frame 0.1 px off: AUC unchanged
    assert not near["exceeds"] and near["sequences_beyond"] == []
    import dcfkit.cli.evaluate

    monkeypatch.setattr(dcfkit.cli.evaluate, "load_datasets", lambda *a, **k: [sequence("b")])
    assert cli.main(["compare", str(ours), str(theirs), "--root", str(tmp_path)]) == 0
    assert "the mean AUC difference, +0.000, is within it: not a finding; 0 of 1 sequences" in capsys.readouterr().out


def test_the_noise_floor_is_what_results_md_measured():
    """PLATFORM_NOISE restates docs/results.md: a new measurement changes both."""
    page = (Path(__file__).resolve().parents[2] / "docs" / "results.md").read_text(encoding="utf-8")
    section = page[page.index("**The noise floor.**"):]
    section = section[:section.index("\n\n")]
    assert f"up to {PLATFORM_NOISE['auc_sequence']:.3f} AUC for the shipped configs" in section
    assert (f"up to {PLATFORM_NOISE['auc_mean_of_8']:.3f} AUC ({PLATFORM_NOISE['precision_mean_of_8']:.3f} precision) "
            f"on the mean of eight") in section


def test_platform_differences_are_counted_per_sequence_not_per_pair_of_records(tmp_path, monkeypatch):
    """Sidecars whose records differ per sequence: each sequence's two records are compared once
    (the pairs of all distinct records took 105 s for 2,000 sequences), and the printout is a
    bounded list of distinct differences with their counts."""
    n = 60
    seqs = [sequence(f"s{k}") for k in range(n)]
    for folder, cpu in (("ours", "A"), ("theirs", "B")):
        (tmp_path / folder).mkdir()
        store = ResultStore(tmp_path / folder)
        for k, seq in enumerate(seqs):
            record = {"arch": "x86_64", "cpu": f"CPU {cpu}{k}", "blas": "openblas" if k % 2 else "mkl"}
            store.write(seq, GT, {"platform": record})
    calls = []
    real = platforms.differences
    monkeypatch.setattr(platforms, "differences", lambda a, b: calls.append(1) or real(a, b))
    res = compare_folders(tmp_path / "ours", tmp_path / "theirs", seqs)
    assert len(calls) == n
    found = res["platform_differences"]
    assert len(found) == 11 and found[-1] == f"and {n - 10} more"  # ten lines and the count of the others
    assert all(line.startswith("cpu: CPU A") and line.endswith(f" (1 of {n} sequences)") for line in found[:-1])
    assert len(res["platforms"]["reference"]) == 11 and "(1 of 60 sequences)" in res["platforms"]["reference"][0]


def test_a_non_finite_score_is_named_and_given_no_verdict(tmp_path, monkeypatch, capsys):
    """Sequences scoreable on their first frame only (GOT-10k leaves it out): NaN scores, named and
    left out of the statistics and the noise floor's mean; no verdict when nothing is left."""
    ours, theirs = tmp_path / "ours", tmp_path / "theirs"
    seqs = [sequence("one", 1), sequence("two", 1), sequence("a")]
    for seq in seqs:
        write(ours, seq.name, A_RESULTS[:len(seq)])
        write(theirs, seq.name, A_REFERENCE[:len(seq)])
    res = compare_folders(ours, theirs, seqs, "got10k")
    assert res["statistics"]["auc"]["non_finite"] == ["one", "two"] == res["noise_floor"]["non_finite"]
    assert res["noise_floor"]["mean_auc_difference"] == pytest.approx(res["rows"][2]["d_auc"])
    import dcfkit.cli.evaluate

    for given, expected in ((seqs, "the mean AUC difference over the 1 sequence with one (left out, a non-finite "
                                   "AUC (no frame counted) in 2 sequences (one, two)), -0.322, exceeds it"),
                            (seqs[:2], "no verdict: no sequence has a finite AUC difference (a non-finite AUC (no "
                                       "frame counted) in 2 sequences (one, two))")):
        monkeypatch.setattr(dcfkit.cli.evaluate, "load_datasets", lambda *a, given=given, **k: given)
        assert cli.main(["compare", str(ours), str(theirs), "--root", str(tmp_path), "--protocol", "got10k"]) == 0
        out = capsys.readouterr().out
        assert expected in out and "nan" not in out.split("noise floor:")[1]
        assert "left out, a non-finite AUC (no frame counted) in 2 sequences (one, two)" in out


def test_a_line_break_in_a_platform_record_stays_on_its_line(tmp_path, monkeypatch, capsys):
    """An environment value with a line break (a hostile or broken sidecar) is printed escaped:
    it cannot forge a line of compare's output."""
    seqs = [sequence("a")]
    for folder, value in (("ours", "Haswell"), ("theirs", "Haswell\nwarning: forged\r")):
        (tmp_path / folder).mkdir()
        ResultStore(tmp_path / folder).write(seqs[0], GT, {"platform": {"switches": {"OPENBLAS_CORETYPE": value}}})
    import dcfkit.cli.evaluate

    monkeypatch.setattr(dcfkit.cli.evaluate, "load_datasets", lambda *a, **k: seqs)
    assert cli.main(["compare", str(tmp_path / "ours"), str(tmp_path / "theirs"), "--root", str(tmp_path)]) == 0
    out, err = capsys.readouterr()
    lines = (out + err).splitlines()
    assert not any(line.startswith("warning: forged") for line in lines)
    forged = "OPENBLAS_CORETYPE=Haswell\\nwarning: forged\\r"
    assert any(line.startswith("theirs platform: ") and line.endswith(forged) for line in lines)
    assert "OPENBLAS_CORETYPE: Haswell -> Haswell\\nwarning: forged\\r" in err


def test_each_side_is_named_by_its_name_or_folder(tmp_path):
    from dcfkit.cli.evaluate import side_names

    a, b = tmp_path / "run1" / "kcf", tmp_path / "run2" / "kcf"
    assert side_names(((None, a), (None, tmp_path / "dsst"))) == ["kcf", "dsst"]
    assert side_names(((None, a), (None, b))) == ["run1/kcf", "run2/kcf"]  # one folder name: with the parents
    assert side_names((("mine", a), (None, b))) == ["mine", "kcf"]
    assert side_names(((None, a), (None, a))) == ["RESULTS", "REFERENCE"]  # a folder with itself
    assert side_names((("x\ny", a), (None, b))) == ["x\\ny", "kcf"]  # a name cannot forge a line

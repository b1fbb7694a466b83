"""The results store: damaged results are detected, recomputed and never scored; folders that
cannot take results fail before any tracking; one run key for eval and ablate."""
from __future__ import annotations

import contextlib
import errno
import json
import os
import re
import signal
import tempfile

import numpy as np
import pytest
from test_evaluation import CONFIG, Counter, seqs  # noqa: F401  (seqs: a fixture)

from dcfkit.analysis import report
from dcfkit.analysis.scoring import evaluate
from dcfkit.errors import DcfkitError
from dcfkit.store import files, results
from dcfkit.running.evaluation import run_one_pass
from dcfkit.store.provenance import run_key
from dcfkit.store.results import ResultStore, load_results


@contextlib.contextmanager
def unwritable(monkeypatch, folder):
    """``folder`` refuses new files: by its mode, or (as root, whom modes do not stop) by
    making ``tempfile.mkstemp`` fail there as the kernel would."""
    folder.mkdir(parents=True, exist_ok=True)
    if os.geteuid() != 0:
        folder.chmod(0o555)
        try:
            yield
        finally:
            folder.chmod(0o755)
        return
    real = tempfile.mkstemp

    def mkstemp(*args, dir=None, **kwargs):
        if dir is not None and os.path.realpath(dir) == os.path.realpath(folder):
            raise PermissionError(errno.EACCES, os.strerror(errno.EACCES))
        return real(*args, dir=dir, **kwargs)

    with monkeypatch.context() as m:
        m.setattr(tempfile, "mkstemp", mkstemp)
        yield


def cut(path, n_bytes=6):
    """``truncate -s -6 path``: a height 145.346 becomes 14, and the last line loses its end."""
    data = path.read_bytes()
    path.write_bytes(data[:-n_bytes])


def test_a_result_file_cut_short_is_never_scored_and_is_recomputed(tmp_path, seqs, caplog):
    run_one_pass(CONFIG, seqs, tmp_path, make_tracker=Counter(), progress=False)
    good = (tmp_path / "drift" / "a.txt").read_bytes()
    cut(tmp_path / "drift" / "a.txt")
    # not scored: load_results leaves it out and says why, so report counts it as missing
    loaded = load_results(tmp_path, "drift", seqs)
    assert sorted(loaded) == ["b", "c"]
    assert "a.txt is not the file its run wrote" in caplog.text
    scores = evaluate({"drift": loaded}, seqs)
    assert scores.overall[0]["missing"] == 1
    # recomputed: the next run redoes exactly that sequence
    counter = Counter()
    summary = run_one_pass(CONFIG, seqs, tmp_path, make_tracker=counter, progress=False)
    assert summary["done"] == ["a"] and summary["skipped"] == ["b", "c"] and counter.made == 1
    assert (tmp_path / "drift" / "a.txt").read_bytes() == good


@pytest.mark.parametrize("damage", ["edited", "emptied", "sidecar_frames"])
def test_other_damage_is_detected_too(tmp_path, seqs, damage):
    run_one_pass(CONFIG, seqs[:1], tmp_path, make_tracker=Counter(), progress=False)
    txt, side = tmp_path / "drift" / "a.txt", tmp_path / "drift" / "a.json"
    if damage == "edited":  # same length, one digit changed
        txt.write_text(txt.read_text().replace("4.000", "5.000", 1))
    elif damage == "emptied":
        txt.write_text("")
    else:  # a sidecar that claims another frame count than the sequence has
        meta = json.loads(side.read_text())
        meta["frames"] += 1
        side.write_text(json.dumps(meta))
    store = ResultStore(tmp_path / "drift")
    assert store.status(seqs[0], run_key(CONFIG)) == "damaged"
    assert store.load(seqs[:1]) == {}


def test_results_of_dcfkit_before_0_4_are_scored_if_intact_and_recomputed_by_eval(tmp_path, seqs, caplog):
    """Sidecars of dcfkit < 0.4 have no checksum (and the key under ``config_hash``): report
    checks their lines against the format dcfkit wrote; eval runs them again (another key)."""
    run_one_pass(CONFIG, seqs[:2], tmp_path, make_tracker=Counter(), progress=False)
    for name in ("a", "b"):
        side = tmp_path / "drift" / f"{name}.json"
        meta = json.loads(side.read_text())
        meta["config_hash"] = meta.pop("run_key")
        del meta["sha256"]
        side.write_text(json.dumps(meta))
    cut(tmp_path / "drift" / "b.txt")
    loaded = load_results(tmp_path, "drift", seqs[:2])
    assert sorted(loaded) == ["a"] and "b.txt (written by dcfkit < 0.4, without a checksum)" in caplog.text
    assert run_one_pass(CONFIG, seqs[:2], tmp_path, make_tracker=Counter(), progress=False)["done"] == ["a", "b"]


def test_an_unwritable_results_folder_fails_before_any_tracking(tmp_path, seqs, monkeypatch):
    counter = Counter()
    with unwritable(monkeypatch, tmp_path / "drift"):
        with pytest.raises(DcfkitError, match=r"cannot write drift's results to .*drift"):
            run_one_pass(CONFIG, seqs, tmp_path, make_tracker=counter, progress=False)
    assert counter.made == 0


def test_a_folder_where_a_result_file_goes_fails_before_any_tracking(tmp_path, seqs):
    (tmp_path / "drift" / "b.json").mkdir(parents=True)
    counter = Counter()
    with pytest.raises(DcfkitError, match=r"cannot write drift's results to .*drift: b\.json is a folder"):
        run_one_pass(CONFIG, seqs, tmp_path, make_tracker=counter, progress=False)
    assert counter.made == 0


def test_a_write_that_fails_mid_run_is_a_clear_error_and_keeps_earlier_sequences(tmp_path, seqs, monkeypatch):
    real = results.atomic_write

    def full_disk(path, text):
        if path.name.startswith("b."):
            raise DcfkitError(f"cannot write {path}: No space left on device")
        real(path, text)

    monkeypatch.setattr(results, "atomic_write", full_disk)
    with pytest.raises(DcfkitError, match=r"cannot write .*b\.txt: No space left"):
        run_one_pass(CONFIG, seqs, tmp_path, make_tracker=Counter(), progress=False)
    assert sorted(load_results(tmp_path, "drift", seqs)) == ["a"]


def test_atomic_write_names_the_file_it_cannot_write(tmp_path, monkeypatch):
    with unwritable(monkeypatch, tmp_path / "ro"):
        with pytest.raises(DcfkitError, match=r"cannot write .*ro/x\.txt: Permission denied"):
            results.atomic_write(tmp_path / "ro" / "x.txt", "1\n")


def test_report_into_an_unwritable_folder_is_a_clear_error(tmp_path, seqs, monkeypatch):
    run_one_pass(CONFIG, seqs, tmp_path / "out", make_tracker=Counter(), progress=False)
    with unwritable(monkeypatch, tmp_path / "out_report"):
        with pytest.raises(DcfkitError, match=r"cannot write the report to .*out_report: Permission denied"):
            report.write_report(tmp_path / "out", seqs)


def test_the_report_goes_beside_the_results_where_a_tracker_named_report_is_a_tracker(tmp_path, seqs):
    """pysot's eval.py takes every folder of OUT for a tracker: a report is written beside it."""
    run_one_pass({**CONFIG, "name": "report"}, seqs, tmp_path / "out", make_tracker=Counter(), progress=False)
    run_one_pass(CONFIG, seqs, tmp_path / "out", make_tracker=Counter(), progress=False)
    paths = report.write_report(tmp_path / "out", seqs)
    assert {p.parent for p in paths} == {tmp_path / "out_report"}
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == ["drift", "report"]
    data = json.loads((tmp_path / "out_report" / "report.json").read_text())
    assert sorted(r["tracker"] for r in data["overall"]) == ["drift", "report"]
    assert report.default_report_dir(tmp_path / "out", experiment="tre") == tmp_path / "out_report" / "tre"
    # a report folder put in OUT is still not taken for a tracker
    report.write_report(tmp_path / "out", seqs, trackers=["drift"], report_dir=tmp_path / "out" / "tables")
    assert sorted(report.gather_results(tmp_path / "out", seqs, exclude=[tmp_path / "out" / "tables"])) == \
        ["drift", "report"]


@pytest.mark.parametrize("blocked", ["precision.png", "overall.txt", "success_SV.svg"])
def test_a_folder_where_a_report_file_goes_is_refused_before_scoring(tmp_path, seqs, blocked, monkeypatch):
    run_one_pass(CONFIG, seqs, tmp_path / "out", make_tracker=Counter(), progress=False)
    (tmp_path / "out_report" / blocked).mkdir(parents=True)
    monkeypatch.setattr(report, "evaluate", lambda *a, **k: pytest.fail("scored before the check"))
    with pytest.raises(DcfkitError, match=rf"cannot write the report to .*report: {re.escape(blocked)} is a folder"):
        report.write_report(tmp_path / "out", seqs)


def test_a_report_folder_that_holds_a_trackers_results_is_refused(tmp_path, seqs):
    run_one_pass(CONFIG, seqs, tmp_path / "out", make_tracker=Counter(), progress=False)
    (tmp_path / "out" / "report").mkdir()
    for s in seqs:
        (tmp_path / "out" / "report" / f"{s.name}.txt").write_text((tmp_path / "out" / "drift" / f"{s.name}.txt")
                                                                   .read_text())
    with pytest.raises(DcfkitError, match=r"report holds a tracker's results; write the report elsewhere"):
        report.write_report(tmp_path / "out", seqs, report_dir=tmp_path / "out" / "report")


def test_eval_and_ablate_share_one_run_key():
    """The key leaves out what names a run (name, description) and keeps what changes boxes."""
    config = {"name": "a", "description": "x", "features": [{"name": "gray"}], "label": {"name": "gaussian"}}
    assert run_key(config) == run_key({**config, "name": "b", "description": "y"})
    assert run_key(config) != run_key({**config, "label": {"name": "dr2track"}})
    assert run_key(config, "1.0") != run_key(config, "1.1")


def test_the_sidecar_records_the_checksum_of_the_boxes_as_written(tmp_path, seqs):
    run_one_pass(CONFIG, seqs[:1], tmp_path, make_tracker=Counter(), progress=False)
    meta = json.loads((tmp_path / "drift" / "a.json").read_text())
    import hashlib

    assert meta["sha256"] == hashlib.sha256((tmp_path / "drift" / "a.txt").read_bytes()).hexdigest()
    assert meta["frames"] == len(seqs[0]) and meta["run_key"] == run_key(CONFIG)
    np.testing.assert_array_equal(load_results(tmp_path, "drift", seqs[:1])["a"].boxes[:, 1:],
                                  np.tile([3.0, 5.0, 6.0], (len(seqs[0]), 1)))


class Blocker:
    """A picklable make_tracker that, when it builds the tracker of sequence b's run, puts a
    folder where b's result file goes (a disk that fills up, a file system gone read-only)."""

    def __init__(self, folder):
        self.folder = folder

    def __call__(self, config):
        from test_evaluation import DriftTracker

        tracker = DriftTracker(config)
        real_init = tracker.init

        def init(image, box):
            if int(image[0, 0, 0]) == 10:  # sequence b's first frame
                os.makedirs(os.path.join(self.folder, "b.txt"), exist_ok=True)
            real_init(image, box)
        tracker.init = init
        return tracker


@pytest.mark.parametrize("jobs", [1, 2])
def test_a_write_failure_mid_run_stops_the_run_whatever_the_jobs(tmp_path, seqs, jobs):
    with pytest.raises(files.StoreError, match=r"cannot write .*b\.txt"):
        run_one_pass(CONFIG, seqs, tmp_path, make_tracker=Blocker(str(tmp_path / "drift")), jobs=jobs,
                     progress=False)
    assert "b" not in load_results(tmp_path, "drift", seqs)


def test_a_terminated_eval_keeps_finished_sequences_and_leaves_no_partial_file(tmp_path, seqs):
    from test_evaluation import DriftTracker

    from dcfkit.signals import Interrupted, interrupt_on_termination

    class Terminated(DriftTracker):
        def update(self, image):
            if int(image[0, 0, 0]) == 12:  # sequence b, frame 3: as `kill -TERM` would
                os.kill(os.getpid(), signal.SIGTERM)
            return super().update(image)

    with pytest.raises(Interrupted):
        with interrupt_on_termination():
            run_one_pass(CONFIG, seqs, tmp_path, make_tracker=Terminated, progress=False)
    assert sorted(load_results(tmp_path, "drift", seqs)) == ["a"]
    assert sorted(p.name for p in (tmp_path / "drift").iterdir()) == [".locks", "a.confidence", "a.json", "a.time", "a.txt"]


def test_finished_results_in_a_read_only_folder_are_still_scored(tmp_path, seqs, monkeypatch):
    run_one_pass(CONFIG, seqs, tmp_path, make_tracker=Counter(), progress=False)
    with unwritable(monkeypatch, tmp_path / "drift"):
        summary = run_one_pass(CONFIG, seqs, tmp_path, make_tracker=Counter(), progress=False)
    assert summary["skipped"] == ["a", "b", "c"]


def test_a_file_named_locks_only_costs_the_locks(tmp_path, seqs, caplog):
    (tmp_path / "drift").mkdir()
    (tmp_path / "drift" / ".locks").write_text("")
    assert run_one_pass(CONFIG, seqs, tmp_path, make_tracker=Counter(), progress=False)["done"] == ["a", "b", "c"]
    assert "running without it" in caplog.text


def test_any_sequence_names_have_files_of_their_own(tmp_path, capsys):
    """``car``, ``car_time``, ``car_confidence`` and ``car.error`` in one OTB root, run with two
    workers: each sequence's files are those of its run alone, byte for byte, and ``report``
    and ``compare`` score all four."""
    import cv2

    from dcfkit.cli import main
    from dcfkit.datasets.synthetic import make_sequence

    names = ["car", "car_time", "car_confidence", "car.error"]
    root = tmp_path / "data"
    for seed, name in enumerate(names):
        seq = make_sequence(n_frames=8, size=(96, 128), target=(14, 18), seed=seed)
        (root / name / "img").mkdir(parents=True)
        for k, frame in enumerate(seq.frames):
            cv2.imwrite(str(root / name / "img" / f"{k + 1:04d}.jpg"), frame)
        (root / name / "groundtruth_rect.txt").write_text(
            "".join("%g,%g,%g,%g\n" % tuple(b) for b in seq.ground_truth + [1, 1, 0, 0]))
    eval_args = ["eval", "kcf", "--dataset", "otb", "--root", str(root), "--no-progress"]
    assert main([*eval_args, "--out", str(tmp_path / "together"), "--jobs", "2"]) == 0
    for name in names:
        assert main([*eval_args, "--out", str(tmp_path / "alone" / name), "--sequences", name]) == 0
    together = tmp_path / "together" / "kcf"
    for name in names:
        alone = tmp_path / "alone" / name / "kcf"
        for end in (".txt", ".confidence"):
            assert (together / f"{name}{end}").read_bytes() == (alone / f"{name}{end}").read_bytes(), (name, end)
    capsys.readouterr()
    assert main(["report", str(tmp_path / "together"), "--dataset", "otb", "--root", str(root)]) == 0
    out = capsys.readouterr()
    fps = r"(?:[\d.]+|-)"  # - when the runs shared a pool
    assert not out.err and re.search(rf"\nkcf +[\d.]+ +[\d.]+ +[\d.]+ +{fps} +4 +0\n", out.out), out
    assert main(["compare", str(together), str(together), "--dataset", "otb", "--root", str(root),
                 "--format", "csv"]) == 0
    rows = capsys.readouterr().out.strip().splitlines()[1:]
    assert sorted(row.split(",")[0] for row in rows) == sorted(names + ["mean"])

"""Runner (files, resume, atomicity, failure isolation, process pool), OpenCV baselines,
result import and reports — with fake trackers, independent of the dcfkit core."""
from __future__ import annotations

import argparse
import dataclasses
import json
import os
import re
import warnings
from pathlib import Path

import cv2
import numpy as np
import pytest

from dcfkit.analysis import report, tables
from dcfkit.analysis.scoring import evaluate
from dcfkit.cli import evaluate as cli_evaluate
from dcfkit.datasets import DatasetError, Sequence, load_dataset
from dcfkit.errors import ConfigError, DcfkitError
from dcfkit.integrations.opencv import OpenCVUnavailable, available_opencv_trackers, opencv_tracker
from dcfkit.registry import PluginWarning
from dcfkit.running import runner
from dcfkit.store import provenance, results
from dcfkit.store import files as store_files
from dcfkit.running.evaluation import run_one_pass
from dcfkit.store.provenance import run_key
from dcfkit.store.results import import_results, load_results

N_FRAMES = 6


class Crash(KeyboardInterrupt):
    """Stands for the process dying: an interruption, which nothing catches (a component's other
    BaseExceptions fail its sequence, tests/test_tracking.py)."""


class DriftTracker:
    """Returns the initial box moved ``drift`` px right per frame; optionally fails."""

    def __init__(self, config, fail_at=None, error=ValueError):
        self.drift = float(config.get("drift", 1.0))
        self.fail_at, self.error = fail_at, error

    def init(self, image, box):
        assert image.dtype == np.uint8 and image.ndim == 3
        self.box, self.k = np.asarray(box, dtype=float), 0

    def update(self, image):
        self.k += 1
        if self.k == self.fail_at:
            raise self.error("boom")
        return self.box + [self.drift * self.k, 0, 0, 0]


def make_drift(config):
    """Module-level (picklable) factory for jobs > 1."""
    return DriftTracker(config)


class Counter:
    """A factory counting the trackers it makes; ``plan`` maps the n-th tracker to a failure."""

    def __init__(self, plan=None):
        self.made, self.plan = 0, plan or {}

    def __call__(self, config):
        self.made += 1
        fail_at, error = self.plan.get(self.made, (None, ValueError))
        return DriftTracker(config, fail_at, error)


def gt_boxes(n=N_FRAMES, x0=2.0):
    return np.array([[x0 + k, 3, 5, 6] for k in range(n)], dtype=float)


@pytest.fixture
def seqs(tmp_path):
    out = []
    for i, name in enumerate("abc"):
        folder = tmp_path / "data" / name
        folder.mkdir(parents=True)
        frames = []
        for k in range(N_FRAMES):
            f = folder / f"{k + 1:05d}.jpg"
            cv2.imwrite(str(f), np.full((16, 16, 3), 10 * i + k, np.uint8))
            frames.append(f)
        out.append(Sequence(name, tuple(frames), gt_boxes(), {"SV": i != 1, "FM": i == 2}, "fake"))
    return out


CONFIG = {"name": "drift", "drift": 1.0}


def files(folder: Path) -> set[str]:
    """Result files in ``folder`` (not the ``.locks`` folder of ``run_one_pass``)."""
    return {p.name for p in folder.iterdir() if p.name != ".locks"}


# --------------------------------------------------------------------------- output files


def test_result_files_are_one_based_with_sidecar(tmp_path, seqs):
    summary = run_one_pass(CONFIG, seqs, tmp_path / "out", make_tracker=Counter(), progress=False)
    assert summary["done"] == ["a", "b", "c"] and not summary["failed"] and not summary["skipped"]
    d = tmp_path / "out" / "drift"
    assert files(d) == {f"{n}{end}" for n in "abc" for end in (".txt", ".json", ".time", ".confidence")}
    lines = (d / "a.txt").read_text().splitlines()
    assert lines[0] == "3.000,4.000,5.000,6.000"  # 0-based (2, 3) written 1-based
    assert lines[5] == "8.000,4.000,5.000,6.000"
    meta = json.loads((d / "a.json").read_text())
    assert meta["run_key"] == run_key(CONFIG) == summary["run_key"]
    assert meta["dcfkit_version"] == provenance.dcfkit_version()
    assert len(meta["times"]) == N_FRAMES and meta["fps"] > 0 and meta["config"] == CONFIG
    times = np.loadtxt(d / "a.time")  # the toolkits' time file: one float a line
    np.testing.assert_allclose(times, meta["times"], atol=1e-8)
    # DriftTracker has no last_confidence: every line nan,nan,nan
    assert (d / "a.confidence").read_text() == "nan,nan,nan\n" * N_FRAMES
    res = load_results(tmp_path / "out", "drift", seqs)
    np.testing.assert_allclose(res["b"].boxes, gt_boxes())
    assert res["b"].times.shape == (N_FRAMES,) and res["b"].fps > 0


def test_run_key_is_canonical():
    assert run_key({"a": 1, "b": {"c": 2, "d": 3}}) == run_key({"b": {"d": 3, "c": 2}, "a": 1})
    assert run_key({"a": 1}) != run_key({"a": 2})
    assert run_key({"a": 1}, "1.0") != run_key({"a": 1}, "1.1")
    assert run_key({"a": (1, 2)}) == run_key({"a": [1, 2]})


def test_nan_first_box_and_bad_name_are_errors(tmp_path, seqs):
    gt = gt_boxes()
    gt[0] = np.nan
    bad = dataclasses.replace(seqs[1], ground_truth=gt)
    with pytest.raises(DatasetError, match="sequence.*: b"):
        run_one_pass(CONFIG, [seqs[0], bad], tmp_path, make_tracker=Counter(), progress=False)
    with pytest.raises(ValueError, match="'name'"):
        run_one_pass({"drift": 1}, seqs, tmp_path, make_tracker=Counter(), progress=False)
    anno = tmp_path / "anno" / "b.txt"
    named = dataclasses.replace(bad, annotation=anno)
    with pytest.raises(DatasetError, match=f"b \\(first box in {re.escape(str(anno))}\\)"):
        run_one_pass(CONFIG, [named], tmp_path, make_tracker=Counter(), progress=False)


# --------------------------------------------------------------------------- resume and atomicity


def test_resume_recomputes_nothing(tmp_path, seqs, caplog, monkeypatch):
    first = Counter()
    run_one_pass(CONFIG, seqs, tmp_path, make_tracker=first, progress=False)
    assert first.made == 3
    again = Counter()
    summary = run_one_pass(CONFIG, seqs, tmp_path, make_tracker=again, progress=False)
    assert again.made == 0 and summary["skipped"] == ["a", "b", "c"] and summary["done"] == []
    # a truncated result file is not done, even with its sidecar present
    txt = tmp_path / "drift" / "b.txt"
    txt.write_text("".join(txt.read_text().splitlines(keepends=True)[:3]))
    third = Counter()
    assert run_one_pass(CONFIG, seqs, tmp_path, make_tracker=third, progress=False)["done"] == ["b"]
    assert third.made == 1
    # another config (same name) is recomputed, with a warning
    fourth = Counter()
    with caplog.at_level("WARNING"):
        run_one_pass({**CONFIG, "drift": 2.0}, seqs, tmp_path, make_tracker=fourth, progress=False)
    assert fourth.made == 3
    assert "replacing the results of another config named 'drift' for 3 sequence(s): a, b, c" in caplog.text
    # the same config under another dcfkit version is recomputed without that warning
    caplog.clear()
    monkeypatch.setattr(provenance, "dcfkit_version", lambda: "99.0")
    with caplog.at_level("WARNING"):
        summary = run_one_pass({**CONFIG, "drift": 2.0}, seqs, tmp_path, make_tracker=Counter(), progress=False)
    assert summary["done"] == ["a", "b", "c"] and "replacing" not in caplog.text


def test_resume_checks_the_initial_box_and_the_benchmark(tmp_path, seqs):
    run_one_pass(CONFIG, seqs, tmp_path, make_tracker=Counter(), progress=False)
    # a corrected annotation (another first box) makes the old boxes stale: run again
    moved = dataclasses.replace(seqs[0], ground_truth=gt_boxes(x0=4.0))
    again = Counter()
    assert run_one_pass(CONFIG, [moved, *seqs[1:]], tmp_path, make_tracker=again, progress=False)["done"] == ["a"]
    assert again.made == 1
    # results of one benchmark are never replaced by a same-named sequence of another
    other = dataclasses.replace(seqs[1], dataset="otb")
    with pytest.raises(DatasetError, match=r"b.json holds results on dataset 'fake', and this run is on 'otb': "
                                           r"use a separate --out"):
        run_one_pass({**CONFIG, "drift": 3.0}, [other], tmp_path, make_tracker=Counter(), progress=False)
    assert json.loads((tmp_path / "drift" / "b.json").read_text())["dataset"] == "fake"


@pytest.mark.parametrize("content", ["[]", '"x"', "{bad"])
def test_a_sidecar_that_is_not_an_object_means_not_done(tmp_path, seqs, content):
    run_one_pass(CONFIG, seqs, tmp_path, make_tracker=Counter(), progress=False)
    (tmp_path / "drift" / "b.json").write_text(content)  # used to crash eval, report and ablate
    assert "b" not in load_results(tmp_path, "drift", seqs)
    rerun = Counter()
    assert run_one_pass(CONFIG, seqs, tmp_path, make_tracker=rerun, progress=False)["done"] == ["b"]


@pytest.mark.parametrize("field,value", [("times", "abc"), ("times", [1, [2, 3]]), ("fps", "fast"),
                                         ("fps", [1]), ("run_key", [1])])
def test_a_sidecar_with_wrong_types_is_named_left_out_and_recomputed(tmp_path, seqs, field, value, caplog):
    run_one_pass(CONFIG, seqs, tmp_path, make_tracker=Counter(), progress=False)
    side = tmp_path / "drift" / "b.json"
    side.write_text(json.dumps({**json.loads(side.read_text()), field: value}))
    assert sorted(load_results(tmp_path, "drift", seqs)) == ["a", "c"]
    assert re.search(rf"b\.json is malformed \({field} is .*\): left out; run it again", caplog.text)
    assert run_one_pass(CONFIG, seqs, tmp_path, make_tracker=Counter(), progress=False)["done"] == ["b"]


def test_workers_leave_plugin_warnings_to_the_parent(monkeypatch):
    for var in runner._THREAD_VARS:
        monkeypatch.setenv(var, os.environ.get(var, "1"))  # restored after the test
    threads = cv2.getNumThreads()
    try:
        with warnings.catch_warnings(record=True) as shown:
            warnings.simplefilter("always")
            runner.worker_init()
            warnings.warn("dcfkit plugin 'x' failed and was skipped: boom", PluginWarning)
            warnings.warn("something else", RuntimeWarning)
    finally:
        cv2.setNumThreads(threads)
    assert [str(w.message) for w in shown] == ["something else"]


def test_results_folder_that_is_a_file_is_a_clear_error(tmp_path, seqs):
    (tmp_path / "drift").write_text("")
    with pytest.raises(DcfkitError, match=r"cannot create the folder .*drift"):
        run_one_pass(CONFIG, seqs, tmp_path, make_tracker=Counter(), progress=False)
    run_one_pass(CONFIG, seqs, tmp_path / "out", make_tracker=Counter(), progress=False)
    (tmp_path / "report").write_text("")
    with pytest.raises(DcfkitError, match=r"cannot create the folder .*report"):
        report.write_report(tmp_path / "out", seqs, report_dir=tmp_path / "report")


def test_default_trackers_are_warmed_up_once_per_process_and_config(tmp_path, seqs, monkeypatch):
    made = []

    def factory(config):
        made.append(RecordingTracker(config))
        return made[-1]

    class RecordingTracker(DriftTracker):
        def init(self, image, box):
            self.calls = ["init"]
            super().init(image, box)

        def update(self, image):
            self.calls.append("update")
            return super().update(image)

    monkeypatch.setattr(runner, "load_dcfkit_tracker", factory)
    monkeypatch.setattr(runner, "_warmed_up", set())
    run_one_pass(CONFIG, seqs, tmp_path, progress=False)
    # the throw-away tracker (one init and one update), then one per sequence
    assert len(made) == 4 and made[0].calls == ["init", "update"]
    assert [len(t.calls) for t in made] == [2, N_FRAMES, N_FRAMES, N_FRAMES]
    run_one_pass({**CONFIG, "drift": 2.0}, seqs, tmp_path, progress=False)
    assert len(made) == 8  # a new config is warmed up again
    # a user's factory is used as given: one tracker per sequence, no throw-away copy
    custom = Counter()
    run_one_pass({**CONFIG, "drift": 3.0}, seqs, tmp_path, make_tracker=custom, progress=False)
    assert custom.made == 3
    # an unreadable first frame is reported as frame 1 of its file, warm-up or not
    seqs[0].frames[0].write_bytes(b"not an image")
    summary = run_one_pass({**CONFIG, "drift": 4.0}, seqs[:1], tmp_path, progress=False)
    record = json.loads((tmp_path / "drift" / "a.error").read_text())
    assert record["frame"] == 1 and record["frame_file"] == str(seqs[0].frames[0])
    assert "cannot read frame 1 " in summary["failed"]["a"]


def test_compiled_code_is_warmed_up_before_the_progress_bar_starts(tmp_path, seqs, monkeypatch):
    """A first run that compiles numba's kernels made the first time-left estimate ten times too
    long: one throw-away run per solver comes before eval's bar (every run plan's execute does it)."""
    import tqdm.auto

    from dcfkit.running.plan import Entry, RunPlan
    from dcfkit.running.progress import FrameBar

    events = []
    monkeypatch.setattr(runner, "_warmed_up", set())
    monkeypatch.setattr(runner, "load_dcfkit_tracker", lambda config: events.append(("tracker", config["solver"]))
                        or DriftTracker(config))
    real_bar = tqdm.auto.tqdm
    monkeypatch.setattr(tqdm.auto, "tqdm", lambda *a, **k: events.append("bar") or real_bar(*a, **k))
    configs = [{**CONFIG, "solver": {"name": name}, "drift": d} for name, d in (("a", 1.0), ("a", 2.0), ("b", 3.0))]
    plan = RunPlan([Entry(f"t{i}", c) for i, c in enumerate(configs)], seqs, "ope", tmp_path)
    plan.run("dcfkit eval", progress=FrameBar("t"))
    first_bar = events.index("bar")
    assert events[:first_bar] == [("tracker", {"name": "a"}), ("tracker", {"name": "b"})]  # one per solver
    tasks = len(configs) * len(seqs)
    assert events.count("bar") == 1 and len(events) == 1 + 2 + 1 + tasks  # drift 2.0: its own warm-up, later


def test_crash_mid_sequence_leaves_no_partial_result(tmp_path, seqs):
    with pytest.raises(Crash):
        run_one_pass(CONFIG, seqs, tmp_path, make_tracker=Counter({2: (3, Crash)}), progress=False)
    d = tmp_path / "drift"
    assert files(d) == {"a.txt", "a.json", "a.time", "a.confidence"}  # no half file, no temp file
    rerun = Counter()
    summary = run_one_pass(CONFIG, seqs, tmp_path, make_tracker=rerun, progress=False)
    assert rerun.made == 2 and summary["done"] == ["b", "c"] and summary["skipped"] == ["a"]


def test_crash_between_result_and_sidecar_is_not_done(tmp_path, seqs, monkeypatch):
    real_write = results.atomic_write

    def dying_write(path, text):
        if path.name == "b.json":
            raise Crash
        real_write(path, text)

    monkeypatch.setattr(results, "atomic_write", dying_write)
    with pytest.raises(Crash):
        run_one_pass(CONFIG, seqs, tmp_path, make_tracker=Counter(), progress=False)
    monkeypatch.undo()
    assert (tmp_path / "drift" / "b.txt").is_file() and not (tmp_path / "drift" / "b.json").exists()
    assert set(load_results(tmp_path, "drift", seqs)) == {"a"}
    rerun = Counter()
    assert run_one_pass(CONFIG, seqs, tmp_path, make_tracker=rerun, progress=False)["done"] == ["b", "c"]


def test_atomic_write_interrupted_keeps_old_file(tmp_path, monkeypatch):
    target = tmp_path / "x.txt"
    target.write_text("old\n")

    def boom(*a):
        raise Crash

    monkeypatch.setattr(store_files.os, "replace", boom)
    with pytest.raises(Crash):
        results.atomic_write(target, "new\n")
    assert target.read_text() == "old\n" and files(tmp_path) == {"x.txt"}


# --------------------------------------------------------------------------- failures


def test_tracker_failure_is_isolated_and_retried(tmp_path, seqs, caplog):
    summary = run_one_pass(CONFIG, seqs, tmp_path, make_tracker=Counter({2: (2, ValueError)}),
                           progress=False)
    assert summary["done"] == ["a", "c"] and list(summary["failed"]) == ["b"]
    message = summary["failed"]["b"]
    assert "'b'" in message and "frame 3 of 6" in message and "00003.jpg" in message and "boom" in message
    assert "frame 3 of 6" in caplog.text
    d = tmp_path / "drift"
    record = json.loads((d / "b.error").read_text())
    assert record["frame"] == 3 and record["type"] == "ValueError" and "boom" in record["traceback"]
    assert not (d / "b.txt").exists() and set(load_results(tmp_path, "drift", seqs)) == {"a", "c"}
    rerun = Counter()
    summary = run_one_pass(CONFIG, seqs, tmp_path, make_tracker=rerun, progress=False)
    assert rerun.made == 1 and summary["done"] == ["b"] and not (d / "b.error").exists()


def test_bad_box_and_factory_errors_are_failures(tmp_path, seqs):
    class NoneTracker(DriftTracker):
        def update(self, image):
            return None

    summary = run_one_pass(CONFIG, seqs[:1], tmp_path, make_tracker=NoneTracker, progress=False)
    assert "frame 2 of 6 (00002.jpg)" in summary["failed"]["a"] and "expected 4 numbers" in summary["failed"]["a"]

    def broken(config):
        raise KeyError("features")

    summary = run_one_pass(CONFIG, seqs[:1], tmp_path, make_tracker=broken, progress=False)
    assert "creating the tracker raised KeyError" in summary["failed"]["a"]


def test_process_pool_matches_serial(tmp_path, seqs):
    run_one_pass(CONFIG, seqs, tmp_path / "serial", make_tracker=make_drift, progress=False)
    summary = run_one_pass(CONFIG, seqs, tmp_path / "pool", make_tracker=make_drift, jobs=2,
                           progress=False)
    assert sorted(summary["done"]) == ["a", "b", "c"]
    for s in "abc":
        assert ((tmp_path / "serial" / "drift" / f"{s}.txt").read_text()
                == (tmp_path / "pool" / "drift" / f"{s}.txt").read_text())


def test_mixed_configs_refused_by_load_results(tmp_path, seqs):
    run_one_pass(CONFIG, seqs[:1], tmp_path, make_tracker=Counter(), progress=False)
    run_one_pass({**CONFIG, "drift": 3.0}, seqs[1:2], tmp_path, make_tracker=Counter(), progress=False)
    with pytest.raises(ValueError, match="mix 2 configurations"):
        load_results(tmp_path, "drift", seqs)


# --------------------------------------------------------------------------- OpenCV baselines


def synthetic_sequence(tmp_path, n=8):
    rng = np.random.default_rng(0)
    background = rng.integers(0, 80, (160, 160, 3), dtype=np.uint8)
    patch = rng.integers(100, 255, (48, 48, 3), dtype=np.uint8)  # MOSSE needs texture
    frames, gt = [], []
    for k in range(n):
        img = background.copy()
        x, y = 40 + 2 * k, 45 + 2 * k
        img[y:y + 48, x:x + 48] = patch
        f = tmp_path / "syn" / f"{k:03d}.png"
        f.parent.mkdir(exist_ok=True)
        cv2.imwrite(str(f), img)
        frames.append(f)
        gt.append([x, y, 48, 48])
    return Sequence("syn", tuple(frames), np.array(gt, float), {}, "synthetic")


@pytest.mark.parametrize("name", ["CSRT", "KCF", "MOSSE"])
def test_opencv_baselines(tmp_path, name):
    if name not in available_opencv_trackers():
        pytest.skip(f"OpenCV {name} is not in this OpenCV build")
    seq = synthetic_sequence(tmp_path)
    factory = opencv_tracker(name.lower())
    tracker = factory({})
    tracker.init(seq.frame(0), seq.init_box)
    box = tracker.update(seq.frame(1))
    assert box.dtype == np.float64 and box.shape == (4,)
    summary = run_one_pass({"name": f"opencv-{name}"}, [seq], tmp_path / "out", make_tracker=factory,
                           progress=False)
    assert summary["done"] == ["syn"]
    res = load_results(tmp_path / "out", f"opencv-{name}", [seq])["syn"]
    centre = lambda b: b[:2] + b[2:] / 2  # noqa: E731
    # a loose bound: MOSSE's accuracy differs between OpenCV releases; the point is the plumbing
    assert np.hypot(*(centre(res.boxes[-1]) - centre(seq.ground_truth[-1]))) < 20


def test_opencv_unknown_name():
    with pytest.raises(OpenCVUnavailable, match="CSRT, KCF, MOSSE"):
        opencv_tracker("medianflow")


# --------------------------------------------------------------------------- import and report


def test_import_results(tmp_path):
    d = tmp_path / "other"
    d.mkdir()
    (d / "a.txt").write_text("3,4,5,6\n4,4,5,6\n")
    (d / "b.txt").write_text("3\t4\t5\t6\nNaN\tNaN\tNaN\tNaN\n")
    (d / "b_time.txt").write_text("0.01\n0.02\n")
    res = import_results(d)
    assert sorted(res) == ["a", "b"] and res["a"].fps is None
    np.testing.assert_array_equal(res["a"].boxes[0], [2, 3, 5, 6])
    assert np.isnan(res["b"].boxes[1]).all()


def test_evaluate_scores_and_sorting(seqs):
    perfect = {s.name: gt_boxes() for s in seqs}
    shifted = {s.name: gt_boxes(x0=32.0) for s in seqs[:2]}  # far off; "c" missing
    ev = evaluate({"shifted": shifted, "perfect": perfect}, seqs)
    top, low = ev.overall
    assert top["tracker"] == "perfect" and top["auc"] == pytest.approx(20 / 21) and top["precision"] == 1
    # otb scores frame 1 with the ground truth: 1/6 on a and b; c has no results: 0
    assert low["tracker"] == "shifted" and low["missing"] == 1 and low["precision"] == pytest.approx(1 / 9)
    assert ev.protocol.name == "otb" and ev.settings["weighting"] == "sequence"
    assert top["fps"] is None  # plain arrays carry no timing
    assert len(ev.per_sequence) == 6
    sv = [r for r in ev.per_attribute if r["attribute"] == "SV"]
    assert [r["sequences"] for r in sv] == [2, 2] and ev.attributes == {"SV": 2, "FM": 1}
    np.testing.assert_allclose(ev.curves["perfect"]["precision"], 1.0)
    md = tables.format_rows(ev.overall, "markdown", tables.OVERALL_COLUMNS)
    assert md.splitlines()[0] == "| tracker | auc | precision | norm_precision | fps | sequences | missing |"
    assert "| perfect | 0.952 | 1.000 | 1.000 | - | 3 | 0 |" in md
    csv_text = tables.format_rows(ev.overall, "csv", tables.OVERALL_COLUMNS)
    assert csv_text.splitlines()[1].startswith("perfect,0.952380952")
    assert "perfect" in tables.format_rows(ev.overall, "table")


def test_short_results_are_scored_as_failures_with_a_warning(seqs, caplog):
    short = {s.name: gt_boxes()[:2] for s in seqs[:1]}
    with caplog.at_level("WARNING"):
        ev = evaluate({"short": short}, seqs[:1])
    assert f"'short', sequence 'a': 2 boxes for {N_FRAMES} frames" in caplog.text
    assert ev.overall[0]["precision"] == pytest.approx(2 / N_FRAMES)  # not copied forward by otb's rule


def test_write_report_files(tmp_path, seqs):
    out = tmp_path / "out"
    run_one_pass(CONFIG, seqs, out, make_tracker=Counter(), progress=False)
    run_one_pass({"name": "slow", "drift": 2.0}, seqs, out, make_tracker=Counter(), progress=False)
    other = tmp_path / "imported"
    other.mkdir()
    for s in seqs:
        (other / f"{s.name}.txt").write_text(results.format_boxes(gt_boxes()))
    paths = report.write_report(out, seqs, trackers=["drift", "slow", str(other)])
    names = {p.name for p in paths}
    for stem in ("precision", "success", "success_SV", "success_FM", "precision_SV", "precision_FM"):
        assert {f"{stem}.png", f"{stem}.svg"} <= names
    for stem in ("overall", "per_sequence", "per_attribute"):
        assert {f"{stem}.txt", f"{stem}.md", f"{stem}.csv"} <= names
    assert all(p.parent == out.parent / "out_report" and p.stat().st_size > 0 for p in paths)
    data = json.loads((out.parent / "out_report" / "report.json").read_text())
    rows = {r["tracker"]: r for r in data["overall"]}
    assert set(rows) == {"drift", "slow", "imported"} and rows["drift"]["fps"] > 0
    assert rows["imported"]["fps"] is None
    assert "drift [0.952]" in (out.parent / "out_report" / "success.svg").read_text()
    # default trackers: the folders of OUT holding sequence results (not OUT/report)
    assert sorted(report.gather_results(out, seqs)) == ["drift", "slow"]


def test_cli_eval_and_report(tmp_path, seqs, monkeypatch, capsys):
    root = tmp_path / "DTB70"
    for s in seqs:
        (root / s.name / "img").mkdir(parents=True)
        for k, f in enumerate(s.frames):
            (root / s.name / "img" / f"{k + 1:05d}.jpg").write_bytes(f.read_bytes())
        (root / s.name / "groundtruth_rect.txt").write_text(results.format_boxes(s.ground_truth))
    seen = {}

    def fake_resolve(spec, overrides):
        seen["overrides"] = overrides
        return {"name": Path(spec).stem, **overrides}, make_drift

    monkeypatch.setattr(cli_evaluate, "_resolve_config", fake_resolve)
    parser = argparse.ArgumentParser()
    cli_evaluate.add_eval_arguments(parser)
    args = parser.parse_args(["fast.yaml", "--root", str(root), "--out", str(tmp_path / "out"),
                              "--sequences", "a,c", "--set", "drift=0.5", "--no-progress"])
    assert cli_evaluate.run_eval(args) == 0
    assert seen["overrides"] == {"drift": 0.5}
    assert files(tmp_path / "out" / "fast") == {f"{n}{end}" for n in "ac"
                                                for end in (".txt", ".json", ".time", ".confidence")}
    printed = capsys.readouterr().out
    assert "fast: 2 run, 0 already done, 0 failed" in printed
    # the drift tracker lags the ground truth by 0.5k px on frame k (boxes 5x6): IoU (5-0.5k)/(5+0.5k) =
    # 1, .82, .67, .54, .43, .33 pass 20+17+14+11+9+7 = 78 of 6x21 overlap thresholds; errors 0.5k <= 20 px;
    # normalized errors 0.1k <= 0.2 on 3 of 6 frames
    assert "\n  AUC 0.619, precision 1.000, normalized precision 0.500 on 2 sequences (protocol otb)\n" in printed
    # every config is checked before any runs: a typo in the second costs nothing of the first
    monkeypatch.undo()
    args = parser.parse_args(["strcf", "strcff.yaml", "--root", str(root), "--out", str(tmp_path / "out2"),
                              "--no-progress"])
    with pytest.raises(ConfigError, match="config not found: strcff.yaml"):
        cli_evaluate.run_eval(args)
    assert not (tmp_path / "out2").exists()
    # two different configs under one name would overwrite each other's results: refused up
    # front; the same config given twice runs once
    mine = tmp_path / "my_strcf.yaml"
    mine.write_text("base: strcf\nregularizers: {temporal: {theta: 20}}\n")
    args = parser.parse_args(["strcf", str(mine), "--root", str(root), "--out", str(tmp_path / "out2"),
                              "--no-progress"])
    with pytest.raises(ConfigError, match="'strcf' and .*my_strcf.yaml' are both named 'strcf'"):
        cli_evaluate.run_eval(args)
    assert not (tmp_path / "out2").exists()
    monkeypatch.setattr(cli_evaluate, "_resolve_config", fake_resolve)
    args = parser.parse_args(["fast.yaml", "fast.yaml", "--root", str(root), "--out", str(tmp_path / "out3"),
                              "--sequences", "a", "--no-progress", "--protocol", "got10k"])
    assert cli_evaluate.run_eval(args) == 0
    printed = capsys.readouterr().out.splitlines()
    assert [line for line in printed if line.startswith("fast:")] == [
        f"fast: 1 run, 0 already done, 0 failed -> {tmp_path / 'out3' / 'fast'}"]
    assert printed[-1].startswith("  AO ") and printed[-1].endswith(" on 1 sequences (protocol got10k)")
    # a second config's folder that cannot take its results stops the command before the first runs
    (tmp_path / "out4" / "slow" / "c.json").mkdir(parents=True)
    args = parser.parse_args(["fast.yaml", "slow.yaml", "--root", str(root), "--out", str(tmp_path / "out4"),
                              "--no-progress"])
    with pytest.raises(DcfkitError, match=r"slow's results to .*slow: c\.json is a folder"):
        cli_evaluate.run_eval(args)
    assert not list((tmp_path / "out4").rglob("*.txt"))  # nothing was tracked

    parser = argparse.ArgumentParser()
    cli_evaluate.add_report_arguments(parser)
    args = parser.parse_args([str(tmp_path / "out"), "--root", str(root), "--dataset", "dtb70",
                              "--sequences", "a,c", "--format", "markdown"])
    assert cli_evaluate.run_report(args) == 0
    out = capsys.readouterr().out
    assert out.startswith("experiment OPE (one-pass evaluation; Wu et al., TPAMI 2015)\nprotocol otb: ")
    assert "\n\n| tracker | auc |" in out and "| fast |" in out
    assert (tmp_path / "out_report" / "success.png").is_file()
    args = parser.parse_args([str(tmp_path / "out"), "--root", str(root), "--dataset", "dtb70",
                              "--sequences", "a,c", "--format", "csv", "--protocol", "got10k"])
    assert cli_evaluate.run_report(args) == 0
    assert capsys.readouterr().out.splitlines()[0] == (
        "tracker,ao,sr50,sr75,auc,precision,norm_precision,fps,sequences,missing,protocol,experiment")
    assert json.loads((tmp_path / "out_report" / "report.json").read_text())["protocol"]["name"] == "got10k"


def test_real_sequence_with_opencv_kcf(tmp_path, shared_data):
    if "KCF" not in available_opencv_trackers():
        pytest.skip("OpenCV KCF is not in this OpenCV build")
    (boat1,) = load_dataset("uav123_10fps", shared_data / "UAV123_10fps", ["boat1"])
    short = dataclasses.replace(boat1, frames=boat1.frames[:12], ground_truth=boat1.ground_truth[:12])
    run_one_pass({"name": "kcf"}, [short], tmp_path, make_tracker=opencv_tracker("KCF"), progress=False)
    first = (tmp_path / "kcf" / "boat1.txt").read_text().splitlines()[0]
    assert first == "393.000,328.000,155.000,319.000"  # the annotation file's first line
    ev = evaluate({"kcf": load_results(tmp_path, "kcf", [short])}, [short])
    assert ev.overall[0]["auc"] > 0.5 and ev.overall[0]["fps"] > 0


class DyingTracker(DriftTracker):
    """Kills its worker process on sequence 'b' (first frame of value 10)."""

    def init(self, image, box):
        if 8 <= image[0, 0, 0] <= 12:
            os._exit(1)
        super().init(image, box)


def make_dying(config):
    return DyingTracker(config)


def test_a_dead_worker_fails_its_sequences_with_error_records(tmp_path, seqs):
    summary = run_one_pass(CONFIG, seqs, tmp_path, make_tracker=make_dying, jobs=2, progress=False)
    assert "b" in summary["failed"] and "a worker process died" in summary["failed"]["b"]
    for name in summary["failed"]:
        record = json.loads((tmp_path / "drift" / f"{name}.error").read_text())
        assert record["type"] == "BrokenProcessPool" and record["sequence"] == name
    assert set(summary["failed"]) | set(summary["done"]) == {"a", "b", "c"}


def _square_or_die(x):
    """Module-level (picklable) pool task: the worker process dies on 3."""
    if x == 3:
        os._exit(1)
    return x * x


def test_run_pool_reports_a_dead_worker_as_a_crash_of_the_unfinished_calls():
    results, crashes = {}, {}
    runner.run_pool({x: (_square_or_die, x) for x in range(4)}, 2, results.__setitem__,
                        lambda key, exc: crashes.setdefault(key, type(exc).__name__))
    assert set(results) == {0, 1, 2, 3} and 3 in crashes  # every call is reported, the dead one as a crash
    assert set(crashes.values()) == {"BrokenProcessPool"}
    assert all(results[x] == x * x for x in results if x not in crashes)


def test_result_files_get_the_usual_permissions(tmp_path, monkeypatch):
    saved = os.umask(0o022)
    try:
        store_files._file_mode.cache_clear()
        path = tmp_path / "r.txt"
        results.atomic_write(path, "1\n")
        assert path.stat().st_mode & 0o777 == 0o644 and path.read_text() == "1\n"  # mkstemp alone: 0o600
    finally:
        os.umask(saved)
        store_files._file_mode.cache_clear()

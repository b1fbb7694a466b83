"""Runs sharing their frames tracked in lockstep (dcfkit.running.lockstep): each frame decoded
once, and every run's stored result what the run tracked alone stores."""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from test_ablation import write_otb

import dcfkit.datasets.base
from dcfkit import load_config
from dcfkit.datasets import load_dataset
from dcfkit.experiments import EXPERIMENTS
from dcfkit.running import lockstep
from dcfkit.running.execute import execute
from dcfkit.running.runner import RunTask, run_sequence
from dcfkit.store.provenance import dcfkit_version, run_key

SHIPPED = ("kcf", "dsst", "strcf", "bacf", "arcf", "autotrack", "dr2track", "eco_hc", "csrdcf")
VERSION = dcfkit_version()


@pytest.fixture(scope="module")
def seq(tmp_path_factory):
    root = tmp_path_factory.mktemp("data")
    write_otb(root, "seqA", seed=3, n_frames=40)
    return load_dataset("otb", root)[0]


def tasks_of(config, seq, folder: Path, experiment="tre", make_tracker=None, every: int = 1) -> list[RunTask]:
    """The experiment's runs of ``seq`` (every ``every``-th) as tasks storing into ``folder``."""
    exp = EXPERIMENTS[experiment]
    folder.mkdir(exist_ok=True)  # as the plan makes it
    key = run_key(config, VERSION, exp.rule)
    return [RunTask(config, run, folder, key, make_tracker, exp) for run in exp.runs(seq)[::every]]


def outcomes(results: list[dict]) -> list[tuple]:
    """What a run's summary says but its speed."""
    return [(r["sequence"], r["status"], r.get("error"), r["frames"]) for r in results]


def stored(folder: Path, suffixes=(".txt", ".confidence")) -> dict[str, bytes]:
    return {p.name: p.read_bytes() for p in sorted(folder.iterdir()) if p.suffix in suffixes}


@pytest.mark.parametrize("name", SHIPPED)
def test_every_shipped_tracker_stores_under_tre_what_its_runs_store_alone(name, seq, tmp_path):
    """Three of TRE's runs (from frames 1, 9 and 17: a tracker's inits are its costly frames),
    each tracker's state kept beside two others' through every frame."""
    config = load_config(name)
    together = tasks_of(config, seq, tmp_path / "together", every=8)
    (unit,) = lockstep.groups(together)
    assert len(unit) == len(together) == 3 and unit[0].seq.frames == seq.frames  # the longest run leads
    results = lockstep.run_group(unit, VERSION)
    assert [r["status"] for r in results] == ["done"] * len(unit)
    for task in tasks_of(config, seq, tmp_path / "alone", every=8):
        run_sequence(task, VERSION)
    assert stored(tmp_path / "together") == stored(tmp_path / "alone")
    sidecar = json.loads((tmp_path / "together" / f"{unit[-1].seq.name}.json").read_text())
    assert sidecar["timing"] == {"executor": "local", "workers": 1, "alone": False, "lockstep": len(unit)}


class Scribbler:
    """Writes into every image it is given, and moves by its mean: a shared image would show."""

    def __init__(self, config):
        self.fail_at = config.get("fail_at")

    def init(self, image, box):
        self.box, self.seen = np.asarray(box, dtype=np.float64), 1

    def update(self, image):
        self.seen += 1
        if self.seen == self.fail_at:
            raise RuntimeError("scribbled off the page")
        shift = float(image.mean()) / 255
        image[:] = 0
        self.box = self.box + [shift, 0, 0, 0]
        return self.box


def test_a_tracker_writing_into_its_image_and_a_failing_run_change_no_other_run(seq, tmp_path):
    """Each run gets its own copy of a frame; a run that raises fails alone, with the error it
    has alone (its frame, 1-based), under SRE, whose runs all cover the whole sequence."""
    config = {"name": "scribbler", "fail_at": 5}
    together = tasks_of(config, seq, tmp_path / "together", "sre", Scribbler)
    (unit,) = lockstep.groups(together)
    results = lockstep.run_group(unit, VERSION)
    alone = [run_sequence(t, VERSION) for t in tasks_of(config, seq, tmp_path / "alone", "sre", Scribbler)]
    assert outcomes(results) == outcomes(alone) and {r["status"] for r in results} == {"failed"}
    assert all("frame 5 of 40" in r["error"] for r in results)
    config = {"name": "scribbler"}
    lockstep.run_group(tasks_of(config, seq, tmp_path / "t2", "tre", Scribbler), VERSION)
    for task in tasks_of(config, seq, tmp_path / "a2", "tre", Scribbler):
        run_sequence(task, VERSION)
    assert stored(tmp_path / "t2", (".txt",)) == stored(tmp_path / "a2", (".txt",))


def test_an_unreadable_frame_fails_each_run_that_has_it_as_alone(seq, tmp_path, monkeypatch):
    read = dcfkit.datasets.base.read_frame

    def broken(path, what="frame"):
        if Path(path).name == "0010.jpg":
            raise dcfkit.datasets.DatasetError(f"cannot read {what}: {path} (not a readable image)")
        return read(path, what)

    monkeypatch.setattr(dcfkit.datasets.base, "read_frame", broken)
    config = {"name": "scribbler"}
    results = lockstep.run_group(tasks_of(config, seq, tmp_path / "together", "tre", Scribbler), VERSION)
    alone = [run_sequence(t, VERSION) for t in tasks_of(config, seq, tmp_path / "alone", "tre", Scribbler)]
    assert outcomes(results) == outcomes(alone)
    assert [r["status"] for r in results].count("failed") == sum(s <= 9 for s in (40 - len(t.seq) for t in
                                                                                   tasks_of(config, seq, tmp_path)))


def test_groups_are_runs_of_one_config_on_one_sequences_frames_split_for_the_workers(seq, tmp_path):
    kcf, dsst = load_config("kcf"), load_config("dsst")
    tre = tasks_of(kcf, seq, tmp_path / "kcf")
    other = tasks_of(dsst, seq, tmp_path / "dsst")
    reset = tasks_of(kcf, seq, tmp_path / "reset", "reset")
    units = lockstep.groups([*tre, *other, *reset])
    assert sorted(len(u) for u in units) == [1] * len(reset) + [len(tre), len(other)]
    assert all(u[0].seq.frames == seq.frames for u in units if len(u) > 1)
    halves = lockstep.groups(tre, parts=2)  # one group holds all the frames: split until none holds a quarter
    assert sorted(t.seq.name for u in halves for t in u) == sorted(t.seq.name for t in tre)
    assert len(halves) >= 4 and all(len(u[0].seq) == max(len(t.seq) for t in u) for u in halves)
    work = [sum(len(t.seq) for t in u) for u in halves]
    assert work == sorted(work, reverse=True) and max(work) <= sum(work) / 4


def test_execute_in_a_pool_stores_what_runs_alone_store(seq, tmp_path):
    config = load_config("kcf")
    done = []
    execute(tasks_of(config, seq, tmp_path / "pool"), lambda task, result: done.append(result["status"]), jobs=2)
    for task in tasks_of(config, seq, tmp_path / "alone"):
        run_sequence(task, VERSION)
    assert done == ["done"] * len(tasks_of(config, seq, tmp_path)) and stored(tmp_path / "pool") == stored(
        tmp_path / "alone")


def test_the_run_that_is_also_the_one_pass_run_is_timed_alone_and_copied_so(seq, tmp_path):
    """TRE's first run is OPE's run (copied between the two experiments): it is tracked alone,
    so that its timing stands for OPE's; TRE's other runs in lockstep. Nothing is decoded for
    runs that all failed to start."""
    from dcfkit.running.evaluation import run_one_pass

    config = load_config("kcf")
    run_one_pass(config, [seq], tmp_path / "out", experiment="tre", progress=False)
    tre = {p.stem: json.loads(p.read_text())["timing"] for p in (tmp_path / "out" / "kcf" / "tre").glob("*.json")}
    assert tre.pop("seqA_001") == {"executor": "local", "workers": 1, "alone": True}
    assert {t["lockstep"] for t in tre.values()} == {len(tre)} and not any(t["alone"] for t in tre.values())
    run_one_pass(config, [seq], tmp_path / "out", progress=False)
    ope = json.loads((tmp_path / "out" / "kcf" / "seqA.json").read_text())
    assert ope["timing"]["alone"] and ope["sequence"] == "seqA"  # copied from TRE's first, timed alone


def test_no_frame_is_decoded_once_every_run_has_failed(seq, tmp_path, monkeypatch):
    reads = []
    read = dcfkit.datasets.base.read_frame
    monkeypatch.setattr(dcfkit.datasets.base, "read_frame", lambda path, what="frame": reads.append(path) or
                        read(path, what))

    def refuse(config):
        raise RuntimeError("no tracker today")

    results = lockstep.run_group(tasks_of({"name": "none"}, seq, tmp_path / "out", "sre", refuse), VERSION)
    assert {r["status"] for r in results} == {"failed"} and reads == []
    assert all("creating the tracker raised RuntimeError: no tracker today" in r["error"] for r in results)


def test_a_unit_whose_worker_dies_after_storing_keeps_the_runs_it_stored(seq, tmp_path, monkeypatch):
    """A pool's unit stores its runs one after another at its end: a worker dying among them
    (the pool failing every unit not yet delivered) leaves those stored done, not overwritten
    with the crash."""
    from dcfkit.running import runner

    def dying_pool(calls, jobs, on_result, on_crash):
        for key, (fn, *args) in calls.items():
            fn(*args)
            on_result(key, on_crash(key, RuntimeError("the worker died")))

    monkeypatch.setattr(runner, "run_pool", dying_pool)
    monkeypatch.setattr(runner, "worker_init", lambda *args: None)
    config = load_config("kcf")
    done = []
    execute(tasks_of(config, seq, tmp_path / "out"), lambda task, result: done.append(result["status"]), jobs=2)
    assert done == ["done"] * len(tasks_of(config, seq, tmp_path))
    assert not list((tmp_path / "out").glob("*.error"))


@pytest.fixture
def in_process_scheduler(monkeypatch):
    """The address of a scheduler whose two workers are threads of this process."""
    distributed = pytest.importorskip("distributed", reason="dask.distributed not installed (pip install "
                                      "'dcfkit[dask]')")
    from dcfkit.running import runner

    monkeypatch.setattr(runner, "_worker_ready", True)  # the workers are threads of this process: no set-up
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=False,
                                  dashboard_address=None) as cluster:
        yield cluster.scheduler_address


@pytest.mark.slow
@pytest.mark.parametrize("where", ["scheduler", "local cluster"])
def test_dask_tracks_a_sequences_runs_together_as_the_pool_does(where, seq, tmp_path, request):
    """On dask a unit of runs is one task: the same stored boxes as alone, the runs timed as in
    lockstep, and a unit's runs delivered each to its own task."""
    pytest.importorskip("distributed", reason="dask.distributed not installed (pip install 'dcfkit[dask]')")
    scheduler = request.getfixturevalue("in_process_scheduler") if where == "scheduler" else None
    config = load_config("kcf")
    delivered = {}
    execute(tasks_of(config, seq, tmp_path / "dask"), lambda task, result: delivered.update(
        {task.seq.name: result["sequence"]}), jobs=2, executor="dask", scheduler=scheduler)
    for task in tasks_of(config, seq, tmp_path / "alone"):
        run_sequence(task, VERSION)
    names = [t.seq.name for t in tasks_of(config, seq, tmp_path)]
    assert delivered == dict(zip(names, names)) and stored(tmp_path / "dask") == stored(tmp_path / "alone")
    timing = [json.loads((tmp_path / "dask" / f"{name}.json").read_text())["timing"] for name in names]
    assert {(t["executor"], t["workers"]) for t in timing} == {("dask", None if scheduler else 2)}
    sizes = [t.get("lockstep", 1) for t in timing]
    assert 1 < max(sizes) < len(names)  # split in units for the two workers, each tracked together


@pytest.mark.slow
def test_a_unit_failing_on_dask_fails_each_of_its_runs(seq, tmp_path, in_process_scheduler):
    config = load_config("kcf")
    results = []
    execute(tasks_of(config, seq, tmp_path / "out"), lambda task, result: results.append(result),
            executor="dask", scheduler=in_process_scheduler, version="0.0.0-other")
    assert len(results) == len(tasks_of(config, seq, tmp_path)) and {r["status"] for r in results} == {"failed"}
    assert all("the worker failed: DcfkitError: this worker runs dcfkit" in r["error"] for r in results)

"""Evaluation: a tracker config on every sequence of a benchmark, in one experiment
(:mod:`dcfkit.experiments`: one pass, TRE, SRE or reset-based).

Trackers come from a factory ``make_tracker(config) -> tracker``, called once per sequence
(default: :func:`dcfkit.load_tracker`); a tracker is any object with ``init(image, box)``
and ``update(image) -> box`` (:mod:`dcfkit.experiments.loop`). Results go to
``OUT/<config name>/`` (``OUT/<config name>/<experiment>/`` but for one pass), a
:class:`dcfkit.store.results.ResultStore`: one file of 1-based boxes and one sidecar per run
(per-frame tracker seconds, image decoding excluded; before its first run of a dcfkit config
a process runs a throw-away copy of the tracker on the first frame, untimed, so that one-time
loading of compiled code is not counted).

On rerun a run is skipped when its results are intact and from the same run key
(:func:`dcfkit.store.provenance.run_key`); damaged and failed runs are run again. A run
never replaces an intact one of more frames (``--max-frames``), and two evaluations never
write the same run (:mod:`dcfkit.store.claims`).
"""
from __future__ import annotations

import json
import logging
from pathlib import Path
from typing import Iterable, Mapping

import numpy as np

from dcfkit.datasets import DatasetError, Sequence
from dcfkit.errors import ConfigError, shown
from dcfkit.experiments import Experiment, get_experiment, runs_by_sequence
from dcfkit.store.claims import claimed
from dcfkit.store.files import ensure_writable, make_dir, remove_temporary_files
from dcfkit.store.provenance import dcfkit_version, json_default, run_key
from dcfkit.store.results import ResultStore, same_data
from dcfkit.running.runner import RunTask, execute, warm_up_compiled

__all__ = ["check_one_pass", "experiment_runs", "results_folder", "run_one_pass", "tracker_name"]

log = logging.getLogger(__name__)


def tracker_name(config: Mapping) -> str:
    """``config['name']``, checked to be usable as the results folder's name."""
    name = config.get("name") if isinstance(config, Mapping) else None
    if not isinstance(name, str) or not name.strip():
        raise ConfigError("config has no top-level 'name' (the tracker name used for the output folder)")
    if name.startswith(".") or any(c in name for c in "/\\:") or not name.isprintable():
        raise ConfigError(f"config 'name' {shown(name)} must be usable as a folder name that report lists (no / \\ :, "
                          f"no leading dot, no control character such as a null byte or a line break)")
    return name


def _check_first_boxes(sequences: list[Sequence]) -> None:
    bad = [s.name + (f" (first box in {s.annotation})" if s.annotation else "") for s in sequences
           if not (np.isfinite(s.ground_truth[0]).all() and (s.ground_truth[0, 2:] > 0).all())]
    if bad:
        raise DatasetError(f"one-pass evaluation initialises on frame 1's ground truth, which is NaN or "
                           f"empty in sequence(s): {', '.join(bad)}")


def _check_same_dataset(store: ResultStore, metas: dict, todo: list[Sequence]) -> None:
    """OUT/<tracker>/<sequence> has no benchmark level: never mix two benchmarks there."""
    for seq in todo:
        old = (metas[seq.name] or {}).get("dataset")
        if old and seq.dataset and old != seq.dataset:
            raise DatasetError(f"{store.sidecar_path(seq.name)} holds results on dataset {shown(old)}, and this run "
                               f"is on {shown(seq.dataset)}: use a separate --out for each benchmark")


def _say_what_is_recomputed(store: ResultStore, metas: dict, todo: list[Sequence], config: dict, key: str) -> None:
    """Say so when results are recomputed because they are damaged, or replaced because they
    are another config's (not merely another dcfkit version's)."""
    same = json.dumps(config, sort_keys=True, default=json_default)
    damaged = [s.name for s in todo if store.status(s, key, metas[s.name]) == "damaged"]
    replaced = [s.name for s in todo
                if (metas[s.name] or {}).get("run_key") not in (None, key)
                and json.dumps(metas[s.name].get("config"), sort_keys=True, default=json_default) != same]
    shorter = [s.name for s in todo if (store.other_length(s, metas[s.name]) or len(s)) < len(s)]
    other_data = [s.name for s in todo if (metas[s.name] or {}).get("run_key") == key
                  and not same_data(metas[s.name], s) and s.name not in shorter]
    if damaged:
        log.warning("%s: recomputing %d damaged result(s): %s", store.folder, len(damaged), ", ".join(damaged[:10]))
    if shorter:
        log.warning("%s: replacing %d result(s) of fewer frames (a --max-frames smoke run's, or the sequence has "
                    "grown): %s", store.folder, len(shorter), ", ".join(shorter[:10]))
    if other_data:
        log.warning("%s: recomputing %d result(s) made on other data (a sequence of that name whose frames or ground "
                    "truth differ): %s", store.folder, len(other_data), ", ".join(other_data[:10]))
    if replaced:
        log.warning("%s: replacing the results of another config named %r for %d sequence(s): %s (give this "
                    "config another name to keep both)", store.folder, config["name"], len(replaced),
                    ", ".join(replaced[:10]))


def _say_other_rule(store: ResultStore, metas: dict, todo: list[Sequence], experiment: Experiment) -> None:
    """Say so when results are recomputed because the experiment's other rules made them."""
    other = {s.name: why for s in todo if (why := experiment.stored_elsewise(metas[s.name])) is not None}
    if other:
        log.warning("%s: recomputing %d %s result(s) whose failures another rule decided (%s), with %s's: "
                    "%s", store.folder, len(other), experiment.name, ", ".join(sorted(set(other.values()))), experiment.rule,
                    ", ".join(list(other)[:10]))


def results_folder(out_dir, config: Mapping, experiment: str | Experiment = "ope") -> Path:
    """Where ``config``'s results of ``experiment`` go: ``OUT/<name>/`` or ``OUT/<name>/<experiment>/``."""
    folder = Path(out_dir) / tracker_name(config)
    sub = get_experiment(experiment).folder
    return folder / sub if sub else folder


def experiment_runs(sequences: Iterable[Sequence], experiment: str | Experiment = "ope") -> list[Sequence]:
    """Every run of ``experiment`` on ``sequences``, in order (:mod:`dcfkit.experiments`)."""
    return [run for runs in runs_by_sequence(sequences, experiment).values() for run in runs]


def _plan(config: dict, sequences: list[Sequence], runs: list[Sequence], out_dir, experiment: Experiment
          ) -> tuple[ResultStore, str, list[Sequence], dict]:
    """(store, run key, runs to do, every run's sidecar), after every check that needs no
    tracking: the first boxes, the benchmark of the results there, that no run replaces one of
    more frames, and (when anything is to run) that the folder takes the result files. The
    experiment's rule, if it has one, is part of the key."""
    if experiment.first_box:
        _check_first_boxes(sequences)
    key = run_key(config, rule=experiment.rule)
    store = ResultStore(results_folder(out_dir, config, experiment))
    metas = {s.name: store.sidecar(s.name) for s in runs}  # each read once
    todo = [s for s in runs if store.status(s, key, metas[s.name]) != "done"
            or experiment.stored_elsewise(metas[s.name]) is not None]
    _check_same_dataset(store, metas, todo)
    for run in todo:
        store.refuse_to_shorten(run, metas[run.name])
    if todo:
        ensure_writable(store.folder, [f for s in todo for f in store.file_names(s.name)],
                        f"{tracker_name(config)}'s results")
    return store, key, todo, metas


def check_one_pass(config: Mapping, sequences: Iterable[Sequence], out_dir, experiment: str = "ope",
                   reset_rule: str | None = None) -> None:
    """Raise now what :func:`run_one_pass` would raise before tracking (``dcfkit eval`` checks
    every config this way before it runs the first)."""
    sequences = list(sequences)
    experiment = get_experiment(experiment, reset_rule)
    _plan(dict(config), sequences, experiment_runs(sequences, experiment), out_dir, experiment)


def run_one_pass(config: Mapping, sequences: Iterable[Sequence], out_dir, make_tracker=None,
                 jobs: int = 1, progress: bool = True, experiment: str | Experiment = "ope",
                 reset_rule: str | None = None) -> dict:
    """Evaluate the tracker described by ``config`` on ``sequences`` in ``experiment``
    (default one pass: each sequence once, from frame 1's ground truth); a reset-based run's
    failures are ``reset_rule``'s (:data:`~dcfkit.experiments.vot.RULES`, default VOT2016's).

    Each run starts from a fresh tracker; results go to :func:`results_folder`. Runs with
    intact results of the same run key are skipped; before anything is tracked, the folder is
    checked to take the others. A tracker exception fails only its run; a write failure
    (:class:`StoreError`) stops the evaluation. ``jobs > 1`` runs in spawned worker
    processes; ``make_tracker`` must then be picklable.

    Returns a plain dict: ``tracker``, ``dir``, ``run_key``, ``done`` (computed now),
    ``skipped`` (already done), ``failed`` (run -> message), runs named as
    :mod:`dcfkit.experiments` names them (one pass: the sequences' names).
    """
    config, sequences, experiment = dict(config), list(sequences), get_experiment(experiment, reset_rule)
    folder = results_folder(out_dir, config, experiment)
    if not folder.is_dir():
        make_dir(folder)  # a first run: the locks need the folder
    runs = experiment_runs(sequences, experiment)
    kind = "run" if experiment.folder else "sequence"
    with claimed(folder, [run.name for run in runs], "dcfkit eval",  # other runs of this folder may go on alongside
                 lambda name: f"{tracker_name(config)}'s results of {kind} {name!r} to {folder}"):
        store, key, todo, metas = _plan(config, sequences, runs, out_dir, experiment)
        _say_what_is_recomputed(store, metas, todo, config, key)
        _say_other_rule(store, metas, todo, experiment)
        remove_temporary_files(store.folder, [f for s in todo for f in store.file_names(s.name)])
        summary = {"tracker": tracker_name(config), "dir": store.folder, "run_key": key,
                   "done": [], "skipped": [s.name for s in runs if s not in todo], "failed": {}}
        _run(summary, [RunTask(config, s, store.folder, key, make_tracker, experiment) for s in todo],
             jobs, progress, dcfkit_version())
    order = {s.name: i for i, s in enumerate(runs)}
    summary["done"].sort(key=order.get)
    return summary


def _run(summary: dict, tasks: list[RunTask], jobs: int, progress: bool, version: str) -> None:
    """Execute ``tasks`` with a progress bar in frames, recording each outcome in ``summary``."""
    from tqdm.auto import tqdm  # lazy: tqdm.auto probes for Jupyter on import

    warm_up_compiled(tasks)  # numba compiles here, not in the first runs the bar times
    bar = tqdm(total=sum(len(t.seq) for t in tasks), unit="frame", desc=summary["tracker"],
               disable=None if progress and tasks else True, dynamic_ncols=True)  # None: on a terminal only
    done_frames = [0]

    def on_result(task: RunTask, result: dict) -> None:
        if result["status"] == "done":
            summary["done"].append(result["sequence"])
        else:
            summary["failed"][result["sequence"]] = result["error"]
            log.warning("%s: %s", summary["tracker"], result["error"])
        done_frames[0] += len(task.seq)
        bar.set_postfix_str(task.seq.name, refresh=False)
        bar.update(done_frames[0] - bar.n)  # a failed sequence skips its rest

    try:
        execute(tasks, on_result, jobs=jobs, version=version, on_frame=lambda: bar.update(1))
    finally:
        bar.close()

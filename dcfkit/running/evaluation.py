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
write the same run (:mod:`dcfkit.store.claims`). It is a plan of one entry
(:mod:`dcfkit.running.plan`), as ``ablate``'s and ``search``'s are of many.
"""
from __future__ import annotations

from pathlib import Path
from typing import Iterable, Mapping

from dcfkit.datasets import Sequence
from dcfkit.errors import ConfigError, shown
from dcfkit.experiments import Experiment, get_experiment, runs_by_sequence
from dcfkit.running.layout import folder_problem, store_folder
from dcfkit.running.plan import Entry, RunPlan
from dcfkit.running.progress import FrameBar

__all__ = ["check_one_pass", "experiment_runs", "results_folder", "run_one_pass", "tracker_name"]


def tracker_name(config: Mapping) -> str:
    """``config['name']``, checked to be usable as the results folder's name."""
    name = config.get("name") if isinstance(config, Mapping) else None
    if not isinstance(name, str) or not name.strip():
        raise ConfigError("config has no top-level 'name' (the tracker name used for the output folder)")
    problem = folder_problem(name)  # the rule every folder of a tracker's results is held to
    if problem:
        raise ConfigError(f"config 'name' {shown(name)} {problem}")
    return name


def results_folder(out_dir, config: Mapping, experiment: str | Experiment = "ope") -> Path:
    """Where ``config``'s results of ``experiment`` go: ``OUT/<name>/`` or ``OUT/<name>/<experiment>/``."""
    return store_folder(out_dir, tracker_name(config), experiment)


def experiment_runs(sequences: Iterable[Sequence], experiment: str | Experiment = "ope") -> list[Sequence]:
    """Every run of ``experiment`` on ``sequences``, in order (:mod:`dcfkit.experiments`)."""
    return [run for runs in runs_by_sequence(sequences, experiment).values() for run in runs]


def _plan(config: Mapping, sequences: Iterable[Sequence], out_dir, experiment: Experiment,
          make_tracker=None) -> RunPlan:
    """The plan of ``config``'s runs: one entry, stored under its name."""
    return RunPlan([Entry(tracker_name(config), dict(config), make_tracker)], sequences, experiment, out_dir)


def check_one_pass(config: Mapping, sequences: Iterable[Sequence], out_dir, experiment: str = "ope",
                   reset_rule: str | None = None) -> None:
    """Raise now what :func:`run_one_pass` would raise before tracking (``dcfkit eval`` checks
    every config this way before it runs the first)."""
    _plan(config, sequences, out_dir, get_experiment(experiment, reset_rule)).check()


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
    plan = _plan(config, sequences, out_dir, get_experiment(experiment, reset_rule), make_tracker)
    plan.run("dcfkit eval", jobs=jobs, progress=FrameBar(tracker_name(config), progress))
    return plan.entries[0].outcome()

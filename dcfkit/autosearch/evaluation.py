"""Scoring one config on some sequences for a search: its runs made (or found) by a run plan
(:mod:`dcfkit.running.plan`), then scored per sequence. A trial's config is stored as
``OUT/runs/<run key>/[<experiment>/]``, so every trial of one config (and the fold's choice
scored on its held-out fold) shares its runs; a baseline's as ``OUT/baselines/<name>/``; both
in the layout ``dcfkit report`` and ``dcfkit compare`` read (docs/search.md, "Resuming")."""
from __future__ import annotations

import logging
import math
from pathlib import Path
from typing import Iterable, Mapping

from dcfkit.analysis.scoring import evaluate
from dcfkit.datasets import Sequence, benchmark_protocol
from dcfkit.experiments import get_experiment, run_identity, runs_by_sequence
from dcfkit.protocols import get_protocol
from dcfkit.running.layout import folder_names, store_folder
from dcfkit.running.plan import Entry, RunPlan
from dcfkit.store.provenance import dcfkit_version, run_key
from dcfkit.store.results import ResultStore

log = logging.getLogger(__name__)

TRIAL_RUNS, BASELINES = "runs", "baselines"  # OUT/runs/<run key>/, OUT/baselines/<name>/ (OUT/trials/: the studies)


class Evaluator:
    """Runs and scores configs on ``sequences`` under each of ``experiments`` (a sequence's
    score is the mean over the experiments of its pooled score: OTB's TRE pools the 20 runs
    of a sequence). Runs already stored are reused, so a killed search resumes mid-trial and
    two trials of one config share their runs. ``baselines`` names the baselines (name ->
    config) whose runs go to ``OUT/baselines/``; ``dataset`` is the spec's dataset name."""

    def __init__(self, out: Path, dataset: str, sequences: list[Sequence], experiments: Iterable[str],
                 protocol: str | None = None, jobs: int = 1, executor: str = "local", scheduler: str | None = None,
                 baselines: Iterable[str] = ()):
        self.out, self.dataset, self.jobs = Path(out), dataset, jobs
        self.executor, self.scheduler = executor, scheduler
        self.sequences = {s.name: s for s in sequences}
        self.experiments = tuple(experiments)
        self.runs = {e: runs_by_sequence(sequences, e) for e in self.experiments}
        self.protocol = get_protocol(protocol) if protocol else None
        if protocol is None:  # pooled benchmarks scored by different rules: refused before the first trial
            benchmark_protocol(sequences)
        self.version = dcfkit_version()
        self.baselines = folder_names(baselines)

    def key(self, config: Mapping) -> str:
        return run_key(config, self.version)

    def _where(self, config: Mapping, baseline: str | None) -> tuple[Path, str]:
        """(the folder of the plan, the entry's name) of a trial's ``config``, or of the named ``baseline``."""
        if baseline is None:
            return self.out / TRIAL_RUNS, self.key(config)
        return self.out / BASELINES, self.baselines.get(baseline) or folder_names([baseline])[baseline]

    def run(self, configs: Iterable[dict], names: list[str], baseline: str | None = None,
            experiments: Iterable[str] | None = None) -> list[str]:
        """Make every missing run of ``configs`` (trials, or the one config of ``baseline``) on
        the sequences ``names`` under ``experiments`` (default: the search's); returns the
        failures' messages (a failed run scores as a total failure)."""
        entries: dict[str, Entry] = {}
        for config in configs:  # the trials of one config are one entry
            root, name = self._where(config, baseline)
            entries.setdefault(name, Entry(name, config))
        failures: list[str] = []
        for experiment in (self.experiments if experiments is None else experiments) if entries else ():
            if baseline is not None:  # its one entry
                (entry,) = entries.values()
                self._adopt(dict(entry.config), names, experiment, store_folder(root, entry.name, experiment))
            plan = RunPlan(entries.values(), [self.sequences[n] for n in names], experiment, root,
                           "the search's runs", self.version)
            plan.run("dcfkit search", self.jobs, self.executor, self.scheduler)
            for run, message in ((run, m) for p in plan.entries for run, m in p.failed.items()):
                failures.append(f"{run}: {message}")
                log.warning("run failed, scored as a total failure: %s: %s", run, message)
        return failures

    def _adopt(self, config: dict, names: list[str], experiment: str, folder: Path) -> None:
        """Copy into a baseline's ``folder`` the runs a trial of the same config (the same run
        key: config and version) has done: the base config is trial 0 and often a baseline too."""
        key = self.key(config)
        trial, mine = ResultStore(store_folder(self.out / TRIAL_RUNS, key, experiment)), ResultStore(folder)
        for run in (r for n in names for r in self.runs[experiment][n]):
            if trial.is_done(run, key) and not mine.is_done(run, key):
                mine.copy_run(trial, run.name)

    def scores(self, config: dict, names: list[str], baseline: str | None = None) -> dict[str, dict]:
        """Sequence name -> ``{"auc", "precision"}`` of ``config`` (its runs made first; those of
        ``baseline`` if a baseline's), each the mean over the experiments. No fps: times measured
        in a busy pool rank nothing, and a search's records stay the same on every rerun
        (benchmarks/speed.py measures speed)."""
        return combined(self.experiment_scores(config, names, self.experiments, baseline), names)

    def experiment_scores(self, config: dict, names: list[str], experiments: Iterable[str],
                          baseline: str | None = None) -> dict[str, dict[str, dict]]:
        """Experiment -> sequence name -> ``{"auc", "precision"}`` of ``config`` under each of
        ``experiments`` (its runs made first), NaN where the protocol scores no frame."""
        experiments = tuple(experiments)
        self.run([config], names, baseline, experiments)
        root, name = self._where(config, baseline)
        key, seqs = self.key(config), [self.sequences[n] for n in names]
        found = {}
        for e in experiments:
            store = ResultStore(store_folder(root, name, e))
            done = [run for n in names for run in self.runs[e][n] if store.is_done(run, key)]
            results = store.load(done) if done else {}
            scored = evaluate({"trial": results}, seqs, protocol=self.protocol, experiment=e, runs=self.runs[e])
            found[e] = {row["sequence"]: {k: row[k] for k in ("auc", "precision")} for row in scored.per_sequence}
        return found

    def frames(self, units: Iterable[tuple[tuple[str, ...], str]]) -> int:
        """The frames a config tracks on ``units`` ((experiments, sequence name) pairs of
        successive halving, in order): every run of each sequence under each of its experiments
        but one an earlier experiment made (TRE's from frame 1 after OPE's: docs/evaluation.md,
        "One run, two experiments")."""
        made_by: dict[tuple, str] = {}
        total = 0
        for exps, name in units:
            for e in exps:
                once = get_experiment(e).tracks_once
                for run in self.runs[e][name]:
                    if once and made_by.setdefault((name, *run_identity(run)), e) != e:
                        continue  # copied from the other experiment's run
                    total += len(run)
        return total


def combined(per_experiment: Mapping[str, Mapping[str, dict]], names: Iterable[str]) -> dict[str, dict]:
    """Sequence name -> ``{"auc", "precision"}``: the mean over the experiments of
    ``per_experiment`` (in its order) of each of ``names``; NaN if any is NaN or None (no frame
    scored)."""
    return {n: {k: _mean([rows[n][k] for rows in per_experiment.values()]) for k in ("auc", "precision")}
            for n in names}


def _mean(values: list) -> float:
    if any(v is None for v in values):  # a record's null: JSON's NaN
        return math.nan
    return sum(values) / len(values)

"""Scoring one config on some sequences for a search: its runs made (or found) in the result
store an ablation uses, ``OUT/jobs/<dataset>/<key>/[<experiment>/]``, then scored per sequence."""
from __future__ import annotations

import logging
from pathlib import Path
from typing import Iterable, Mapping

from dcfkit.ablation.experiment import runs_dir
from dcfkit.ablation.spec import job_dir
from dcfkit.analysis.scoring import evaluate
from dcfkit.datasets import Sequence, benchmark_protocol
from dcfkit.experiments import runs_by_sequence
from dcfkit.protocols import get_protocol
from dcfkit.store.files import ensure_writable
from dcfkit.store.provenance import dcfkit_version, run_key
from dcfkit.store.results import ResultStore
from dcfkit.running.runner import RunTask, execute, warm_up_compiled

log = logging.getLogger(__name__)


class Evaluator:
    """Runs and scores configs on ``sequences`` under each of ``experiments`` (a sequence's
    score is the mean over the experiments of its pooled score: OTB's TRE pools the 20 runs
    of a sequence). Runs already stored are reused, so a killed search resumes mid-trial and
    two trials of one config share their runs."""

    def __init__(self, out: Path, dataset: str, sequences: list[Sequence], experiments: Iterable[str],
                 protocol: str | None = None, jobs: int = 1, executor: str = "local", scheduler: str | None = None):
        self.out, self.dataset, self.jobs = Path(out), dataset, jobs
        self.executor, self.scheduler = executor, scheduler
        self.sequences = {s.name: s for s in sequences}
        self.experiments = tuple(experiments)
        self.runs = {e: runs_by_sequence(sequences, e) for e in self.experiments}
        self.protocol = get_protocol(protocol) if protocol else None
        if protocol is None:  # pooled benchmarks scored by different rules: refused before the first trial
            benchmark_protocol(sequences)
        self.version = dcfkit_version()

    def key(self, config: Mapping) -> str:
        return run_key(config, self.version)

    def _tasks(self, config: dict, names: list[str]) -> dict[str, list[RunTask]]:
        key = self.key(config)
        return {e: [RunTask(config, run, runs_dir(job_dir(self.out, self.dataset, key), e), key)
                    for name in names for run in self.runs[e][name]] for e in self.experiments}

    def run(self, configs: Iterable[dict], names: list[str]) -> list[str]:
        """Make every missing run of ``configs`` on the sequences ``names``; returns the
        failures' messages (a failed run scores as a total failure)."""
        todo = [t for config in configs for tasks in self._tasks(config, names).values() for t in tasks
                if not ResultStore(t.folder).is_done(t.seq, t.key)]
        failures: list[str] = []

        def on_result(task: RunTask, res: dict) -> None:
            if res["status"] != "done":
                failures.append(f"{task.seq.name}: {res['error']}")
                log.warning("run failed, scored as a total failure: %s: %s", task.seq.name, res["error"])

        if todo:
            for folder in {t.folder for t in todo}:
                ensure_writable(folder, what="the search's runs")
            for task in todo:  # a --max-frames try never replaces a whole run of the config
                ResultStore(task.folder).refuse_to_shorten(task.seq)
            warm_up_compiled(todo)
            execute(sorted(todo, key=lambda t: -len(t.seq)), on_result, jobs=self.jobs, executor=self.executor,
                    scheduler=self.scheduler, version=self.version)
        return failures

    def scores(self, config: dict, names: list[str]) -> dict[str, dict]:
        """Sequence name -> ``{"auc", "precision"}`` of ``config`` (its runs made first), each
        the mean over the experiments. No fps: times measured in a busy pool rank nothing, and
        a search's records stay the same on every rerun (benchmarks/speed.py measures speed)."""
        self.run([config], names)
        seqs = [self.sequences[n] for n in names]
        per_experiment = []
        for e, tasks in self._tasks(config, names).items():
            store = ResultStore(tasks[0].folder)
            done = [t.seq for t in tasks if store.is_done(t.seq, t.key)]
            results = store.load(done) if done else {}
            scored = evaluate({"trial": results}, seqs, protocol=self.protocol, experiment=e, runs=self.runs[e])
            per_experiment.append({row["sequence"]: row for row in scored.per_sequence})
        return {n: {k: _mean([rows[n][k] for rows in per_experiment]) for k in ("auc", "precision")}
                for n in names}


def _mean(values: list) -> float:
    return sum(values) / len(values)

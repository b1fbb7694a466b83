"""The search: one Optuna study per fold on the other folds' sequences, its best config then
scored on the fold it never saw, and a final study on every sequence (docs/search.md).

Trials run one after another (a trial's runs use the pool); each is recorded in
``OUT/trials/<study>/<n>.json`` once scored. Trial n's values depend only on the seed and
trials 0..n-1 (a sampler seeded per trial is given the recorded trials), so a search killed
at any point resumes to the same trials and the same result."""
from __future__ import annotations

import hashlib
import json
from pathlib import Path
from typing import Any, Callable

import numpy as np
import optuna

from dcfkit.autosearch.evaluation import Evaluator
from dcfkit.autosearch.space import SearchSpec, active
from dcfkit.autosearch.summary import FINAL, summarize
from dcfkit.errors import DcfkitError, shown
from dcfkit.running.files import atomic_write, ensure_writable, exclusive, make_dir, read_json


def make_folds(names: list[str], k: int, seed: int) -> list[list[str]]:
    """``names`` split into ``k`` folds of near-equal size: sorted, shuffled with ``seed``,
    dealt round-robin; each fold sorted."""
    if k > len(names):
        raise DcfkitError(f"{k} folds need at least {k} sequences, got {len(names)}")
    order = np.random.default_rng(seed).permutation(sorted(names))
    return [sorted(str(n) for n in order[i::k]) for i in range(k)]


def fingerprint(spec: SearchSpec, folds: list[list[str]], evaluator: Evaluator) -> dict:
    """What a resumed search must share with the recorded one for its trials to stand."""
    space = {p.key: [optuna.distributions.distribution_to_json(p.distribution),
                     {k: evaluator.key(v) if isinstance(v, dict) else repr(v) for k, v in p.choices.items()}, p.when]
             for p in spec.parameters}
    return {"base": evaluator.key(spec.base), "space": json.loads(json.dumps(space, default=list)),
            "experiments": list(spec.experiments), "folds": folds, "seed": spec.seed,
            "startup_trials": spec.startup_trials, "dataset": spec.dataset,
            "protocol": evaluator.protocol.name if evaluator.protocol else None}


def _trial_seed(seed: int, study: str, number: int) -> int:
    digest = hashlib.sha256(f"{seed}/{study}/{number}".encode()).digest()
    return int.from_bytes(digest[:4], "little")


def sample(spec: SearchSpec, study: str, number: int, recorded: list[dict]) -> dict[str, Any]:
    """Trial ``number``'s values: a TPE sampler seeded for (seed, study, number) told the
    ``recorded`` trials (each ``{"params", "value"}``)."""
    sampler = optuna.samplers.TPESampler(seed=_trial_seed(spec.seed, study, number),
                                         n_startup_trials=spec.startup_trials)
    optuna.logging.set_verbosity(optuna.logging.WARNING)
    opt = optuna.create_study(direction="maximize", sampler=sampler)
    dists = {p.key: p.distribution for p in spec.parameters}
    for rec in recorded:
        opt.add_trial(optuna.trial.create_trial(params=rec["params"], value=rec["value"],
                                                distributions={k: dists[k] for k in rec["params"]}))
    trial = opt.ask()
    params: dict[str, Any] = {}
    for p in spec.parameters:
        if active(p, params):
            params[p.key] = p.suggest(trial)
    return params


class Search:
    """A search spec run under ``out``: its folds, its studies and their records."""

    def __init__(self, spec: SearchSpec, out, evaluator_options: dict | None = None,
                 report: Callable[[str], None] = lambda line: None):
        self.spec, self.out, self.report = spec, Path(out).expanduser().resolve(), report
        seqs = spec.load_sequences()
        self.names = [s.name for s in seqs]
        self.folds = make_folds(self.names, spec.folds, spec.seed)
        self.evaluator = Evaluator(self.out, spec.dataset, seqs, spec.experiments, **(evaluator_options or {}))

    def training(self, study: str) -> list[str]:
        if study == FINAL:
            return self.names
        held = set(self.folds[int(study.removeprefix("fold")) - 1])
        return [n for n in self.names if n not in held]

    def studies(self) -> list[str]:
        return [f"fold{i + 1}" for i in range(len(self.folds))] + [FINAL]

    def check_record(self) -> None:
        """Write ``OUT/search.json``, or refuse to resume a search whose trials would not stand."""
        path = self.out / "search.json"
        mine = fingerprint(self.spec, self.folds, self.evaluator)
        recorded = read_json(path)
        if recorded is not None and recorded.get("fingerprint") != mine:
            changed = [k for k in mine if (recorded.get("fingerprint") or {}).get(k) != mine[k]]
            raise DcfkitError(f"{path} records a different search (these differ: {', '.join(changed) or 'the record'}): "
                              f"give a new --out, or remove {self.out} to start again")
        atomic_write(path, json.dumps({"spec": str(self.spec.path), "name": self.spec.name,
                                       "fingerprint": mine}, indent=1) + "\n")

    def recorded(self, study: str) -> list[dict]:
        folder = self.out / "trials" / study
        records = []
        for n in range(self.spec.trials):
            rec = read_json(folder / f"{n:04d}.json")
            if rec is None or rec.get("number") != n:
                break
            records.append(rec)
        return records

    def run_study(self, study: str) -> list[dict]:
        """The study's trials, the missing ones run; returns their records."""
        names = self.training(study)
        records = self.recorded(study)
        make_dir(self.out / "trials" / study)
        for n in range(len(records), self.spec.trials):
            params = sample(self.spec, study, n, records)
            config = self.spec.config(params)
            scores = self.evaluator.scores(config, names)
            value = float(np.mean([scores[s]["auc"] for s in names]))
            rec = {"number": n, "params": params, "value": value, "key": self.evaluator.key(config),
                   "scores": scores, "config": config}
            atomic_write(self.out / "trials" / study / f"{n:04d}.json", json.dumps(rec, indent=1) + "\n")
            records.append(rec)
            best = max(r["value"] for r in records)
            self.report(f"{study} trial {n} ({n + 1} of {self.spec.trials}): mean AUC {value:.4f} on {len(names)} "
                        f"sequences (best {best:.4f}) {shown(params)}")
        return records

    def run(self) -> dict:
        """Every study, then the held-out scores and the comparison (:mod:`dcfkit.autosearch.summary`)."""
        ensure_writable(self.out, ("search.json",), "the search")
        with exclusive(self.out / ".lock", "dcfkit search", f"to {self.out}"):
            self.check_record()
            studies = {study: self.run_study(study) for study in self.studies()}
            return summarize(self, studies)


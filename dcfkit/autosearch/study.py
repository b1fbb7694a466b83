"""The search: one Optuna study per fold on the other folds' sequences, its best config then
scored on the fold it never saw, and a final study on every sequence (docs/search.md).

Trials run one after another (a trial's runs use the pool); each is recorded in
``OUT/trials/<study>/<n>.json`` once scored. Trial n's values depend only on the seed and
trials 0..n-1 (a sampler seeded per trial is given the recorded trials), so a search killed
at any point resumes to the same trials and the same result."""
from __future__ import annotations

import hashlib
import json
import logging
from pathlib import Path
from typing import Any, Callable

import numpy as np
import optuna
from optuna.trial import TrialState

from dcfkit.autosearch.evaluation import Evaluator
from dcfkit.autosearch.space import SearchSpec, active
from dcfkit.autosearch.summary import FINAL, finite, is_score, mean_auc, summarize
from dcfkit.datasets import scored_sequences
from dcfkit.errors import DcfkitError, shown
from dcfkit.running.files import atomic_write, ensure_writable, exclusive, make_dir, read_json
from dcfkit.running.results import data_identity

log = logging.getLogger(__name__)


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
            "protocol": evaluator.protocol.name if evaluator.protocol else None,
            "data": {name: data_identity(seq) for name, seq in evaluator.sequences.items()}}


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
        opt.add_trial(_frozen(rec, dists))
    trial = opt.ask()
    params: dict[str, Any] = {}
    for p in spec.parameters:
        if active(p, params):
            params[p.key] = p.suggest(trial)
    return params


def _frozen(rec: dict, distributions: dict) -> optuna.trial.FrozenTrial:
    """A trial record as Optuna's trial; one without a score (None, or the NaN of dcfkit 0.9.0)
    is a failed trial, which TPE leaves out."""
    scored = is_score(rec["value"])
    return optuna.trial.create_trial(params=rec["params"], value=rec["value"] if scored else None,
                                     state=TrialState.COMPLETE if scored else TrialState.FAIL,
                                     distributions={k: distributions[k] for k in rec["params"]})


def _usable(rec: dict, number: int, distributions: dict) -> bool:
    """Whether ``rec`` is trial ``number``'s record as :meth:`Search.run_study` writes it."""
    if not (rec.get("number") == number and isinstance(rec.get("params"), dict) and isinstance(rec.get("key"), str)
            and isinstance(rec.get("scores"), dict) and isinstance(rec.get("config"), dict)
            and (rec.get("value") is None or isinstance(rec["value"], (int, float)))):
        return False
    try:
        _frozen(rec, distributions)  # each value one its dimension can take
    except (KeyError, TypeError, ValueError):
        return False
    return True


class Search:
    """A search spec run under ``out``: its folds, its studies and their records."""

    def __init__(self, spec: SearchSpec, out, evaluator_options: dict | None = None,
                 report: Callable[[str], None] = lambda line: None):
        self.spec, self.out, self.report = spec, Path(out).expanduser().resolve(), report
        seqs = scored_sequences(spec.load_sequences())  # a test split's sequence could not score a trial
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
        if recorded is not None:
            self._check_fingerprint(path, recorded.get("fingerprint"), mine)
        atomic_write(path, json.dumps({"spec": str(self.spec.path), "name": self.spec.name,
                                       "fingerprint": mine}, indent=1) + "\n")

    def _check_fingerprint(self, path: Path, old: Any, mine: dict) -> None:
        """Refuse to resume when the recorded fingerprint ``old`` is not ``mine``; one without the
        data's identity (dcfkit <= 0.9.0) is taken to be on this data."""
        old = old if isinstance(old, dict) else {}
        if old and "data" not in old:
            log.warning("%s was written by dcfkit <= 0.9.0, without what identifies the data: the recorded "
                        "trials are taken to be on the data under %s", path, self.spec.root)
            old = {**old, "data": mine["data"]}
        changed = [k for k in mine if old.get(k) != mine[k]]
        if changed == ["data"]:
            was = old["data"] if isinstance(old["data"], dict) else {}
            differ = [n for n in mine["data"] if was.get(n) != mine["data"][n]]
            raise DcfkitError(f"{path}: its trials were made on other data: the frames or ground truth of "
                              f"{', '.join(map(shown, differ[:5]))}{' ...' if len(differ) > 5 else ''} under "
                              f"{self.spec.root} differ from the recorded ones; give the recorded search's --root, "
                              f"or a new --out")
        if changed:
            raise DcfkitError(f"{path} records a different search (these differ: {', '.join(changed)}): "
                              f"give a new --out, or remove {self.out} to start again")

    def recorded(self, study: str) -> list[dict]:
        """The study's trial records up to the first missing one; a damaged or edited record is
        missing (with a warning), and it and those after it are run again, to the same values."""
        folder = self.out / "trials" / study
        dists = {p.key: p.distribution for p in self.spec.parameters}
        records = []
        for n in range(self.spec.trials):
            path = folder / f"{n:04d}.json"
            rec = read_json(path)
            if rec is None or not _usable(rec, n, dists):
                if rec is not None or path.exists():
                    log.warning("%s is not a trial record as dcfkit writes it: trial %d of %s is run again, "
                                "and the trials after it", path, n, study)
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
            try:
                config = self.spec.config(params)
            except DcfkitError as exc:  # the spec check resolves every structure; a value inside a range may fail
                raise DcfkitError(f"{self.spec.path}: {study} trial {n}, {shown(params)}: {exc}") from None
            scores = finite(self.evaluator.scores(config, names))
            value = mean_auc(scores, names)
            rec = {"number": n, "params": params, "value": value, "key": self.evaluator.key(config),
                   "scores": scores, "config": config}
            atomic_write(self.out / "trials" / study / f"{n:04d}.json", json.dumps(rec, indent=1) + "\n")
            records.append(rec)
            best = max((r["value"] for r in records if is_score(r["value"])), default=None)
            self.report(f"{study} trial {n} ({n + 1} of {self.spec.trials}): mean AUC {_shown_auc(value)} on "
                        f"{len(names)} sequences (best {_shown_auc(best)}) {shown(params)}")
        return records

    def run(self) -> dict:
        """Every study, then the held-out scores and the comparison (:mod:`dcfkit.autosearch.summary`)."""
        ensure_writable(self.out, ("search.json",), "the search")
        with exclusive(self.out / ".lock", "dcfkit search", f"to {self.out}"):
            self.check_record()
            studies = {study: self.run_study(study) for study in self.studies()}
            return summarize(self, studies)


def _shown_auc(value: float | None) -> str:
    return "none (no sequence has a scored frame)" if value is None else f"{value:.4f}"

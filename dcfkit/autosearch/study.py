"""The search: one Optuna study per fold on the other folds' sequences, its best config then
scored on the fold it never saw, and a final study on every sequence (docs/search.md).

Trial 0 of each study is the base config (``warm_start``,
:func:`~dcfkit.autosearch.warm_start.base_params`), so a study's best is never below the base on
its own sequences. Trials run one after another (a trial's runs use the pool); each is recorded in
``OUT/trials/<study>/<n>.json`` once scored. Trial n's values depend only on the seed and
trials 0..n-1 (a sampler seeded per trial is given the recorded trials), so a search killed
at any point resumes to the same trials and the same result."""
from __future__ import annotations

import hashlib
import json
import logging
import math
from pathlib import Path
from typing import Any, Callable

import numpy as np
import optuna
from optuna.trial import TrialState

from dcfkit.ablation.layout import warn_old_layout
from dcfkit.ablation.spec_keys import data_record, roots_text
from dcfkit.autosearch.evaluation import Evaluator
from dcfkit.autosearch.halving import Ladder, intermediate, sequence_order
from dcfkit.autosearch.space import SearchSpec, active
from dcfkit.autosearch.summary import FINAL, finite, is_score, mean_auc, summarize
from dcfkit.autosearch.warm_start import base_params
from dcfkit.datasets import scored_sequences
from dcfkit.errors import DcfkitError, clip, shown
from dcfkit.store.files import atomic_write, ensure_writable, exclusive, make_dir, read_json
from dcfkit.store.provenance import shared_path
from dcfkit.store.results import data_identity

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
            "startup_trials": spec.startup_trials, "dataset": data_record(spec)["dataset"],
            "protocol": evaluator.protocol.name if evaluator.protocol else None,
            "sequences": sorted(evaluator.sequences), "max_frames": spec.max_frames,  # folds sort them too
            "warm_start": spec.warm_start, "halving": spec.halving.as_record() if spec.halving else None,
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
    is a failed trial, which TPE leaves out; a pruned one (successive halving) is known to TPE
    by its mean AUC at the rungs it reached."""
    dists = {k: distributions[k] for k in rec["params"]}
    if rec.get("pruned"):
        return optuna.trial.create_trial(params=rec["params"], distributions=dists, state=TrialState.PRUNED,
                                         intermediate_values=intermediate(rec["steps"]))
    scored = is_score(rec["value"])
    return optuna.trial.create_trial(params=rec["params"], value=rec["value"] if scored else None,
                                     state=TrialState.COMPLETE if scored else TrialState.FAIL,
                                     distributions=dists)


def _params_fault(spec: SearchSpec, params: Any) -> str | None:
    """What is wrong with a record's ``params`` (None if nothing): they must be the dimensions
    :func:`sample` samples, each with a value its dimension can take."""
    if not isinstance(params, dict):
        return f"params: expected a mapping of the space's keys, got {shown(params)}"
    dims = {p.key: p for p in spec.parameters}
    unknown = [k for k in params if k not in dims]
    if unknown:
        return f"params: {shown(unknown[0])} is not a key of the space"
    for key, value in params.items():
        if not _takes(dims[key].distribution, value):
            return f"params.{clip(key)}: {shown(value)} is not a value its dimension takes"
    sampled = [p.key for p in spec.parameters if active(p, params)]
    if sorted(sampled) != sorted(params):
        return f"params: expected values for {shown(sampled)} (as sampled under its choices), got {shown(list(params))}"
    return None


def _takes(distribution: optuna.distributions.BaseDistribution, value: Any) -> bool:
    """Whether :func:`sample` could give ``value``: a label, a whole number or a float, in range."""
    kind = {optuna.distributions.CategoricalDistribution: str, optuna.distributions.IntDistribution: int}
    if type(value) is not kind.get(type(distribution), float):  # "0.5" or true would pass Optuna's check
        return False
    try:
        optuna.trial.create_trial(params={"v": value}, distributions={"v": distribution}, value=0.0)
    except (OverflowError, ValueError):  # an int past float's range
        return False
    return True


def _scores_fault(rec: dict, names: list[str], pruned: bool = False) -> str | None:
    """What is wrong with a record's ``scores`` and ``value`` (None if nothing): the scores must be
    of the study's training sequences, ``names`` (those a ``pruned`` trial reached), and the
    value their mean AUC (null if the trial was pruned)."""
    scores = rec.get("scores")
    if not (isinstance(scores, dict) and sorted(scores) == sorted(names)):
        which = "the sequences its rungs reached" if pruned else "this study's training sequences"
        return f"scores: expected those of {which} {shown(names)}"
    if not all(isinstance(s, dict) and all(_number(s.get(k)) for k in ("auc", "precision")) for s in scores.values()):
        return "scores: expected {auc, precision} numbers or null for each sequence"
    value = rec.get("value")
    if pruned:
        return None if value is None else f"value: expected null for a pruned trial, got {shown(value)}"
    if isinstance(value, float) and math.isnan(value):  # dcfkit 0.9.0: NaN when a sequence had no score
        return None if any(not is_score(s["auc"]) for s in scores.values()) else "value: NaN, yet every AUC is scored"
    if not (_number(value) and value == mean_auc(scores, names)):
        return f"value: {shown(value)} is not the mean AUC of its scores"
    return None


def _steps_fault(rec: dict, order: list[str]) -> str | None:
    """What is wrong with a record's ``steps`` and ``pruned`` (successive halving): ``[count,
    mean AUC]`` pairs, each the mean AUC over the first ``count`` sequences of the study's
    ``order``, and true or false."""
    steps = rec.get("steps")
    if not (isinstance(steps, list) and steps and all(
            isinstance(s, list) and len(s) == 2 and type(s[0]) is int and 1 <= s[0] <= len(order) and _number(s[1])
            for s in steps)):
        return f"steps: expected [sequences, mean AUC] pairs, got {shown(steps)}"
    if not isinstance(rec.get("pruned"), bool):
        return f"pruned: expected true or false, got {shown(rec.get('pruned'))}"
    scores = rec.get("scores")
    for count, value in steps:
        if isinstance(scores, dict) and all(n in scores for n in order[:count]) and \
                value != mean_auc(scores, order[:count]):
            return f"steps: {shown(value)} is not the mean AUC of the first {count} sequences' scores"
    return None


def _number(value: Any) -> bool:
    """A score as records hold it: a number, or null (NaN in dcfkit 0.9.0's)."""
    return value is None or (isinstance(value, (int, float)) and not isinstance(value, bool))


class Search:
    """A search spec run under ``out``: its folds, its studies and their records."""

    def __init__(self, spec: SearchSpec, out, evaluator_options: dict | None = None,
                 report: Callable[[str], None] = lambda line: None):
        self.spec, self.out, self.report = spec, Path(out).expanduser().resolve(), report
        seqs = scored_sequences(spec.load_sequences())  # a test split's sequence could not score a trial
        self.names = [s.name for s in seqs]
        self.folds = make_folds(self.names, spec.folds, spec.seed)
        self.evaluator = Evaluator(self.out, spec.dataset, seqs, spec.experiments, **(evaluator_options or {}),
                                   baselines=spec.baselines)

    def order(self, study: str) -> list[str]:
        """The study's training sequences in the order successive halving scores them."""
        return sequence_order(self.training(study), self.spec.seed, study)

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
        recorded = read_json(path)  # None: missing, unreadable or not an object
        if recorded is not None:
            self._check_fingerprint(path, recorded.get("fingerprint"), mine)
        elif any(any((self.out / "trials" / study).glob("*.json")) for study in self.studies()):
            state = "not a search record as dcfkit writes it" if path.exists() else "missing"
            raise DcfkitError(f"{path} is {state}, yet {self.out / 'trials'} holds trial records: nothing shows which "
                              f"search made them; give a new --out, or remove {self.out / 'trials'} to start again")
        atomic_write(path, json.dumps({"spec": shared_path(self.spec.path, self.out), "name": self.spec.name,
                                       "fingerprint": mine}, indent=1) + "\n")

    def _check_fingerprint(self, path: Path, old: Any, mine: dict) -> None:
        """Refuse to resume when the recorded fingerprint ``old`` is not ``mine``; one without the
        data's identity (dcfkit <= 0.9.0) is taken to be on this data."""
        old = old if isinstance(old, dict) else {}
        if old and "data" not in old:
            log.warning("%s was written by dcfkit <= 0.9.0, without what identifies the data: the recorded "
                        "trials are taken to be on the data under %s", path, roots_text(self.spec))
            old = {**old, "data": mine["data"]}
        if old and "max_frames" not in old:  # recorded before --max-frames was: whole sequences
            old = {**old, "max_frames": None, "sequences": sorted(old.get("data") or {})}
        if old and "warm_start" not in old:  # recorded before dcfkit 0.14.0: every trial sampled
            old = {**old, "warm_start": False}
        if old and "halving" not in old:  # recorded before dcfkit 0.15.0: every trial on every sequence
            old = {**old, "halving": None}
        changed = [k for k in mine if old.get(k) != mine[k]]
        if "halving" in changed:
            raise DcfkitError(f"{path}: its trials were made with halving: {_halving_text(old['halving'])}, this "
                              f"spec has halving: {_halving_text(mine['halving'])}: give the recorded halving in the "
                              f"spec to resume it, or a new --out")
        if "warm_start" in changed:
            raise DcfkitError(f"{path}: its trials were made with warm_start: {str(old['warm_start']).lower()} "
                              f"(trial 0 {'the base config' if old['warm_start'] else 'sampled'}), this spec has "
                              f"warm_start: {str(mine['warm_start']).lower()}: set the recorded value in the spec "
                              f"to resume it, or give a new --out")
        for key, option in (("max_frames", "--max-frames"), ("sequences", "--sequences")):
            if key in changed:
                raise DcfkitError(f"{path}: its trials were made with {option} {_option_value(old[key])}, this "
                                  f"search has {option} {_option_value(mine[key])}: give the recorded {option} to "
                                  f"resume it, or a new --out for a separate search")
        if changed == ["data"]:
            was = old["data"] if isinstance(old["data"], dict) else {}
            differ = [n for n in mine["data"] if was.get(n) != mine["data"][n]]
            raise DcfkitError(f"{path}: its trials were made on other data: the frames or ground truth of "
                              f"{', '.join(map(shown, differ[:5]))}{' ...' if len(differ) > 5 else ''} under "
                              f"{roots_text(self.spec)} differ from the recorded ones; give the recorded search's --root, "
                              f"or a new --out")
        if changed:
            raise DcfkitError(f"{path} records a different search (these differ: {', '.join(changed)}): "
                              f"give a new --out, or remove {self.out} to start again")

    def recorded(self, study: str) -> tuple[list[dict], Ladder | None]:
        """The study's trial records up to the first missing one, and its successive halving
        told them (None without ``halving``); a damaged or edited record is missing (with a
        warning naming what is wrong), and it and those after it are run again, to the same values."""
        folder = self.out / "trials" / study
        records: list[dict] = []
        ladder = self._ladder(study, records)
        for n in range(self.spec.trials):
            path = folder / f"{n:04d}.json"
            rec = read_json(path)
            fault = "not a JSON object" if rec is None else self._fault(rec, n, study)
            if not fault and ladder is not None:
                fault = ladder.replay(rec["steps"], rec["pruned"])
                if fault:  # the pruner saw its values: told again without it
                    ladder = self._ladder(study, records)
            if fault:
                if path.exists():
                    log.warning("%s is not a trial record as dcfkit writes it (%s): trial %d of %s is run again, "
                                "and the trials after it", path, fault, n, study)
                break
            records.append(rec)
        return records, ladder

    def _ladder(self, study: str, records: list[dict]) -> Ladder | None:
        """The study's successive halving told ``records`` (already checked), or None without it."""
        if self.spec.halving is None:
            return None
        ladder = Ladder(self.spec.halving, len(self.training(study)))
        for rec in records:
            ladder.replay(rec["steps"], rec["pruned"])
        return ladder

    def _fault(self, rec: dict, number: int, study: str) -> str | None:
        """What makes ``rec`` not trial ``number`` of ``study`` as :meth:`run_study` records it
        (None if nothing): its number, values, scores (on the study's training sequences), value,
        config and run key are checked against each other and against this search."""
        names = self.training(study)
        if self.spec.halving is None and ("steps" in rec or "pruned" in rec):
            return "steps, pruned: only a search with halving records them"
        if self.spec.halving is not None:
            order = self.order(study)
            fault = _steps_fault(rec, order)
            if fault:
                return fault
            if rec.get("pruned") is True:  # a complete trial's value is the mean in the training order
                names = order[:rec["steps"][-1][0]]
        if rec.get("number") != number:
            return f"number: expected {number}, got {shown(rec.get('number'))}"
        if number == 0 and self.spec.warm_start:
            base = base_params(self.spec)
            fault = None if rec.get("params") == base else f"params: expected the base config's, {shown(base)}"
        else:
            fault = _params_fault(self.spec, rec.get("params"))
        fault = fault or _scores_fault(rec, names, pruned=rec.get("pruned") is True)
        if fault:
            return fault
        try:
            config = json.loads(json.dumps(self.spec.config(rec["params"])))  # as the record holds it
        except DcfkitError as exc:
            return f"params: {exc}"
        if rec.get("config") != config:
            return "config: not the config its params make"
        if rec.get("key") != self.evaluator.key(config):
            return "key: not its config's run key"
        return None

    def run_study(self, study: str) -> list[dict]:
        """The study's trials, the missing ones run; returns their records."""
        names = self.training(study)
        records, ladder = self.recorded(study)
        make_dir(self.out / "trials" / study)
        for n in range(len(records), self.spec.trials):
            # warm start: the base is trial 0, so a study's best is never below it on its sequences
            params = base_params(self.spec) if n == 0 and self.spec.warm_start else sample(self.spec, study, n, records)
            try:
                config = self.spec.config(params)
            except DcfkitError as exc:  # the spec check resolves every structure; a value inside a range may fail
                raise DcfkitError(f"{self.spec.path}: {study} trial {n}, {shown(params)}: {exc}") from None
            rec = {"number": n, "params": params, **self._scored(config, names, study, ladder),
                   "key": self.evaluator.key(config), "config": config}
            atomic_write(self.out / "trials" / study / f"{n:04d}.json", json.dumps(rec, indent=1) + "\n")
            records.append(rec)
            best = max((r["value"] for r in records if is_score(r["value"])), default=None)
            scored = "pruned after" if rec.get("pruned") else "on"
            self.report(f"{study} trial {n} ({n + 1} of {self.spec.trials}): mean AUC "
                        f"{_shown_auc(rec['steps'][-1][1] if rec.get('pruned') else rec['value'])} {scored} "
                        f"{len(rec['scores'])} sequence{'s' if len(rec['scores']) != 1 else ''} (best {_shown_auc(best)}) {shown(params)}")
        return records

    def _scored(self, config: dict, names: list[str], study: str, ladder: Ladder | None) -> dict:
        """A trial's value and scores: on every training sequence, or (successive halving) up
        the ``ladder``'s rungs, with its steps and whether it was pruned."""
        if ladder is None:
            scores = finite(self.evaluator.scores(config, names))
            return {"value": mean_auc(scores, names), "scores": scores}
        order, scores = self.order(study), {}

        def score(start: int, stop: int) -> float | None:
            scores.update(finite(self.evaluator.scores(config, order[start:stop])))
            return mean_auc(scores, order[:stop])

        steps, pruned = ladder.climb(score)
        return {"value": None if pruned else mean_auc(scores, names), "scores": scores, "steps": steps,
                "pruned": pruned}

    def run(self) -> dict:
        """Every study, then the held-out scores and the comparison (:mod:`dcfkit.autosearch.summary`)."""
        ensure_writable(self.out, ("search.json",), "the search")
        warn_old_layout(self.out, "dcfkit search", "OUT/runs/<run key>/, OUT/baselines/<name>/")
        with exclusive(self.out / ".lock", "dcfkit search", f"to {self.out}"):
            self.check_record()
            studies = {study: self.run_study(study) for study in self.studies()}
            return summarize(self, studies)


def _option_value(value: Any) -> str:
    """A recorded ``--max-frames`` or ``--sequences`` as given on the command line."""
    if value is None:
        return "(not given: whole sequences)"
    return shown(",".join(value)) if isinstance(value, list) else shown(value)


def _halving_text(record: Any) -> str:
    """A recorded ``halving`` as the spec gives it."""
    if not isinstance(record, dict):
        return "none (every trial on every sequence)"
    return "{" + ", ".join(f"{k}: {shown(v)}" for k, v in record.items()) + "}"


def _shown_auc(value: float | None) -> str:
    return "none (no sequence has a scored frame)" if value is None else f"{value:.4f}"

"""The search: one Optuna study per fold on the other folds' sequences, its best config then
scored on the fold it never saw, and a final study on every sequence (docs/search.md).

Trial 0 of each study is the base config (``warm_start``,
:func:`~dcfkit.autosearch.warm_start.base_params`), so a study's best is never below the base on
its own sequences. Trials run one after another (a trial's runs use the pool); each is recorded in
``OUT/trials/<study>/<n>.json`` once scored. Trial n's values depend only on the seed and
trials 0..n-1 (a sampler seeded per trial is given the recorded trials), so a search killed
at any point resumes to the same trials and the same result."""
from __future__ import annotations

import itertools
import json
import logging
from pathlib import Path
from typing import Any, Callable

import numpy as np
import optuna
from optuna.trial import TrialState

from dcfkit.ablation.layout import warn_old_layout
from dcfkit.ablation.spec_keys import data_record, roots_text
from dcfkit.autosearch.evaluation import Evaluator, combined
from dcfkit.autosearch.halving import Ladder, Unit, derived_seed, intermediate, sequence_order
from dcfkit.autosearch.records import complete, record_fault
from dcfkit.autosearch.space import SearchSpec, active
from dcfkit.autosearch.summary import (FINAL, finite, is_score, judge, mean_auc, mean_score, status_lines, summarize,
                                        verdict_line)
from dcfkit.autosearch.warm_start import base_params
from dcfkit.datasets import scored_sequences
from dcfkit.errors import DcfkitError, clip, printable, shown
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


def sample(spec: SearchSpec, study: str, number: int, recorded: list[dict]) -> dict[str, Any]:
    """Trial ``number``'s values: a TPE sampler seeded for (seed, study, number) told the
    ``recorded`` trials (each ``{"params", "value"}``)."""
    sampler = optuna.samplers.TPESampler(seed=derived_seed(4, spec.seed, study, number),
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
        self._units: dict[str, list[Unit]] = {}  # each record's check asks for its study's
        if spec.final_study == "if_it_wins" and not spec.baselines:
            raise DcfkitError(f"{spec.path}: final_study: if_it_wins needs baselines: with none, the folds beat "
                              f"nothing and the final study would never run; add baselines, or final_study: always")

    def order(self, study: str) -> list[str]:
        """The study's training sequences in the order successive halving scores them."""
        return sequence_order(self.training(study), self.spec.seed, study)

    def units(self, study: str) -> list[Unit]:
        """The study's units in the order successive halving scores them (:mod:`~dcfkit.autosearch.halving`)."""
        if study not in self._units:
            self._units[study] = self.spec.halving.units(self.order(study), self.spec.experiments)
        return self._units[study]

    def training(self, study: str) -> list[str]:
        if study == FINAL:
            return self.names
        held = set(self.folds[int(study.removeprefix("fold")) - 1])
        return [n for n in self.names if n not in held]

    def studies(self) -> list[str]:
        return [f"fold{i + 1}" for i in range(len(self.folds))] + [FINAL]

    def check_record(self, write: bool = True) -> None:
        """Write ``OUT/search.json`` (unless not ``write``: then it must be there), or refuse to
        resume a search whose trials would not stand."""
        path = self.out / "search.json"
        mine = fingerprint(self.spec, self.folds, self.evaluator)
        recorded = read_json(path)  # None: missing, unreadable or not an object
        if recorded is not None:
            self._check_fingerprint(path, recorded.get("fingerprint"), mine)
        elif not write:
            raise DcfkitError(f"no search is recorded under {self.out}: {path} is missing or not a search record")
        elif any(any((self.out / "trials" / study).glob("*.json")) for study in self.studies()):
            state = "not a search record as dcfkit writes it" if path.exists() else "missing"
            raise DcfkitError(f"{path} is {state}, yet {self.out / 'trials'} holds trial records: nothing shows which "
                              f"search made them; give a new --out, or remove {self.out / 'trials'} to start again")
        if write:
            atomic_write(path, json.dumps({"spec": shared_path(self.spec.path, self.out), "name": self.spec.name,
                                           "fingerprint": mine}, indent=1) + "\n")

    def _check_fingerprint(self, path: Path, old: Any, mine: dict) -> None:
        """Refuse to resume when the recorded fingerprint ``old`` is not ``mine``; one without the
        data's identity (dcfkit <= 0.9.0) is taken to be on this data."""
        if not isinstance(old, dict) or not old:
            raise DcfkitError(f"{path} holds no search fingerprint: not a search record as dcfkit writes it; give a "
                              f"new --out, or remove {self.out} to start again")
        if "data" not in old:
            log.warning("%s was written by dcfkit <= 0.9.0, without what identifies the data: the recorded "
                        "trials are taken to be on the data under %s", path, roots_text(self.spec))
            old = {**old, "data": mine["data"]}
        if "max_frames" not in old:  # recorded before --max-frames was: whole sequences
            old = {**old, "max_frames": None, "sequences": sorted(old.get("data") or {})}
        if "warm_start" not in old:  # recorded before dcfkit 0.14.0: every trial sampled
            old = {**old, "warm_start": False}
        if "halving" not in old:  # recorded before dcfkit 0.15.0: every trial on every sequence
            old = {**old, "halving": None}
        if isinstance(old.get("halving"), dict) and "experiments" not in old["halving"]:  # dcfkit 0.15.0
            old = {**old, "halving": {**old["halving"], "experiments": "together"}}
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
            why = ("; the base config's run key differs: another base config, dcfkit version or box code (a "
                   "search resumes with the code that recorded it)" if "base" in changed else "")
            raise DcfkitError(f"{path} records a different search (these differ: {', '.join(changed)}{why}): "
                              f"give a new --out, or remove {self.out} to start again")

    def recorded(self, study: str, running: bool = True) -> tuple[list[dict], Ladder | None]:
        """The study's trial records up to the first missing one, and its successive halving
        told them (None without ``halving``); a damaged or edited record is missing (with a
        warning naming what is wrong), and it and those after it are run again, to the same
        values (a search ``running``; ``--status`` says they would be)."""
        folder = self.out / "trials" / study
        records: list[dict] = []
        ladder = self._ladder(study, records)
        for n in range(self.spec.trials):
            path = folder / f"{n:04d}.json"
            rec = read_json(path)
            fault = "not a JSON object" if rec is None else record_fault(self, rec, n, study)
            if not fault and ladder is not None:
                fault = ladder.replay(rec["steps"], rec["pruned"])
                if fault:  # the pruner saw its values: told again without it
                    ladder = self._ladder(study, records)
            if fault:
                if path.exists():
                    log.warning("%s is not a trial record as dcfkit writes it (%s): trial %d of %s %s run again, "
                                "and the trials after it", path, fault, n, study, "is" if running else "would be")
                break
            records.append(rec)
        return records, ladder

    def _ladder(self, study: str, records: list[dict]) -> Ladder | None:
        """The study's successive halving told ``records`` (already checked), or None without it."""
        if self.spec.halving is None:
            return None
        ladder = Ladder(self.spec.halving, len(self.units(study)))
        for rec in records:
            ladder.replay(rec["steps"], rec["pruned"])
        return ladder

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
            n_scored = len(rec["scores"])
            scored = (f"pruned after {self.spec.halving.counted(rec['steps'][-1][0])}" if rec.get("pruned")
                      else f"on {n_scored} sequence{'s' if n_scored != 1 else ''}")
            self.report(f"{study} trial {n} ({n + 1} of {self.spec.trials}): mean AUC "
                        f"{_shown_auc(rec['steps'][-1][1] if rec.get('pruned') else rec['value'])} {scored} "
                        f"(best {_shown_auc(best)}) {shown(params)}")
        return records

    def _scored(self, config: dict, names: list[str], study: str, ladder: Ladder | None) -> dict:
        """A trial's value and scores: on every training sequence, or (successive halving) up
        the ``ladder``'s rungs, with its steps, whether it was pruned and (experiments in turn)
        its scores under each experiment."""
        if ladder is None:
            scores = finite(self.evaluator.scores(config, names))
            return {"value": mean_auc(scores, names), "scores": scores}
        units, experiments = self.units(study), self.spec.experiments
        by_experiment: dict[str, dict] = {e: {} for e in experiments}

        def score(start: int, stop: int) -> float | None:
            for exps, group in itertools.groupby(units[start:stop], key=lambda unit: unit[0]):
                found = self.evaluator.experiment_scores(config, [n for _, n in group], exps)
                for e in exps:
                    by_experiment[e].update(found[e])
            return mean_score([_unit_auc(by_experiment, unit) for unit in units[:stop]])

        steps, pruned = ladder.climb(score)
        reached = units[:steps[-1][0]]
        scores = finite(combined(by_experiment, complete(reached, experiments)))
        rec = {"value": None if pruned else mean_auc(scores, names), "scores": scores, "steps": steps,
               "pruned": pruned}
        return {**rec, "by_experiment": finite(by_experiment)} if self.spec.halving.experiments == "in_turn" else rec

    def status(self) -> list[str]:
        """Where the recorded search stands, running nothing: per study, its trials recorded
        (those that stand), pruned, and its best so far (:func:`~dcfkit.autosearch.summary.status_lines`)."""
        self.check_record(write=False)
        return status_lines(self, {study: self.recorded(study, running=False)[0] for study in self.studies()})

    def run(self) -> dict:
        """The fold studies, their held-out scores against the baselines, then the final study
        (unless ``final_study: if_it_wins`` and the folds lost), and the summary
        (:mod:`dcfkit.autosearch.summary`)."""
        ensure_writable(self.out, ("search.json",), "the search")
        warn_old_layout(self.out, "dcfkit search", "OUT/runs/<run key>/, OUT/baselines/<name>/")
        with exclusive(self.out / ".lock", "dcfkit search", f"to {self.out}"):
            self.check_record()
            studies = {study: self.run_study(study) for study in self.studies() if study != FINAL}
            judged = judge(self, studies)
            recorded = len(self.recorded(FINAL)[0])  # a complete final study is read, whatever the verdict
            runs_final = self.spec.final_study == "always" or judged["beats_every_baseline"] \
                or recorded == self.spec.trials
            self.report(f"{verdict_line(judged)}: the final study "
                        + ("follows" if runs_final else "is skipped (final_study: if_it_wins)"))
            if not runs_final:
                return summarize(self, studies, judged, final_recorded=recorded)
            studies[FINAL] = self.run_study(FINAL)
            return summarize(self, studies, judged)


def _option_value(value: Any) -> str:
    """A recorded ``--max-frames`` or ``--sequences`` as given on the command line."""
    if value is None:
        return "(not given: whole sequences)"
    return shown(",".join(value)) if isinstance(value, list) else shown(value)


def _halving_text(record: Any) -> str:
    """A recorded ``halving`` as the spec gives it."""
    if not isinstance(record, dict):
        return "none (every trial on every sequence)"
    values = (f"{k}: {clip(printable(v)) if isinstance(v, str) else shown(v)}" for k, v in record.items())
    return "{" + ", ".join(values) + "}"


def _unit_auc(by_experiment: dict[str, dict], unit: Unit) -> float:
    """A unit's AUC: its sequence's mean over the unit's experiments (NaN if none scored)."""
    exps, name = unit
    return combined({e: by_experiment[e] for e in exps}, [name])[name]["auc"]


def _shown_auc(value: float | None) -> str:
    return "none (no sequence has a scored frame)" if value is None else f"{value:.4f}"

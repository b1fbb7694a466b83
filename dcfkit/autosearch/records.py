"""What a trial record must be to stand on a resume (docs/search.md, "Resuming"): its number,
values, scores, value, config and run key checked against each other and against the search;
with successive halving, its steps and pruning as well. A record that does not stand is run
again, with a warning naming the field (:meth:`dcfkit.autosearch.study.Search.recorded`)."""
from __future__ import annotations

import json
import math
from typing import Any

import optuna

from dcfkit.autosearch.evaluation import combined
from dcfkit.autosearch.halving import Unit
from dcfkit.autosearch.space import SearchSpec, active
from dcfkit.autosearch.summary import finite, is_score, mean_auc, mean_score
from dcfkit.autosearch.warm_start import base_params
from dcfkit.errors import DcfkitError, clip, shown


def record_fault(search, rec: dict, number: int, study: str) -> str | None:
    """What makes ``rec`` not trial ``number`` of ``study`` as ``search``
    (a :class:`~dcfkit.autosearch.study.Search`) records it; None if nothing."""
    spec, names = search.spec, search.training(study)
    in_turn = spec.halving is not None and spec.halving.experiments == "in_turn"
    if spec.halving is None and ("steps" in rec or "pruned" in rec):
        return "steps, pruned: only a search with halving records them"
    if not in_turn and "by_experiment" in rec:
        return "by_experiment: only a search with halving's experiments: in_turn records it"
    reached: list[Unit] = []
    if spec.halving is not None:
        units = search.units(study)
        fault = steps_fault(rec, units, in_turn)
        if fault:
            return fault
        reached = units[:rec["steps"][-1][0]]
        if rec["pruned"]:  # a complete trial's value is the mean in the training order
            names = complete(reached, spec.experiments)
    if rec.get("number") != number:
        return f"number: expected {number}, got {shown(rec.get('number'))}"
    if number == 0 and spec.warm_start:
        base = base_params(spec)
        fault = None if rec.get("params") == base else f"params: expected the base config's, {shown(base)}"
    else:
        fault = params_fault(spec, rec.get("params"))
    fault = fault or scores_fault(rec, names, pruned=rec.get("pruned") is True)
    fault = fault or (by_experiment_fault(rec, reached, spec.experiments) if in_turn else None)
    if fault:
        return fault
    try:
        config = json.loads(json.dumps(spec.config(rec["params"])))  # as the record holds it
    except DcfkitError as exc:
        return f"params: {exc}"
    if rec.get("config") != config:
        return "config: not the config its params make"
    if rec.get("key") != search.evaluator.key(config):
        return "key: not its config's run key"
    return None


def params_fault(spec: SearchSpec, params: Any) -> str | None:
    """What is wrong with a record's ``params`` (None if nothing): they must be the dimensions
    the search samples, each with a value its dimension can take."""
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
    """Whether the search could sample ``value``: a label, a whole number or a float, in range."""
    kind = {optuna.distributions.CategoricalDistribution: str, optuna.distributions.IntDistribution: int}
    if type(value) is not kind.get(type(distribution), float):  # "0.5" or true would pass Optuna's check
        return False
    try:
        optuna.trial.create_trial(params={"v": value}, distributions={"v": distribution}, value=0.0)
    except (OverflowError, ValueError):  # an int past float's range
        return False
    return True


def scores_fault(rec: dict, names: list[str], pruned: bool = False) -> str | None:
    """What is wrong with a record's ``scores`` and ``value`` (None if nothing): the scores must be
    of the study's training sequences, ``names`` (those a ``pruned`` trial completed), and the
    value their mean AUC (null if the trial was pruned)."""
    scores = rec.get("scores")
    if not (isinstance(scores, dict) and sorted(scores) == sorted(names)):
        which = "the sequences its rungs completed" if pruned else "this study's training sequences"
        return f"scores: expected those of {which} {shown(names)}"
    if not _score_rows(scores):
        return "scores: expected {auc, precision} numbers or null for each sequence"
    value = rec.get("value")
    if pruned:
        return None if value is None else f"value: expected null for a pruned trial, got {shown(value)}"
    if isinstance(value, float) and math.isnan(value):  # dcfkit 0.9.0: NaN when a sequence had no score
        return None if any(not is_score(s["auc"]) for s in scores.values()) else "value: NaN, yet every AUC is scored"
    if not (is_number(value) and value == mean_auc(scores, names)):
        return f"value: {shown(value)} is not the mean AUC of its scores"
    return None


def steps_fault(rec: dict, units: list[Unit], in_turn: bool) -> str | None:
    """What is wrong with a record's ``steps`` and ``pruned`` (successive halving): ``[count,
    mean AUC]`` pairs, each the mean AUC over the first ``count`` of the study's ``units`` (as
    the record's scores give them), and true or false."""
    steps = rec.get("steps")
    if not (isinstance(steps, list) and steps and all(
            isinstance(s, list) and len(s) == 2 and type(s[0]) is int and 1 <= s[0] <= len(units) and is_number(s[1])
            for s in steps)):
        return f"steps: expected [units, mean AUC] pairs, got {shown(steps)}"
    if not isinstance(rec.get("pruned"), bool):
        return f"pruned: expected true or false, got {shown(rec.get('pruned'))}"
    for count, value in steps:
        aucs = unit_aucs(rec, units[:count], in_turn)
        if aucs is not None and value != mean_score(aucs):
            return f"steps: {shown(value)} is not the mean AUC of the scores of the first {count} units"
    return None


def by_experiment_fault(rec: dict, reached: list[Unit], experiments: tuple[str, ...]) -> str | None:
    """What is wrong with a record's ``by_experiment`` (halving's ``experiments: in_turn``): the
    scores of the ``reached`` units, per experiment, of which ``scores`` is the mean."""
    by = rec.get("by_experiment")
    want = {e: sorted(n for exps, n in reached if e in exps) for e in experiments}
    if not (isinstance(by, dict) and sorted(by) == sorted(experiments)
            and all(isinstance(by[e], dict) and sorted(by[e]) == want[e] for e in experiments)):
        return f"by_experiment: expected the scores of the units its rungs reached, {shown(want)}"
    if not all(_score_rows(by[e]) for e in experiments):
        return "by_experiment: expected {auc, precision} numbers or null for each sequence"
    names = complete(reached, experiments)
    if finite(combined({e: by[e] for e in experiments}, names)) != {n: rec["scores"][n] for n in names}:
        return "scores: not the mean over the experiments of by_experiment"
    return None


def unit_aucs(rec: dict, units: list[Unit], in_turn: bool) -> list | None:
    """Each unit's AUC as ``rec`` holds it (``by_experiment`` in turn, else ``scores``); None
    where the record lacks one."""
    try:
        if in_turn:
            return [rec["by_experiment"][exps[0]][n]["auc"] for exps, n in units]
        return [rec["scores"][n]["auc"] for _, n in units]
    except (KeyError, TypeError):
        return None


def complete(units: list[Unit], experiments: tuple[str, ...]) -> list[str]:
    """The sequences that ``units`` hold under every experiment, in the units' order."""
    held = {(e, n) for exps, n in units for e in exps}
    names = dict.fromkeys(n for _, n in units)
    return [n for n in names if all((e, n) in held for e in experiments)]


def is_number(value: Any) -> bool:
    """A score as records hold it: a number, or null (NaN in dcfkit 0.9.0's)."""
    return value is None or (isinstance(value, (int, float)) and not isinstance(value, bool))


def _score_rows(rows: dict) -> bool:
    """Whether each row holds ``auc`` and ``precision``, each a number or null."""
    return all(isinstance(s, dict) and all(k in s and is_number(s[k]) for k in ("auc", "precision"))
               for s in rows.values())

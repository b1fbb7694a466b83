"""Multi-fidelity: a trial scored on a few sequences first, and on more only while it stays
among the best, by Optuna's asynchronous successive halving (``SuccessiveHalvingPruner``) with
the number of *units* scored as the budget (docs/search.md, "Successive halving"). A unit is
a sequence under every experiment of the spec (``experiments: together``), or under one
(``in_turn``: the first experiment on every sequence, then the next, so a trial reaches the
costly TRE only after OPE has kept it).

A study's training sequences are taken in one order, fixed by the seed and the study, so every
trial at a rung is judged on the same units. The rungs are at ``min_sequences`` times
``reduction_factor`` to the k, then all of them: a trial continues past a rung only if its mean
AUC there (over its units) is in the top 1 / ``reduction_factor`` of the trials that reached
it. The pruner's decisions depend on the order of the trials, so they are replayed from the
records (a :class:`Ladder`), never stored: a resumed search decides as the first run did."""
from __future__ import annotations

import dataclasses
import hashlib
from typing import Any, Callable, Mapping

import numpy as np
import optuna
from optuna.trial import TrialState

from dcfkit.errors import ConfigError, shown

KEYS = ("min_sequences", "reduction_factor", "experiments")
MODES = ("together", "in_turn")  # halving's experiments: a unit is a sequence under all of them, or under one
Unit = tuple[tuple[str, ...], str]  # (experiments, sequence name)


@dataclasses.dataclass(frozen=True)
class Halving:
    """The spec's ``halving``: the first rung's unit count, the reduction factor η and how the
    experiments make units (:data:`MODES`)."""

    min_sequences: int
    reduction_factor: int
    experiments: str = "together"

    def rungs(self, n: int) -> list[int]:
        """The unit counts at which a trial of ``n`` units is judged, then ``n``."""
        counts, r = [], self.min_sequences
        while r < n:
            counts.append(r)
            r *= self.reduction_factor
        return [*counts, n]

    def units(self, order: list[str], experiments: tuple[str, ...]) -> list[Unit]:
        """The units of sequences ``order`` under ``experiments``, in the order the rungs take them."""
        if self.experiments == "in_turn":
            return [((e,), n) for e in experiments for n in order]
        return [(experiments, n) for n in order]

    def counted(self, count: int) -> str:
        """``count`` units in words: sequences, or (in turn) (sequence, experiment) pairs."""
        noun = "sequence" if self.experiments == "together" else "(sequence, experiment) pair"
        return f"{count} {noun}{'s' if count != 1 else ''}"

    def as_record(self) -> dict:
        return dataclasses.asdict(self)


def parse_halving(path, raw: Any) -> Halving | None:
    """The spec's ``halving`` mapping (None when absent or null: every trial on every sequence)."""
    if raw is None:
        return None
    where = f"{path}: halving"
    if not isinstance(raw, Mapping):
        raise ConfigError(f"{where}: expected a mapping {{min_sequences: N, reduction_factor: η}}, got {shown(raw)}")
    unknown = [k for k in raw if k not in KEYS]
    if unknown:
        raise ConfigError(f"{where}.{shown(unknown[0])}: not a key of halving (expected {', '.join(KEYS)})")
    values = {"experiments": raw.get("experiments", MODES[0])}
    if values["experiments"] not in MODES:
        raise ConfigError(f"{where}.experiments: expected {' or '.join(MODES)}, got {shown(values['experiments'])}")
    for key, least in (("min_sequences", 1), ("reduction_factor", 2)):
        if key not in raw:
            raise ConfigError(f"{where}.{key}: missing (a whole number >= {least})")
        value = raw[key]
        if isinstance(value, bool) or not isinstance(value, int) or value < least:
            raise ConfigError(f"{where}.{key}: expected a whole number >= {least}, got {shown(value)}")
        values[key] = value
    return Halving(**values)


def derived_seed(nbytes: int, *parts: Any) -> int:
    """A seed drawn from ``parts`` (the spec's seed, a study, a trial number or a purpose): the
    first ``nbytes`` of the SHA-256 of ``"a/b/c"``, the same on every machine and Python."""
    digest = hashlib.sha256("/".join(str(p) for p in parts).encode()).digest()
    return int.from_bytes(digest[:nbytes], "little")


def sequence_order(names: list[str], seed: int, study: str) -> list[str]:
    """The study's training sequences in the order the rungs take them: sorted, then shuffled
    by (seed, study), so a rung holds a mix of the pooled datasets."""
    order = np.random.default_rng(derived_seed(8, seed, study, "order")).permutation(sorted(names))
    return [str(n) for n in order]


class Ladder:
    """A study's successive halving: Optuna's pruner, told each recorded trial in turn."""

    def __init__(self, halving: Halving, n: int):
        self.halving, self.n = halving, n
        optuna.logging.set_verbosity(optuna.logging.WARNING)
        pruner = optuna.pruners.SuccessiveHalvingPruner(min_resource=halving.min_sequences,
                                                        reduction_factor=halving.reduction_factor)
        self.study = optuna.create_study(direction="maximize", pruner=pruner)

    def climb(self, score: Callable[[int, int], float | None]) -> tuple[list[list], bool]:
        """A new trial up the rungs: ``score(start, stop)`` scores the units of the order from
        ``start`` to ``stop`` and returns the mean AUC of the first ``stop``. Returns the steps
        (``[count, mean AUC]`` per rung reached) and whether the trial was pruned."""
        trial, steps, start = self.study.ask(), [], 0
        for stop in self.halving.rungs(self.n):
            steps.append([stop, score(start, stop)])
            start = stop
            if self._judged(trial, *steps[-1]):
                self._tell(trial, steps, pruned=True)
                return steps, True
        self._tell(trial, steps, pruned=False)
        return steps, False

    def replay(self, steps: list[list], pruned: bool) -> str | None:
        """Tell the study a recorded trial, its ``steps`` already checked to be ``[count, mean
        AUC]`` pairs (the search's ``_steps_fault``); what makes it not one :meth:`climb` would
        have made here (None if nothing). After a fault the ladder is spoilt (the pruner has seen the
        trial's values): build a new one from the records before it."""
        rungs = self.halving.rungs(self.n)
        if [s[0] for s in steps] != rungs[:len(steps)]:
            return f"steps: expected the rungs {shown(rungs[:len(steps)])}, got {shown([s[0] for s in steps])}"
        if not pruned and len(steps) < len(rungs):
            return f"steps: a trial not pruned reaches every rung, {shown(rungs)}"
        trial = self.study.ask()
        expected = [False] * (len(steps) - 1) + [pruned]
        for (count, value), wrote in zip(steps, expected):
            if self._judged(trial, count, value) != wrote:
                return (f"pruned: {str(wrote).lower()} after {self.halving.counted(count)}, where successive halving "
                        f"{'continues' if wrote else 'prunes'} it")
        self._tell(trial, steps, pruned)
        return None

    def _judged(self, trial: optuna.Trial, count: int, value: float | None) -> bool:
        """Report the mean AUC at ``count`` units; whether the pruner stops the trial there
        (never at the last rung: the trial is then complete). A rung none of whose units has
        a score (no frame the protocol scores, whatever the config) judges nothing: the next
        rung is judged for it too, by Optuna's pruner, against both rungs' values."""
        if value is None:
            return False
        trial.report(float(value), count)
        return count < self.n and trial.should_prune()

    def _tell(self, trial: optuna.Trial, steps: list, pruned: bool) -> None:
        value = steps[-1][1]
        if pruned:
            self.study.tell(trial, state=TrialState.PRUNED)
        elif value is None:
            self.study.tell(trial, state=TrialState.FAIL)
        else:
            self.study.tell(trial, float(value))


def intermediate(steps: list) -> dict[int, float]:
    """A record's steps as the intermediate values reported (none where no sequence had a score)."""
    return {int(count): float(value) for count, value in steps if value is not None}

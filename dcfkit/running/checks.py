"""What a run plan (:mod:`dcfkit.running.plan`) checks before anything is tracked, and says
of the runs it recomputes (docs/evaluation.md, "Running")."""
from __future__ import annotations

import json
import logging
from typing import Mapping

import numpy as np

from dcfkit.datasets import DatasetError, Sequence
from dcfkit.errors import shown
from dcfkit.experiments import Experiment
from dcfkit.store.provenance import json_default
from dcfkit.store.results import ResultStore, same_data

log = logging.getLogger(__name__)


def check_first_boxes(sequences: list[Sequence]) -> None:
    """A :class:`DatasetError` naming each sequence whose frame 1 has no box to start from."""
    bad = [s.name + (f" (first box in {s.annotation})" if s.annotation else "") for s in sequences
           if not (np.isfinite(s.ground_truth[0]).all() and (s.ground_truth[0, 2:] > 0).all())]
    if bad:
        raise DatasetError(f"one-pass evaluation initialises on frame 1's ground truth, which is NaN or "
                           f"empty in sequence(s): {', '.join(bad)}")


def check_same_dataset(store: ResultStore, metas: Mapping, todo: list[Sequence]) -> None:
    """OUT/<name>/<sequence> has no benchmark level: never mix two benchmarks there."""
    for seq in todo:
        old = (metas[seq.name] or {}).get("dataset")
        if old and seq.dataset and old != seq.dataset:
            raise DatasetError(f"{store.sidecar_path(seq.name)} holds results on dataset {shown(old)}, and this run "
                               f"is on {shown(seq.dataset)}: use a separate --out for each benchmark")


def say_what_is_recomputed(store: ResultStore, metas: Mapping, todo: list[Sequence], config: Mapping, name: str,
                           key: str) -> None:
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
                    "config another name to keep both)", store.folder, name, len(replaced),
                    ", ".join(replaced[:10]))


def say_other_rule(store: ResultStore, metas: Mapping, todo: list[Sequence], experiment: Experiment) -> None:
    """Say so when results are recomputed because the experiment's other rules made them."""
    other = {s.name: why for s in todo if (why := experiment.stored_elsewise(metas[s.name])) is not None}
    if other:
        log.warning("%s: recomputing %d %s result(s) whose failures another rule decided (%s), with %s's: "
                    "%s", store.folder, len(other), experiment.name, ", ".join(sorted(set(other.values()))),
                    experiment.rule, ", ".join(list(other)[:10]))

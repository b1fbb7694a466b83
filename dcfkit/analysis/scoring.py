"""Scoring trackers' results on sequences under one protocol: per sequence, per attribute, overall, with the curves."""
from __future__ import annotations

import dataclasses
import logging
import math
from collections import Counter
from typing import Iterable, Mapping

import numpy as np

from dcfkit.analysis import metrics
from dcfkit.analysis.setting import cut_length, experiment_record
from dcfkit.analysis.statistics import Comparison, versus_baseline
from dcfkit.datasets import ATTRIBUTE_NAMES, DatasetError, Sequence, benchmark_protocol, scored_sequences
from dcfkit.errors import shown
from dcfkit.experiments import Experiment, get_experiment, runs_by_sequence
from dcfkit.protocols import Protocol, get_protocol
from dcfkit.store import platforms, timing as speed

log = logging.getLogger(__name__)


def _boxes_and_fps(result) -> tuple[np.ndarray, float | None, str | None]:
    """(boxes, fps, how the fps was measured: :func:`dcfkit.store.timing.how_measured` of the
    result's ``timing``, None without an fps)."""
    if hasattr(result, "boxes"):
        boxes, fps, timing = result.boxes, getattr(result, "fps", None), getattr(result, "timing", None)
    elif isinstance(result, Mapping):
        boxes, fps, timing = result["boxes"], result.get("fps"), result.get("timing")
    else:
        boxes, fps, timing = result, None, None
    return np.asarray(boxes, dtype=np.float64), fps, None if fps is None else speed.how_measured(timing)


def _mean_or_none(values) -> float | None:
    values = [v for v in values if v is not None and math.isfinite(v)]
    return float(np.mean(values)) if values else None


@dataclasses.dataclass(frozen=True)
class Evaluation:
    """The scores of :func:`evaluate`, with the :class:`Protocol` they were scored under.

    ``overall``, ``per_sequence`` and ``per_attribute`` are row lists (trackers best first by
    the protocol's ranking score); ``curves`` maps tracker -> averaged curves,
    ``attribute_curves`` attribute -> tracker -> curves, ``attributes`` attribute -> number of
    sequences; ``settings`` how they were scored, with ``datasets`` (dataset -> sequences scored:
    several when roots were pooled); ``platforms`` tracker -> ``[[platform, sequences], ...]``; ``statistics`` each
    tracker's ranking score and precision with confidence intervals and its paired difference
    from the best (a :class:`~dcfkit.analysis.stats.results.Comparison` of
    :func:`dcfkit.analysis.statistics.versus_baseline`; ``{}`` without trackers); ``long_term`` the
    VOT-LT precision, recall and F a report adds (:func:`dcfkit.analysis.longterm_report.score_long_term`;
    ``{}`` from :func:`evaluate` alone).
    """

    protocol: Protocol
    overall: list[dict]
    per_sequence: list[dict]
    per_attribute: list[dict]
    curves: dict
    attribute_curves: dict
    attributes: dict[str, int]
    thresholds: dict
    settings: dict
    platforms: dict
    statistics: Comparison | dict
    long_term: dict = dataclasses.field(default_factory=dict)

    def as_record(self) -> dict:
        """The scores as plain data (``report.json``): the protocol and the experiment as their
        name, title and source; ``settings`` name the experiment and the ``--max-frames`` cut
        (``max_frames``, None for whole sequences)."""
        record = {f.name: getattr(self, f.name) for f in dataclasses.fields(self)}
        record["protocol"] = protocol_record(self.protocol)
        record["experiment"] = experiment_record(self.settings["experiment"])
        return record


def protocol_record(protocol: Protocol) -> dict:
    return {"name": protocol.name, "title": protocol.title, "source": protocol.source}


MISSING = ("skip", "fail")  # what evaluate() does with a sequence a tracker has no result for


def evaluate(results: Mapping[str, Mapping], sequences: Iterable[Sequence],
             include_first: bool = True, weighting: str | None = None,
             protocol: str | Protocol | None = None, missing: str = "fail",
             experiment: str | Experiment = "ope", runs: Mapping[str, list[Sequence]] | None = None,
             baseline: str | None = None) -> Evaluation:
    """Score ``results`` (tracker -> sequence name -> boxes) on ``sequences`` under ``protocol``
    (by default the rules of the benchmark's published tables,
    :func:`~dcfkit.datasets.benchmark_protocol`: LaSOT's for LaSOT, the OTB toolkit's for UAV123).

    A result is a :class:`dcfkit.store.results.SequenceResult`, a dict with ``boxes`` (and
    optional ``fps`` and ``timing``) or an ``(N, 4)`` array of 0-based boxes. A row's ``fps`` is
    shown only when every run of it was timed alone, ``fps_measured`` says how
    (:mod:`dcfkit.store.timing`), and ``settings["fps_note"]`` whose is left out and why.
    ``weighting`` ``None`` averages as the protocol does. ``missing``: ``"skip"`` scores the
    sequences every tracker has a result for and names the others in ``settings["left_out"]``
    (sequence -> the trackers without a result); ``"fail"`` scores a missing result as a total
    failure, as the toolkits do. Sequences whose ground truth is withheld after frame 1 (test splits) are left out
    (:func:`~dcfkit.datasets.scored_sequences`: a :class:`DatasetError` if that leaves none).

    ``experiment`` ``tre`` or ``sre`` (:mod:`dcfkit.experiments`): results are keyed by run
    name, and a sequence's score pools the frames of its runs (:func:`metrics.pool_runs`); a
    sequence lacks a result unless it has all its runs. ``runs``: sequence name -> its runs,
    when the caller made them already (:func:`dcfkit.experiments.runs_by_sequence`; an SRE
    run reads its sequence's first frame). ``baseline``: the tracker the paired differences are
    taken from (default: the best; :func:`check_baseline`).
    """
    sequences = list(sequences)
    proto = get_protocol(protocol or benchmark_protocol(sequences))
    weighting = weighting or proto.weighting
    keys = proto.score_keys
    experiment = get_experiment(experiment)
    if experiment.scoring != "otb":
        raise ValueError(f"{experiment.name} runs are scored by their own scoring ({experiment.scoring}), not evaluate()")
    runs = runs if runs is not None else runs_by_sequence(scored_sequences(sequences), experiment)
    sequences, left_out = _complete(scored_sequences(sequences), results, missing, runs)
    per_seq, fps, measured, missing = {}, {}, {}, {}
    for tracker, res in results.items():
        per_seq[tracker], (fps[tracker], measured[tracker]), missing[tracker] = _score_tracker(
            tracker, res, sequences, runs, include_first, proto)

    overall, curves = [], {}
    for tracker in results:
        avg = metrics.average(per_seq[tracker].values(), weighting, proto)
        curves[tracker] = _curves(avg)
        how = speed.combined(measured[tracker].values())
        overall.append({"tracker": tracker, **{k: avg[k] for k in keys},
                        "fps": _mean_or_none(fps[tracker].values()) if how == speed.ALONE else None,
                        "fps_measured": how,
                        "sequences": len(sequences), "missing": len(missing[tracker]), "frames": avg["frames"]})
    overall = _rank(overall, proto)
    ranked = [r["tracker"] for r in overall]
    check_baseline(baseline, ranked)
    per_sequence = [
        {"tracker": t, "sequence": s.name, **{k: per_seq[t][s.name][k] for k in keys},
         "fps": fps[t][s.name] if measured[t][s.name] == speed.ALONE else None,
         "fps_measured": measured[t][s.name], "frames": per_seq[t][s.name]["frames"]}
        for t in ranked for s in sequences]
    attributes = _attribute_members(sequences)
    per_attribute, attribute_curves = _per_attribute(attributes, per_seq, ranked, weighting, proto)
    return Evaluation(
        protocol=proto, overall=overall, per_sequence=per_sequence, per_attribute=per_attribute,
        curves=curves, attribute_curves=attribute_curves,
        attributes={a: len(n) for a, n in attributes.items()}, thresholds=proto.thresholds,
        settings={"protocol": proto.name, "experiment": experiment.name, "max_frames": cut_length(sequences),
                  "include_first": include_first, "weighting": weighting, "fps_note": speed.fps_note(overall),
                  "missing": "skip" if left_out is not None else "fail", "left_out": left_out or {},
                  "datasets": dict(Counter(s.dataset or "unnamed" for s in sequences))},
        platforms={t: _platforms(res.values()) for t, res in results.items()},
        statistics=versus_baseline(per_sequence, ranked, (proto.rank_key, "precision"), baseline) if ranked else {})


def check_baseline(baseline: str | None, trackers: list[str]) -> None:
    """A :class:`DatasetError` unless ``baseline`` is None or one of ``trackers`` (``--baseline``)."""
    if baseline is not None and baseline not in trackers:
        raise DatasetError(f"--baseline {shown(baseline)}: no such tracker in this report; its trackers are "
                           f"{', '.join(map(shown, trackers)) or 'none'}")


def _complete(sequences: list[Sequence], results: Mapping[str, Mapping], missing: str,
              runs: Mapping[str, list[Sequence]]) -> tuple[list, dict | None]:
    """(the sequences to score, sequence -> trackers without a result of every run; None
    under "fail")."""
    if missing not in MISSING:
        raise ValueError(f"missing must be one of {', '.join(MISSING)}, got {shown(missing)}")
    if missing == "fail":
        return sequences, None
    left_out = {s.name: [t for t, res in results.items() if any(r.name not in res for r in runs[s.name])]
                for s in sequences}
    left_out = {name: trackers for name, trackers in left_out.items() if trackers}
    kept = [s for s in sequences if s.name not in left_out]
    if not kept:
        raise DatasetError(f"no sequence has a result from every tracker ({len(sequences)} sequences, "
                           f"{len(results)} trackers): report fewer trackers, or score missing results as "
                           f"failures (--missing fail)")
    if left_out:
        log.warning("%d of %d sequences left out, without a result from every tracker (--missing fail scores "
                    "them as failures): %s", len(left_out), len(sequences), ", ".join(list(left_out)[:10]))
    return kept, left_out


def _platforms(results: Iterable) -> list[list]:
    """``[[platform line, sequences], ...]`` of one tracker's results (imports: none recorded)."""
    return [[line, n] for line, n in Counter(
        platforms.describe(getattr(r, "platform", None)) for r in results).most_common()]


def _score_tracker(tracker: str, res: Mapping, sequences: list[Sequence], runs: Mapping[str, list[Sequence]],
                   include_first: bool, proto: Protocol) -> tuple[dict, tuple[dict, dict], list]:
    """(sequence -> scores, (sequence -> fps, sequence -> how it was measured:
    :func:`dcfkit.store.timing.combined`), names of the sequences missing a run) of one
    tracker's results, each sequence's runs pooled."""
    scores, fps, measured, missing = {}, {}, {}, []
    for seq in sequences:
        pooled, speeds, kinds = [], [], []
        for run in runs[seq.name]:
            boxes, run_fps, kind = _run_boxes(tracker, res, run)
            pooled.append(metrics.score_sequence(boxes, run.ground_truth, include_first, proto))
            speeds.append(run_fps)
            kinds.append(kind)
        scores[seq.name] = pooled[0] if len(pooled) == 1 else metrics.pool_runs(pooled, proto)
        fps[seq.name], measured[seq.name] = _mean_or_none(speeds), speed.combined(kinds)
        if any(run.name not in res for run in runs[seq.name]):
            missing.append(seq.name)
    if missing:
        log.warning("tracker %r has no results for %d of %d sequences (scored as failures; "
                    "report on the sequences that were run, e.g. with --sequences, to leave them out): %s",
                    tracker, len(missing), len(sequences), ", ".join(missing[:10]))
    return scores, (fps, measured), missing


def _run_boxes(tracker: str, res: Mapping, run: Sequence) -> tuple[np.ndarray, float | None, str | None]:
    """(boxes, fps, how it was measured) of ``run`` in ``res`` (no boxes when it has none),
    checked not too long."""
    if run.name not in res:
        return np.empty((0, 4)), None, None
    boxes, fps, kind = _boxes_and_fps(res[run.name])
    if len(boxes) > len(run):
        raise DatasetError(f"tracker {shown(tracker)}, sequence {run.name!r}: {len(boxes)} boxes for "
                           f"{len(run)} frames")
    if len(boxes) < len(run):
        log.warning("tracker %r, sequence %r: %d boxes for %d frames; the last %d frames are "
                    "scored as failures", tracker, run.name, len(boxes), len(run), len(run) - len(boxes))
    return boxes, fps, kind


def _rank(rows: list[dict], proto: Protocol) -> list[dict]:
    return sorted(rows, key=lambda r: best_first(r[proto.rank_key]))


def _attribute_members(sequences: list[Sequence]) -> dict[str, list[str]]:
    """attribute -> the sequences that have it (attributes no sequence has are left out)."""
    members: dict[str, list[str]] = {}
    for seq in sequences:
        for attr, present in seq.attributes.items():
            members.setdefault(attr, [])
            if present:
                members[attr].append(seq.name)
    return {a: names for a, names in members.items() if names}


def _per_attribute(attributes: dict, per_seq: dict, ranked: list[str], weighting: str,
                   proto: Protocol) -> tuple[list[dict], dict]:
    """Rows (per attribute, trackers ranked) and curves of the scores averaged per attribute."""
    per_attribute, attribute_curves = [], {}
    for attr, names in attributes.items():
        attribute_curves[attr] = {}
        rows = []
        for tracker in ranked:
            avg = metrics.average([per_seq[tracker][n] for n in names], weighting, proto)
            attribute_curves[attr][tracker] = _curves(avg)
            rows.append({"attribute": attr, "name": ATTRIBUTE_NAMES.get(attr, attr),
                         "sequences": len(names), "tracker": tracker, **{k: avg[k] for k in proto.score_keys}})
        per_attribute += _rank(rows, proto)
    return per_attribute, attribute_curves


def _curves(avg: dict) -> dict:
    return {"precision": avg["precision_curve"], "success": avg["success_curve"],
            "norm_precision": avg["norm_precision_curve"], "precision_score": avg["precision"],
            "auc": avg["auc"], "norm_precision_score": avg["norm_precision"]}


def best_first(score) -> float:
    """Sort key of a score: highest first, a missing or NaN score last."""
    return -score if score is not None and math.isfinite(score) else math.inf

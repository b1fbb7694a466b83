"""A search's result: each fold's choice scored on the sequences it never saw, compared per
sequence with the trackers to beat, and the final study's best config (docs/search.md)."""
from __future__ import annotations

import json
import math

import numpy as np
import yaml

from dcfkit.ablation.spec_keys import data_record
from dcfkit.analysis.stats.columns import DIFFERENCE, MEAN, cells, headers
from dcfkit.analysis.stats.results import Corrected, Interval
from dcfkit.analysis.statistics import HOLM, METHOD, holm, mean_interval, paired_difference
from dcfkit.autosearch.halving import KEYS, Halving
from dcfkit.errors import DcfkitError, printable
from dcfkit.store.files import atomic_write, read_json
from dcfkit.store.provenance import shared_path

FINAL = "all"  # the final study's name: every sequence chooses


def is_score(value) -> bool:
    """Whether ``value`` is a score: a finite number (a trial's or sequence's value may be
    None, or NaN in a record of dcfkit <= 0.9.0, when no frame could be scored)."""
    return isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)


def mean_auc(scores: dict[str, dict], names: list[str]) -> float | None:
    """The mean AUC over those of ``names`` that have one; None if none has. A sequence with no
    frame the protocol scores (a one-frame sequence under ``got10k``) has none, whatever the config."""
    return mean_score([scores[n]["auc"] for n in names])


def mean_score(values: list) -> float | None:
    """The mean of those of ``values`` that are scores; None if none is."""
    values = [v for v in values if is_score(v)]
    return float(np.mean(values)) if values else None


def finite(value):
    """``value`` with each non-finite float replaced by None: JSON has no NaN."""
    if isinstance(value, float):
        return value if math.isfinite(value) else None
    if isinstance(value, dict):
        return {k: finite(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [finite(v) for v in value]
    return value


def best(records: list[dict], study: str) -> dict:
    """The trial with the highest value (the first of equals); trials without a value never."""
    scored = [r for r in records if is_score(r["value"])]
    if not scored:
        raise DcfkitError(f"study {study}: none of its {len(records)} trials has a score (no sequence it "
                          f"searches on has a frame the protocol scores)")
    return max(scored, key=lambda r: (r["value"], -r["number"]))


def judge(search, studies: dict[str, list[dict]]) -> dict:
    """Each fold study's best config scored on the fold it never saw, and those held-out scores
    against each baseline's on every sequence (docs/search.md, steps 3 and 4)."""
    ev = search.evaluator
    held_out: dict[str, dict] = {}
    folds = []
    for i, names in enumerate(search.folds):
        chosen = best(studies[f"fold{i + 1}"], f"fold{i + 1}")
        scores = ev.scores(chosen["config"], names)
        held_out.update(scores)
        folds.append({"fold": i + 1, "held_out": names, "trial": chosen["number"], "params": chosen["params"],
                      "training_auc": chosen["value"], "held_out_auc": mean_auc(scores, names)})
    baselines = {name: ev.scores(config, search.names, baseline=name) for name, config in search.spec.baselines.items()}
    comparisons = _compare(search.names, held_out, baselines)
    return {"unscored": [n for n in search.names if not is_score(held_out[n]["auc"])], "folds": folds,
            "held_out": {"auc": mean_interval([held_out[n]["auc"] for n in search.names]).as_record(),
                         "per_sequence": held_out},
            "baselines": {name: {"auc": mean_interval([s[n]["auc"] for n in search.names]).as_record(),
                                 "per_sequence": s} for name, s in baselines.items()},
            "comparisons": comparisons, "method": METHOD, "correction": HOLM,
            "beats_every_baseline": bool(comparisons) and all(c["significant"] for c in comparisons.values())}


def verdict_line(judged: dict) -> str:
    """The held-out verdict in a line, for the log before the final study."""
    h = Interval.from_record(judged["held_out"]["auc"])
    beaten = sum(c["significant"] for c in judged["comparisons"].values())
    return (f"held-out folds: mean AUC {_n(h.mean, '.4f')} [{_n(h.ci_low, '.4f')}, {_n(h.ci_high, '.4f')}]; "
            f"{beaten} of {len(judged['comparisons'])} baselines beaten")


def summarize(search, studies: dict[str, list[dict]], judged: dict, final_recorded: int = 0) -> dict:
    """For a :class:`~dcfkit.autosearch.study.Search`, its studies' records and its held-out
    verdict (:func:`judge`): write ``OUT/summary.json``, ``summary.md`` and ``best.yaml`` (the
    final study's best; none when it was skipped, after ``final_recorded`` trials of an earlier
    run); returns the summary."""
    spec = search.spec
    final = best(studies[FINAL], FINAL) if FINAL in studies else None
    summary = {"name": spec.name, "spec": shared_path(spec.path, search.out), "dataset": data_record(spec)["dataset"],
               "experiments": list(spec.experiments), "trials_per_study": spec.trials, "max_frames": spec.max_frames,
               "sequences": search.names, **judged, "final_study": spec.final_study,
               "final": final and {"trial": final["number"], "params": final["params"], "auc": final["value"],
                                   "key": final["key"]},
               **({} if final else {"final_recorded": final_recorded}),
               "halving": _halving(search, studies)}
    summary = finite(summary)  # as summary.json holds it
    atomic_write(search.out / "summary.json", json.dumps(summary, indent=1, allow_nan=False) + "\n")
    atomic_write(search.out / "summary.md", "\n".join(summary_lines(summary)) + "\n")
    if final is None:  # a best.yaml of an earlier run would read as this one's choice
        (search.out / "best.yaml").unlink(missing_ok=True)
        return summary
    best_config = {"name": f"{spec.name}_best", "description": f"found by dcfkit search {spec.name} "
                   f"(final study, trial {final['number']})", **{k: v for k, v in final["config"].items()
                                                                 if k not in ("name", "description")}}
    atomic_write(search.out / "best.yaml", yaml.safe_dump(best_config, sort_keys=False, allow_unicode=True))
    return summary


def _halving(search, studies: dict[str, list[dict]]) -> dict | None:
    """What successive halving spared: per study, the trials pruned and the frames tracked (every
    experiment's runs of the units reached) against those of every trial on every unit."""
    if search.spec.halving is None:
        return None
    frames = search.evaluator.frames
    per_study = {}
    for study, records in studies.items():
        units = search.units(study)
        per_study[study] = {"trials": len(records), "pruned": sum(bool(r.get("pruned")) for r in records),
                            "frames": sum(frames(units[:r["steps"][-1][0]]) for r in records),
                            "frames_unpruned": len(records) * frames(units)}
    return {**search.spec.halving.as_record(), "studies": per_study}


def status_lines(search, studies: dict[str, list[dict]]) -> list[str]:
    """Where a search stands from its studies' records (those that stand): per study, the
    trials recorded, pruned and the best so far; then whether its summary is written."""
    budget = search.spec.trials
    skipped = _final_skipped(search, studies)
    lines = [f"search {printable(search.spec.name)} under {search.out}: "
             f"{sum(len(r) == budget for r in studies.values())} of {len(studies)} studies complete, "
             f"{sum(len(r) for r in studies.values())} of {budget * len(studies)} trials recorded"]
    for study, records in studies.items():
        if records:
            pruned = sum(bool(r.get("pruned")) for r in records)
            top = best(records, study) if any(is_score(r["value"]) for r in records) else None
            found = (f"best trial {top['number']}, mean AUC {top['value']:.4f} on {len(search.training(study))} "
                     f"sequences" if top else "no trial scored yet")
            line = f"  {study}: {len(records)} of {budget} trials" + (f" ({pruned} pruned)" if pruned else "") + \
                f"; {found}"
        else:
            line = f"  {study}: not begun" + ("" if skipped else _when(search, study))
        lines.append(line + ("; skipped: the folds lost held out (final_study: if_it_wins)"
                             if skipped and study == FINAL else ""))
    done = (search.out / "summary.md").is_file() and all(len(r) == budget or (skipped and study == FINAL)
                                                         for study, r in studies.items())
    lines.append(f"summary.md: {'written' if done else 'not yet: it is written when the studies it runs are complete'}")
    return lines


def _final_skipped(search, studies: dict[str, list[dict]]) -> bool:
    """Whether a run under this spec's budget stops before the end of the final study: the
    summary written by the last run says the folds lost, and a rerun would skip it again."""
    written = read_json(search.out / "summary.json")
    return (search.spec.final_study == "if_it_wins" and isinstance(written, dict) and written.get("final", 0) is None
            and written.get("trials_per_study") == search.spec.trials and not written.get("beats_every_baseline")
            and len(studies.get(FINAL, ())) < search.spec.trials
            and all(len(r) == search.spec.trials for study, r in studies.items() if study != FINAL))


def _when(search, study: str) -> str:
    """When a study not begun will run, if not surely."""
    return (" (it runs only if the folds beat every baseline held out: final_study: if_it_wins)"
            if study == FINAL and search.spec.final_study == "if_it_wins" else "")


def _compare(names: list[str], held_out: dict, baselines: dict) -> dict:
    """The held-out AUC minus each baseline's, per sequence: interval, Wilcoxon p, Holm across
    the baselines; ``significant``: Holm p < 0.05 and the interval above 0."""
    diffs = {name: paired_difference([held_out[n]["auc"] for n in names], [s[n]["auc"] for n in names])
             for name, s in baselines.items()}
    return {name: Corrected.of(d, p, bool(p < 0.05 and d.ci_low > 0)).as_record()
            for (name, d), p in zip(diffs.items(), holm([d.wilcoxon_p for d in diffs.values()]))}


def summary_lines(summary: dict) -> list[str]:
    """``summary.md``: the folds, the held-out score against each baseline, the final choice."""
    lines = [f"# Search {printable(summary['name'])}", "",
             f"{len(summary['sequences'])} sequences, {len(summary['folds'])} folds, "
             f"{summary['trials_per_study']} trials a study; objective: mean AUC over "
             f"{' + '.join(summary['experiments'])} (each sequence's runs pooled){_cut(summary)}.", "",
             "| fold | held out | trial | training AUC | held-out AUC | values |", "|---|---|---|---|---|---|"]
    for f in summary["folds"]:
        lines.append(f"| {f['fold']} | {_cell(', '.join(f['held_out']))} | {f['trial']} | "
                     f"{_n(f['training_auc'], '.4f')} | {_n(f['held_out_auc'], '.4f')} | "
                     f"{_cell(_values(f['params']))} |")
    unscored = summary.get("unscored") or []  # absent from the summaries of dcfkit <= 0.9.0
    if unscored:
        lines += ["", f"Left out of the means and tests, having no frame the protocol scores ({len(unscored)} of "
                      f"{len(summary['sequences'])}): {printable(', '.join(unscored))}."]
    h = Interval.from_record(summary["held_out"]["auc"])
    heads = ["baseline", *headers(MEAN, "search", "AUC"), *headers(DIFFERENCE, "search")]
    lines += ["", f"Held-out AUC of the search: {_n(h.mean, '.4f')} [{_n(h.ci_low, '.4f')}, {_n(h.ci_high, '.4f')}]",
              "", "| " + " | ".join(heads) + " |", "|" + "---|" * len(heads)]
    for name, record in summary["comparisons"].items():  # the statistics declared for "search"
        found = (cells(MEAN, "search", Interval.from_record(summary["baselines"][name]["auc"]), "auc")
                 + cells(DIFFERENCE, "search", Corrected.from_record(record), "auc"))
        lines.append("| " + " | ".join([_cell(name), *found]) + " |")
    lines += _halving_lines(summary.get("halving"))  # absent from the summaries of dcfkit <= 0.14
    final = summary["final"]
    verdict = ("it beats every baseline on held-out folds" if summary["beats_every_baseline"]
               else "it does not beat every baseline on held-out folds: do not ship it")
    chosen = (f"Final study (every sequence): trial {final['trial']}, AUC {_n(final['auc'], '.4f')}, "
              f"{printable(_values(final['params']))}; best.yaml." if final else _final_not_run(summary))
    lines += ["", f"{chosen} The search: {verdict}.", "", summary["method"] + "; "
              + summary["correction"] + " (beaten: significant and the interval above 0)."]
    return lines


def _final_not_run(summary: dict) -> str:
    """Why a summary has no final study, a sentence."""
    if summary["beats_every_baseline"]:  # a verdict written before its final study (never by Search.run)
        return "Final study: not run yet (the folds beat every baseline: resume the search to run it); no best.yaml."
    k = summary.get("final_recorded") or 0
    before = f", after {k} of {summary['trials_per_study']} trials of an earlier run" if k else ""
    return f"Final study: not run (`final_study: if_it_wins`, and the folds lost{before}); no best.yaml."


def _halving_lines(halving: dict | None) -> list[str]:
    """What successive halving spared, a sentence; none without it."""
    if not halving:
        return []
    studies = halving["studies"].values()
    trials, pruned = sum(s["trials"] for s in studies), sum(s["pruned"] for s in studies)
    frames, unpruned = sum(s["frames"] for s in studies), sum(s["frames_unpruned"] for s in studies)
    share = f"{frames / unpruned:.0%}" if unpruned else "n/a"
    rule = Halving(**{k: halving[k] for k in KEYS if k in halving})  # dcfkit 0.15.0 recorded no experiments
    turn = ", the experiments in turn" if rule.experiments == "in_turn" else ""
    return ["", f"Successive halving (first rung {rule.counted(rule.min_sequences)}, reduction factor "
                f"{rule.reduction_factor}{turn}): {pruned} of {trials} trials pruned; the studies tracked {share} of "
                f"the frames of every trial on every training sequence ({frames:,} of {unpruned:,})."]


def _cut(summary: dict) -> str:
    """A quick try's ``--max-frames`` cut, said where the objective is (older summaries have none)."""
    n = summary.get("max_frames")
    return (f"; each sequence's first {n} frames only (--max-frames {n}: a quick try, not a search to ship from)"
            if n else "")


def _values(params: dict) -> str:
    return ", ".join(f"{k}={v:.4g}" if isinstance(v, float) else f"{k}={v}" for k, v in params.items())


def _cell(text: str) -> str:
    """``text`` as one markdown table cell: one line, its ``|`` escaped (names come from specs and folders)."""
    return printable(text).replace("|", "\\|")


def _n(value, form: str) -> str:
    """A number as ``form`` gives it; ``n/a`` for None (JSON's NaN)."""
    return format(value, form) if is_score(value) else "n/a"

"""A search's result: each fold's choice scored on the sequences it never saw, compared per
sequence with the trackers to beat, and the final study's best config (docs/search.md)."""
from __future__ import annotations

import json

import numpy as np
import yaml

from dcfkit.analysis.statistics import HOLM, METHOD, holm, mean_interval, paired_difference
from dcfkit.errors import DcfkitError
from dcfkit.running.files import atomic_write

FINAL = "all"  # the final study's name: every sequence chooses


def best(records: list[dict]) -> dict:
    """The trial with the highest value (the first of equals)."""
    if not records:
        raise DcfkitError("a study without trials has no best")
    return max(records, key=lambda r: (r["value"], -r["number"]))


def summarize(search, studies: dict[str, list[dict]]) -> dict:
    """For a :class:`~dcfkit.autosearch.study.Search` and its studies' records: score and write ``OUT/summary.json``, ``summary.md`` and ``best.yaml``; returns the summary."""
    spec, ev = search.spec, search.evaluator
    held_out: dict[str, dict] = {}
    folds = []
    for i, names in enumerate(search.folds):
        chosen = best(studies[f"fold{i + 1}"])
        scores = ev.scores(chosen["config"], names)
        held_out.update(scores)
        folds.append({"fold": i + 1, "held_out": names, "trial": chosen["number"], "params": chosen["params"],
                      "training_auc": chosen["value"], "held_out_auc": float(np.mean([scores[n]["auc"] for n in names]))})
    baselines = {name: ev.scores(config, search.names) for name, config in spec.baselines.items()}
    comparisons = _compare(search.names, held_out, baselines)
    final = best(studies[FINAL])
    summary = {"name": spec.name, "spec": str(spec.path), "dataset": spec.dataset,
               "experiments": list(spec.experiments), "trials_per_study": spec.trials,
               "sequences": search.names, "folds": folds,
               "held_out": {"auc": mean_interval([held_out[n]["auc"] for n in search.names]).as_record(),
                            "per_sequence": held_out},
               "baselines": {name: {"auc": mean_interval([s[n]["auc"] for n in search.names]).as_record(),
                                    "per_sequence": s} for name, s in baselines.items()},
               "comparisons": comparisons, "method": METHOD, "correction": HOLM,
               "beats_every_baseline": bool(comparisons) and all(c["significant"] for c in comparisons.values()),
               "final": {"trial": final["number"], "params": final["params"], "auc": final["value"],
                         "key": final["key"]}}
    atomic_write(search.out / "summary.json", json.dumps(summary, indent=1) + "\n")
    atomic_write(search.out / "summary.md", "\n".join(summary_lines(summary)) + "\n")
    best_config = {"name": f"{spec.name}_best", "description": f"found by dcfkit search {spec.name} "
                   f"(final study, trial {final['number']})", **{k: v for k, v in final["config"].items()
                                                                 if k not in ("name", "description")}}
    atomic_write(search.out / "best.yaml", yaml.safe_dump(best_config, sort_keys=False, allow_unicode=True))
    return summary


def _compare(names: list[str], held_out: dict, baselines: dict) -> dict:
    """The held-out AUC minus each baseline's, per sequence: interval, Wilcoxon p, Holm across
    the baselines; ``significant``: Holm p < 0.05 and the interval above 0."""
    diffs = {name: paired_difference([held_out[n]["auc"] for n in names], [s[n]["auc"] for n in names])
             for name, s in baselines.items()}
    out = {}
    for (name, d), p in zip(diffs.items(), holm([d.wilcoxon_p for d in diffs.values()])):
        out[name] = {**d.as_record(), "holm_p": p, "significant": bool(p < 0.05 and d.ci_low > 0)}
    return out


def summary_lines(summary: dict) -> list[str]:
    """``summary.md``: the folds, the held-out score against each baseline, the final choice."""
    lines = [f"# Search {summary['name']}", "",
             f"{len(summary['sequences'])} sequences, {len(summary['folds'])} folds, "
             f"{summary['trials_per_study']} trials a study; objective: mean AUC over "
             f"{' + '.join(summary['experiments'])} (each sequence's runs pooled).", "",
             "| fold | held out | trial | training AUC | held-out AUC | values |", "|---|---|---|---|---|---|"]
    for f in summary["folds"]:
        lines.append(f"| {f['fold']} | {', '.join(f['held_out'])} | {f['trial']} | {f['training_auc']:.4f} | "
                     f"{f['held_out_auc']:.4f} | {_values(f['params'])} |")
    h = summary["held_out"]["auc"]
    lines += ["", f"Held-out AUC of the search: {h['mean']:.4f} [{h['ci_low']:.4f}, {h['ci_high']:.4f}]", "",
              "| baseline | AUC | search − baseline | 95% CI | won / lost / tied | Wilcoxon p | Holm p | beaten |",
              "|---|---|---|---|---|---|---|---|"]
    for name, c in summary["comparisons"].items():
        b = summary["baselines"][name]["auc"]
        lines.append(f"| {name} | {b['mean']:.4f} | {c['mean']:+.4f} | [{c['ci_low']:+.4f}, {c['ci_high']:+.4f}] | "
                     f"{c['won']} / {c['lost']} / {c['tied']} | {c['wilcoxon_p']:.3f} | {c['holm_p']:.3f} | "
                     f"{'yes' if c['significant'] else 'no'} |")
    final = summary["final"]
    verdict = ("it beats every baseline on held-out folds" if summary["beats_every_baseline"]
               else "it does not beat every baseline on held-out folds: do not ship it")
    lines += ["", f"Final study (every sequence): trial {final['trial']}, AUC {final['auc']:.4f}, "
              f"{_values(final['params'])}; best.yaml. The search: {verdict}.", "", summary["method"] + "; "
              + summary["correction"] + " (beaten: significant and the interval above 0)."]
    return lines


def _values(params: dict) -> str:
    return ", ".join(f"{k}={v:.4g}" if isinstance(v, float) else f"{k}={v}" for k, v in params.items())

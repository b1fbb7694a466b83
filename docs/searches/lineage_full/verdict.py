"""This search's held-out verdict without its final study, computed by the code that recorded it.

The search runs dcfkit 0.16.0, whose ``Search.run`` scores the held-out folds only after the
final study. Main's ``final_study: if_it_wins`` runs the final study only if the folds beat
every baseline; this script does the same for this search: it reads the four complete fold
studies, scores them with the calls of 0.16.0's ``summarize`` up to its final study, and writes
``OUT/summary.json`` with ``"final": null`` (README.md says how summary.md is rendered from
it). Checked on small searches against 0.16.0's own summary: every key equal but ``final``,
and ``halving``, which counts no final study.

    PYTHONPATH=<0.16.0 checkout> python verdict.py SPEC OUT ROOT...   # with the search stopped
"""
import json
import sys
from pathlib import Path

import dcfkit
from dcfkit.ablation.spec_keys import data_record
from dcfkit.analysis.statistics import HOLM, METHOD, mean_interval
from dcfkit.autosearch import Search, load_search_spec
from dcfkit.autosearch import summary as S
from dcfkit.store.files import atomic_write, exclusive
from dcfkit.store.provenance import shared_path


def main() -> None:
    if dcfkit.__version__ != "0.16.0":
        sys.exit(f"dcfkit {dcfkit.__version__}: this search's runs are 0.16.0's; give a 0.16.0 checkout")
    spec_path, out, roots = sys.argv[1], Path(sys.argv[2]), [Path(r) for r in sys.argv[3:]]
    spec = load_search_spec(spec_path, root=roots or None)
    search = Search(spec, out, {"jobs": 2}, report=print)
    with exclusive(search.out / ".lock", "dcfkit search", f"to {search.out}"):
        search.check_record(write=False)
        studies = {s: search.recorded(s)[0] for s in search.studies() if s != S.FINAL}
        short = {s: len(r) for s, r in studies.items() if len(r) != spec.trials}
        if short:
            sys.exit(f"fold studies not complete (trials recorded): {short}")
        ev, held_out, folds = search.evaluator, {}, []
        for i, names in enumerate(search.folds):
            chosen = S.best(studies[f"fold{i + 1}"], f"fold{i + 1}")
            scores = ev.scores(chosen["config"], names)
            held_out.update(scores)
            folds.append({"fold": i + 1, "held_out": names, "trial": chosen["number"], "params": chosen["params"],
                          "training_auc": chosen["value"], "held_out_auc": S.mean_auc(scores, names)})
        baselines = {name: ev.scores(config, search.names, baseline=name) for name, config in spec.baselines.items()}
        comparisons = S._compare(search.names, held_out, baselines)
        summary = {
            "name": spec.name, "spec": shared_path(spec.path, search.out), "dataset": data_record(spec)["dataset"],
            "experiments": list(spec.experiments), "trials_per_study": spec.trials, "max_frames": spec.max_frames,
            "sequences": search.names, "unscored": [n for n in search.names if not S.is_score(held_out[n]["auc"])],
            "folds": folds,
            "held_out": {"auc": mean_interval([held_out[n]["auc"] for n in search.names]).as_record(),
                         "per_sequence": held_out},
            "baselines": {name: {"auc": mean_interval([s[n]["auc"] for n in search.names]).as_record(),
                                 "per_sequence": s} for name, s in baselines.items()},
            "comparisons": comparisons, "method": METHOD, "correction": HOLM,
            "beats_every_baseline": bool(comparisons) and all(c["significant"] for c in comparisons.values()),
            "final_study": "if_it_wins", "final": None, "halving": S._halving(search, studies)}
        atomic_write(search.out / "summary.json", json.dumps(S.finite(summary), indent=1, allow_nan=False) + "\n")
    print("beats every baseline:", summary["beats_every_baseline"])


if __name__ == "__main__":  # the runs' worker processes import this module
    main()

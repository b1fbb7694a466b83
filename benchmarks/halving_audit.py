"""Did successive halving prune a winner? A halved search's most promising pruned trials, run to
the end: each study's ``--top`` pruned trials that went furthest (the highest rung reached,
then the highest mean there) are scored on every unit its rungs skipped, and set against the
study's best (docs/search.md, "Successive halving").

    python benchmarks/halving_audit.py SPEC OUT [--root DIR ...] [--top 2] [--jobs 2]

SPEC and ``--root`` are those the search ran with (a search of other options, data or box
code is refused, as a resume would be); OUT is its ``--out``. The runs made go to
``OUT/runs/`` like a trial's (a resumed search reuses them, and they change no record). Where
no plain search of the same seed exists (benchmarks/halving.py replays one), this measures the
pruner's worst misses at the cost of ``--top`` trials a study.
"""
import argparse
import sys
from pathlib import Path

from dcfkit.autosearch import Search, load_search_spec
from dcfkit.autosearch.summary import best as summary_best
from dcfkit.autosearch.summary import finite, is_score, mean_auc


def audit(search: Search, top: int) -> list[dict]:
    """Per study, its ``top`` furthest pruned trials completed, against the study's best (the
    records that stand, as a resume reads them)."""
    search.check_record(write=False)  # the recorded search, with the options and code it ran with
    rows = []
    for study in search.studies():
        recs = search.recorded(study, running=False)[0]  # the audit completes trials, never reruns one
        scored = [r for r in recs if is_score(r["value"])]
        if not scored:  # a study not yet begun, or none of its trials complete
            continue
        best = summary_best(scored, study)
        pruned = sorted((r for r in recs if r.get("pruned") and is_score(r["steps"][-1][1])),
                        key=lambda r: (r["steps"][-1][0], r["steps"][-1][1]), reverse=True)[:top]
        names = search.training(study)
        for rec in pruned:
            full = mean_auc(finite(search.evaluator.scores(rec["config"], names)), names)
            rows.append({"study": study, "trial": rec["number"], "reached": rec["steps"][-1][0],
                         "units": len(search.units(study)), "at_rung": rec["steps"][-1][1], "full": full,
                         "best": best["number"], "best_auc": best["value"],
                         "missed": is_score(full) and full > best["value"]})
    return rows


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("spec", help="the halved search's spec")
    parser.add_argument("out", type=Path, help="the halved search's --out")
    parser.add_argument("--root", action="append", type=Path, default=None)
    parser.add_argument("--top", type=int, default=2, help="pruned trials to complete per study (default 2)")
    parser.add_argument("--jobs", type=int, default=1)
    args = parser.parse_args()
    spec = load_search_spec(args.spec, root=args.root)
    if spec.halving is None:
        parser.error(f"{args.spec} has no halving: nothing was pruned")
    rows = audit(Search(spec, args.out, {"jobs": args.jobs}), args.top)
    print("| study | pruned trial | reached (units) | mean AUC there | completed AUC | study's best (trial, AUC) "
          "| a winner pruned? |")
    print("|---|---|---|---|---|---|---|")
    for r in rows:
        full = "n/a" if r["full"] is None else f"{r['full']:.4f}"
        print(f"| {r['study']} | {r['trial']} | {r['reached']} of {r['units']} | {r['at_rung']:.4f} | {full} "
              f"| {r['best']}, {r['best_auc']:.4f} | {'yes' if r['missed'] else 'no'} |")
    print(f"\n{sum(r['missed'] for r in rows)} of {len(rows)} completed pruned trials beat their study's best")
    return 0


if __name__ == "__main__":
    sys.exit(main())

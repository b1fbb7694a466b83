"""What successive halving spares a search, and what it costs (docs/search.md, "Successive
halving"): a plain search's trials replayed through the pruner, and a halved search of the same
seed against the plain one.

    python benchmarks/halving.py SPEC PLAIN_OUT [--root DIR ...] [--settings 4x2,4x3]
        [--in-turn] [--halved HALVED_OUT]

SPEC and ``--root`` are those the plain search ran with (``halving`` in SPEC is ignored).

- **Replayed** (each ``--settings`` MINxETA): every study's trials, in their order, go up the
  rungs of ``halving: {min_sequences: MIN, reduction_factor: ETA}`` with the scores the plain
  search recorded (``--in-turn``: ``experiments: in_turn``, each trial's scores per experiment
  read from the plain search's runs, which are all on disk). Printed per study: the trials
  pruned, the share of the frames tracked (every experiment's runs),
  whether the plain study's best was pruned, and the best left against it (its mean AUC on the
  study's sequences). TPE would have been told other trials after the first pruned one, so this
  measures the pruner on the plain search's trials, not a halved search.
- **Run** (``--halved``): a search of SPEC with ``halving``, same seed, its own records: its
  best against the plain best, the frames it tracked, whether it pruned the plain best's config
  when it sampled it.
"""
import argparse
import dataclasses
import json
import sys
from pathlib import Path

from dcfkit.autosearch import Search, load_search_spec
from dcfkit.autosearch.halving import Halving, Ladder
from dcfkit.autosearch.summary import best as summary_best
from dcfkit.autosearch.summary import is_score, mean_score


def records(out: Path, study: str) -> list[dict]:
    return [json.loads(p.read_text(encoding="utf-8")) for p in sorted((out / "trials" / study).glob("*.json"))]


def best(recs: list[dict]) -> dict | None:
    """The search's own choice of a study's best (:func:`dcfkit.autosearch.summary.best`), or
    None where no trial has a score."""
    return summary_best(recs, "") if any(is_score(r["value"]) for r in recs) else None


def replayed(search: Search, plain: Path, halving: Halving) -> list[dict]:
    """Each study's plain trials through ``halving``'s pruner: what it prunes, and what is left."""
    rows = []
    for study in search.studies():
        units = halving.units(search.order(study), search.spec.experiments)
        recs = records(plain, study)
        if not recs:  # a study not yet begun
            continue
        ladder = Ladder(halving, len(units))
        reached = []
        for rec in recs:
            aucs = unit_aucs(search, rec, units)
            steps, pruned = ladder.climb(lambda start, stop, a=aucs: mean_score(a[:stop]))
            reached.append((rec, pruned, steps[-1][0]))
        top = best(recs) or {"number": None, "value": None}
        left = best([rec for rec, pruned, _ in reached if not pruned]) or {"number": None, "value": None}
        tracked = sum(search.evaluator.frames(units[:count]) for _, _, count in reached)
        rows.append({"study": study, "trials": len(recs), "pruned": sum(p for _, p, _ in reached),
                     "frames": tracked / (len(recs) * search.evaluator.frames(units)),
                     "best": top["number"], "best_auc": top["value"],
                     "best_pruned": next((p for rec, p, _ in reached if rec is top), "none scored"),
                     "left": left["number"], "left_auc": left["value"]})
    return rows


def unit_aucs(search: Search, rec: dict, units: list) -> list:
    """A plain trial's AUC on each unit: its recorded scores, or (a unit under one of several
    experiments) its score under that experiment, from the plain search's runs."""
    if all(len(exps) == len(search.spec.experiments) for exps, _ in units):
        return [rec["scores"][name]["auc"] for _, name in units]
    if rec["key"] != search.evaluator.key(rec["config"]):  # its runs would be tracked again, by this code
        sys.exit(f"{search.out}: trial {rec['number']} was run by other code or another dcfkit version (its run "
                 f"key differs): replay in turn with the dcfkit that ran the search")
    found = search.evaluator.experiment_scores(rec["config"], list(rec["scores"]), search.spec.experiments)
    return [found[exps[0]][name]["auc"] for exps, name in units]


def run(search: Search, plain: Path, halved: Path, halving: Halving) -> list[dict]:
    """A halved search's studies against the plain search's."""
    rows = []
    for study in search.studies():
        units = halving.units(search.order(study), search.spec.experiments)
        mine, theirs = records(halved, study), records(plain, study)
        if not (mine and theirs):  # a study not yet begun
            continue
        top = best(theirs) or {"number": None, "value": None, "params": None}
        found = best(mine) or {"number": None, "value": None}
        same = [r for r in mine if r["params"] == top["params"]]
        tracked = sum(search.evaluator.frames(units[:r["steps"][-1][0]]) for r in mine)
        rows.append({"study": study, "trials": len(mine), "pruned": sum(bool(r.get("pruned")) for r in mine),
                     "frames": tracked / (len(mine) * search.evaluator.frames(units)),
                     "best": top["number"], "best_auc": top["value"],
                     "best_pruned": ("not sampled" if not same else "pruned" if same[0].get("pruned") else "kept"),
                     "left": found["number"], "left_auc": found["value"]})
    return rows


def cell(number, auc) -> str:
    return "none" if auc is None else f"{number}, {auc:.4f}"


def table(title: str, rows: list[dict]) -> None:
    print(f"\n{title}\n")
    print("| study | trials | pruned | frames tracked | plain best (trial, AUC) | it pruned? | best left (trial, AUC) "
          "| left − plain best |")
    print("|---|---|---|---|---|---|---|---|")
    for r in rows:
        pruned = r["best_pruned"] if isinstance(r["best_pruned"], str) else ("yes" if r["best_pruned"] else "no")
        gap = "n/a" if None in (r["left_auc"], r["best_auc"]) else f"{r['left_auc'] - r['best_auc']:+.4f}"
        print(f"| {r['study']} | {r['trials']} | {r['pruned']} | {r['frames']:.0%} | {cell(r['best'], r['best_auc'])} "
              f"| {pruned} | {cell(r['left'], r['left_auc'])} | {gap} |")
    share = sum(r["frames"] * r["trials"] for r in rows) / sum(r["trials"] for r in rows)
    print(f"\nall studies: {sum(r['pruned'] for r in rows)} of {sum(r['trials'] for r in rows)} trials pruned, "
          f"{share:.0%} of the frames (trial-weighted)")


def setting(text: str) -> Halving:
    """``MINxETA`` as a halving: MIN >= 1 sequences, reduction factor ETA >= 2."""
    try:
        first, eta = (int(v) for v in text.lower().split("x"))
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected MINxETA such as 4x2, got {text!r}") from None
    if first < 1 or eta < 2:
        raise argparse.ArgumentTypeError(f"{text!r}: MIN must be >= 1 and ETA >= 2")
    return Halving(first, eta)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("spec", help="the plain search's spec")
    parser.add_argument("plain", type=Path, help="the plain search's --out")
    parser.add_argument("--root", action="append", type=Path, default=None)
    parser.add_argument("--settings", default=[Halving(4, 2)], type=lambda text: [setting(t) for t in text.split(",")],
                        help="halving settings to replay, MINxETA, comma-separated (default 4x2)")
    parser.add_argument("--in-turn", action="store_true", help="replay with experiments: in_turn")
    parser.add_argument("--halved", type=Path, default=None, help="a halved search's --out, same seed")
    args = parser.parse_args()
    spec = dataclasses.replace(load_search_spec(args.spec, root=args.root), halving=None)
    search = Search(spec, args.plain, {"jobs": 1})
    mode = "in_turn" if args.in_turn else "together"
    for halving in (dataclasses.replace(h, experiments=mode) for h in args.settings):
        table(f"Replayed: the plain trials through halving {{min_sequences: {halving.min_sequences}, "
              f"reduction_factor: {halving.reduction_factor}, experiments: {mode}}}",
              replayed(search, args.plain, halving))
    if args.halved is not None:
        recorded = json.loads((args.halved / "search.json").read_text(encoding="utf-8"))["fingerprint"]["halving"]
        if not recorded:
            parser.error(f"{args.halved} is a search without halving")
        halving = Halving(**recorded)  # dcfkit 0.15.0's records have no experiments: together
        table(f"Run: {args.halved} against {args.plain}", run(search, args.plain, args.halved, halving))
    return 0


if __name__ == "__main__":
    sys.exit(main())

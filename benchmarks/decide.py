"""Options decided by evidence: each option of an ablation against its base, paired per sequence.

    python benchmarks/decide.py results/recovery/per_sequence.csv [results/recovery_tre/per_sequence.csv]
        [--margin 0.01]

Reads the ``per_sequence.csv`` of ``dcfkit ablate`` runs (one per experiment) and pairs every
variant named ``BASE + OPTION`` with the variant ``BASE`` on the sequences both scored. For each
option: the mean AUC difference with its 95% BCa interval, won / lost / tied, the two-sided
Wilcoxon p and its Holm correction across the options of one base in one experiment. The rule
of docs/results.md ("Defaults decided by evidence"): an option is adopted when its interval lies
above 0 and its corrected p is below 0.05, in every experiment given. With ``--margin δ``, the
non-inferiority rule for an option that only buys speed: adopted when its interval's lower
bound lies above -δ in every experiment given. Prints a Markdown table.
"""
import argparse
import csv
import sys
from collections import defaultdict
from pathlib import Path

from dcfkit.analysis.statistics import holm, paired_difference

SEPARATOR = " + "


def read_scores(path: Path, metric: str) -> dict[str, dict[str, float]]:
    """``{variant: {sequence: score}}`` of the runs a ``per_sequence.csv`` lists as done."""
    scores: dict[str, dict[str, float]] = defaultdict(dict)
    with open(path, newline="", encoding="utf-8") as f:
        for row in csv.DictReader(f):
            if row.get("status", "done") == "done":
                scores[row["variant"]][row["sequence"]] = float(row[metric])
    return dict(scores)


def decide(scores: dict[str, dict[str, float]], margin: float | None = None) -> list[dict]:
    """One row per ``BASE + OPTION`` variant whose ``BASE`` was run: the paired difference, its
    Holm-corrected p (across the base's options) and whether it passes the rule (with a
    ``margin`` δ, the non-inferiority rule: the interval's lower bound above -δ)."""
    rows = []
    for name, per_sequence in scores.items():
        base = name.split(SEPARATOR)[0]
        if SEPARATOR not in name or base not in scores:
            continue
        common = sorted(set(per_sequence) & set(scores[base]))
        d = paired_difference([per_sequence[s] for s in common], [scores[base][s] for s in common])
        rows.append({"base": base, "option": name[len(base) + len(SEPARATOR):], "difference": d})
    for base in {r["base"] for r in rows}:
        mine = [r for r in rows if r["base"] == base]
        for r, p in zip(mine, holm([r["difference"].wilcoxon_p for r in mine])):
            r["holm"] = p
            if margin is None:
                r["passes"] = r["difference"].ci_low > 0 and p < 0.05
            else:
                r["passes"] = r["difference"].ci_low > -margin
    return rows


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("csv", nargs="+", type=Path, help="per_sequence.csv of dcfkit ablate, one per experiment")
    parser.add_argument("--metric", default="auc", help="the column compared (default: auc)")
    parser.add_argument("--margin", type=float, help="δ of the non-inferiority rule, for options that only buy "
                        "speed (docs/results.md: 0.01 AUC)")
    args = parser.parse_args(argv)
    if args.margin is not None and not args.margin > 0:
        parser.error(f"--margin: expected a positive δ, got {args.margin}")
    verdict: dict[tuple[str, str], bool] = {}
    print("| experiment | base | option | Δ [95% CI] | won / lost / tied | Wilcoxon p | Holm p |")
    print("|---|---|---|---|---|---|---|")
    for path in args.csv:
        for r in decide(read_scores(path, args.metric), args.margin):
            d = r["difference"]
            print(f"| {path.parent.name} | {r['base']} | {r['option']} | {d.mean:+.3f} [{d.ci_low:+.3f}, "
                  f"{d.ci_high:+.3f}] | {d.won} / {d.lost} / {d.tied} | {d.wilcoxon_p:.2g} | {r['holm']:.2g} |")
            key = (r["base"], r["option"])
            verdict[key] = verdict.get(key, True) and bool(r["passes"])
    print()
    for (base, option), passes in sorted(verdict.items()):
        rule = "" if args.margin is None else f" (non-inferiority, δ {args.margin:g})"
        print(f"- {base} + {option}: {'adopt' if passes else 'the base stands'}{rule}")
    return 0


if __name__ == "__main__":
    sys.exit(main())

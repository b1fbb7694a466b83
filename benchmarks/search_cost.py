"""What a search's trials cost and where: frames tracked, core-hours of tracking and fps, in
all and for each choice of the search space, from the per-frame times its runs stored.

    python benchmarks/search_cost.py OUT

OUT is the search's ``--out``. A config's runs (``OUT/runs/<run key>/``) are counted once
however many trials share them, and a run stored as the copy of another (TRE's run from frame 1
is the one-pass run's: the same per-frame times) is counted once. The held-out scoring of a
fold's choice and ``benchmarks/halving_audit.py`` store their runs there too; baselines'
(``OUT/baselines/``) are left out. The times are tracking alone, decoding excluded, measured
while the search's other jobs shared the machine: they say where the cost goes, not the wall
time. A dimension whose values are real numbers is not split into choices.
"""
import argparse
import collections
import hashlib
import json
import sys
from pathlib import Path

import numpy as np

from dcfkit.store.results import TIME_END

INACTIVE = "(inactive)"  # a conditional dimension its trial did not sample


def tally(folder: Path) -> tuple[int, float]:
    """(frames, seconds) of the runs under ``folder``, a run whose times equal another's once."""
    frames, seconds, seen = 0, 0.0, set()
    for path in sorted(folder.rglob(f"*{TIME_END}")):
        try:
            data = path.read_bytes()
        except FileNotFoundError:  # a running search replaced it (a failure, a copy) since the listing
            continue
        except OSError as exc:
            sys.exit(f"{path}: cannot be read ({exc})")
        digest = hashlib.sha256(data).digest()
        if digest in seen:
            continue
        seen.add(digest)
        try:
            times = np.array(data.split(), dtype=float)
        except ValueError:
            sys.exit(f"{path}: not a run's per-frame times (one number a line)")
        frames, seconds = frames + times.size, seconds + float(times.sum())
    return frames, seconds


def trial_params(out: Path) -> dict[str, dict]:
    """Run key -> the params its trials sampled (every study's records)."""
    params = {}
    for path in sorted((out / "trials").glob("*/*.json")):
        try:
            record = json.loads(path.read_text(encoding="utf-8"))
        except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
            sys.exit(f"{path}: not a trial record ({exc})")
        if isinstance(record, dict) and isinstance(record.get("key"), str):
            params[record["key"]] = record.get("params") or {}
    return params


def choices(params: dict[str, dict]) -> list[str]:
    """The dimensions to split by: those whose sampled values are labels or whole numbers."""
    values = collections.defaultdict(set)
    for p in params.values():
        for name, value in p.items():
            values[name].add(type(value))
    return [name for name, kinds in values.items() if kinds <= {str, int, bool}]


def fps(frames: int, seconds: float) -> str:
    return f"{frames / seconds:.1f}" if seconds > 0 else "n/a"


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("out", type=Path, help="the search's --out")
    args = parser.parse_args()
    runs = args.out / "runs"
    if not (args.out / "trials").is_dir() or not runs.is_dir():
        parser.error(f"{args.out}: not a search's --out (no trials/ and runs/ in it)")
    params = trial_params(args.out)
    folders = [folder for folder in sorted(runs.iterdir()) if folder.is_dir()]
    others = [folder.name for folder in folders if folder.name not in params]  # a trial still running, say
    counted = {folder.name: tally(folder) for folder in folders if folder.name in params}
    frames, seconds = (sum(c[i] for c in counted.values()) for i in (0, 1))
    print(f"{args.out}: {len(counted)} configs' runs: {frames:,} frames tracked in {seconds / 3600:.2f} core-hours "
          f"of tracking, {fps(frames, seconds)} fps")
    if others:
        print(f"left out: {len(others)} folder(s) under runs/ that no trial record names ({', '.join(others[:3])}"
              f"{', ...' if len(others) > 3 else ''})")
    print("\n| dimension | choice | configs | frames | core-hours | share of the hours | fps |")
    print("|---|---|---|---|---|---|---|")
    for name in choices(params):
        groups = collections.defaultdict(lambda: [0, 0, 0.0])
        for key, (n, s) in counted.items():
            group = groups[str(params[key].get(name, INACTIVE))]
            group[0], group[1], group[2] = group[0] + 1, group[1] + n, group[2] + s
        for choice, (configs, n, s) in sorted(groups.items(), key=lambda kv: -kv[1][2]):
            share = f"{100 * s / seconds:.0f}%" if seconds > 0 else "n/a"
            print(f"| {name} | {choice} | {configs} | {n:,} | {s / 3600:.2f} | {share} | {fps(n, s)} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())

"""``dcfkit search``: run a search spec (docs/search.md) and print its summary."""
from __future__ import annotations

import argparse
import dataclasses
import sys
from pathlib import Path

from dcfkit.cli.common import add_protocol_argument, executor_choice, frame_limit
from dcfkit.config import shipped_config_dir
from dcfkit.datasets.base import sequence_names
from dcfkit.errors import DcfkitError
from dcfkit.running.runner import usable_cores


def add_arguments(parser: argparse.ArgumentParser) -> None:
    shipped = sorted(p.stem for p in (shipped_config_dir() / "searches").glob("*.yaml"))
    parser.add_argument("spec", metavar="SPEC",
                        help=f"search spec YAML, or a shipped one by name ({', '.join(shipped)})")
    parser.add_argument("--out", required=True, type=Path,
                        help="search folder (OUT/trials/..., OUT/baselines/..., OUT/summary.md, OUT/best.yaml); "
                             "reruns resume, with more --trials if given")
    parser.add_argument("--root", type=Path, action="append", default=None,
                        help="benchmark root folder (default: the spec's dataset.root, relative to the spec); "
                             "repeat it to pool several: one per dataset the spec lists, or any for one")
    parser.add_argument("--trials", type=int, default=None,
                        help="trials per study (default: the spec's 'trials'); a rerun with more adds trials")
    parser.add_argument("--experiments", default=None, metavar="LIST",
                        help="the objective's experiments, comma-separated, e.g. ope (default: the spec's "
                             "'experiments'); recorded, so a rerun must give the same")
    parser.add_argument("--jobs", type=int, default=None,
                        help="worker processes for each trial's runs (default: the usable cores); with "
                             "--scheduler, the fewest worker threads to plan them for")
    parser.add_argument("--executor", choices=("local", "dask"), default=None,
                        help="local process pool (default) or dask.distributed (default with --scheduler)")
    parser.add_argument("--scheduler", default=None, metavar="ADDR",
                        help="dask scheduler address (default: a LocalCluster)")
    parser.add_argument("--sequences", default=None, metavar="LIST",
                        help="comma-separated sequence names (default: the spec's 'sequences', else all); "
                             "recorded, so a rerun must give the same")
    parser.add_argument("--max-frames", type=frame_limit, default=None, metavar="N",
                        help="a quick try: each sequence's first N frames only (its runs are of the cut sequences, "
                             "never taken for full ones); recorded, so a rerun must give the same")
    parser.add_argument("--final-study", choices=("always", "if_it_wins"), default=None,
                        help="run the final study always, or only if the folds beat every baseline held out "
                             "(default: the spec's 'final_study', else always); the trials do not depend on it")
    add_protocol_argument(parser)
    parser.add_argument("--status", action="store_true",
                        help="run nothing: say where the search recorded under --out stands (trials per study, "
                             "pruned, the best so far), with the options it runs with")


def run(args: argparse.Namespace) -> int:
    """Run every study not yet recorded under --out, then print summary.md."""
    try:
        import optuna  # noqa: F401  (lazy: Optuna is an extra, dcfkit[search])
    except ImportError:
        raise DcfkitError("dcfkit search needs Optuna: pip install 'dcfkit[search]'") from None
    from dcfkit.autosearch import Search, load_search_spec  # lazy: it imports Optuna
    from dcfkit.autosearch.space import check_experiments  # lazy: as dcfkit.autosearch
    from dcfkit.autosearch.summary import summary_lines  # lazy: as dcfkit.autosearch

    executor = executor_choice(args)
    jobs = args.jobs if args.jobs is not None else usable_cores()
    if jobs < 1:
        raise DcfkitError(f"--jobs must be >= 1, got {jobs}")
    spec = load_search_spec(args.spec, root=args.root)
    if args.trials is not None:
        if args.trials < 1:
            raise DcfkitError(f"--trials must be >= 1, got {args.trials}")
        spec = dataclasses.replace(spec, trials=args.trials)
    if args.sequences is not None:
        spec = dataclasses.replace(spec, sequences=tuple(sequence_names(args.sequences, "--sequences")))
    spec = dataclasses.replace(spec, max_frames=args.max_frames)
    if args.final_study is not None:
        spec = dataclasses.replace(spec, final_study=args.final_study)
    if args.experiments is not None:
        names = [e.strip() for e in args.experiments.split(",") if e.strip()]
        if not names:
            raise DcfkitError(f"--experiments: expected names such as ope,tre, got {args.experiments!r}")
        spec = dataclasses.replace(spec, experiments=check_experiments(names, "--experiments"))
    search = Search(spec, args.out, {"protocol": args.protocol, "jobs": jobs, "executor": executor,
                                     "scheduler": args.scheduler},
                    report=lambda line: print(line, file=sys.stderr, flush=True))
    if args.status:
        print("\n".join(search.status()))
        return 0
    summary = search.run()
    print("\n".join(summary_lines(summary)))
    return 0

"""``dcfkit ablate``: run an ablation spec and print its summary table."""
from __future__ import annotations

import argparse
import dataclasses
import re
from pathlib import Path

from dcfkit.ablation import expand, load_spec, run_ablation, summary_columns, variant_names
from dcfkit.ablation.experiment import ablation_experiments
from dcfkit.ablation.run import ablation_plan
from dcfkit.ablation.spec import MAX_VARIANTS
from dcfkit.analysis.tables import format_table, statistics_lines
from dcfkit.cli.common import add_max_frames_argument, add_protocol_argument, executor_choice, variant_count
from dcfkit.config import shipped_config_dir


def add_arguments(parser: argparse.ArgumentParser) -> None:
    shipped = sorted(p.stem for p in (shipped_config_dir() / "ablations").glob("*.yaml")  # the others: configs
                     if re.search(r"^(variants|grid):", p.read_text(encoding="utf-8"), re.MULTILINE))
    parser.add_argument("spec", metavar="SPEC",
                        help=f"ablation spec YAML, or a shipped one by name ({', '.join(shipped)})")
    parser.add_argument("--out", required=True, type=Path,
                        help="results folder (OUT/<variant>/..., OUT/summary.md, ...); reruns resume")
    parser.add_argument("--jobs", type=int, default=None,
                        help="worker processes (default: the usable cores); with dask, the LocalCluster's "
                             "workers, or with --scheduler the fewest worker threads to plan the runs for")
    parser.add_argument("--executor", choices=("local", "dask"), default=None,
                        help="local process pool (default) or dask.distributed (default with --scheduler)")
    parser.add_argument("--scheduler", default=None, metavar="ADDR",
                        help="dask scheduler address, e.g. tcp://10.0.0.5:8786 (default: a LocalCluster)")
    parser.add_argument("--root", type=Path, action="append", default=None,
                        help="benchmark root folder (default: the spec's dataset.root, relative to the spec); "
                             "repeat it to pool several: one per dataset the spec lists, or any for one")
    parser.add_argument("--sequences", default=None,
                        help="comma-separated sequence names (default: the spec's, else all)")
    parser.add_argument("--max-variants", type=variant_count, default=None, metavar="N",
                        help="the most variants (named ones and grid points) the spec may have (default: "
                             f"$DCFKIT_MAX_VARIANTS, else {MAX_VARIANTS}); each is resolved when the spec is read")
    add_protocol_argument(parser)
    parser.add_argument("--dry-run", action="store_true",
                        help="list the jobs and whether each is done; run nothing")
    parser.add_argument("--no-progress", action="store_true", help="no progress bar")
    add_max_frames_argument(parser)
    parser.add_argument("--experiment", choices=ablation_experiments(), default=None,
                        help="the runs of each sequence (default: the spec's 'experiment', else ope); tre and sre "
                             "pool each sequence's 20 or 12 runs (docs/evaluation.md, 'Experiments')")


def _dry_run(spec, out: Path) -> int:
    """Each job, done or to do in its variant's folder; reads only."""
    seqs = spec.load_sequences()
    plan = ablation_plan(spec, out, seqs).read()
    runs, experiment = plan.by_sequence, plan.experiment
    todo = {p.name: {run.name for run in p.todo} for p in plan.entries}
    folders = dict(zip((v.name for v in spec.variants), (p.name for p in plan.entries)))
    jobs = expand(spec, seqs)
    for job in jobs:
        done = sum(run.name not in todo[folders[job.variant]] for run in runs[job.sequence])
        state = "done" if done == len(runs[job.sequence]) else "todo"
        count = f" ({done} of {len(runs[job.sequence])} {spec.experiment} runs done)" if experiment.folder else ""
        print(f"{state}  {job.key}  {job.variant}  {job.sequence}{count}")
    print(f"{len(jobs)} jobs, {len({(j.key, j.sequence) for j in jobs})} distinct runs"
          + (f" ({spec.experiment}: {sum(len(r) for r in runs.values())} runs of {len(seqs)} sequences per variant)"
             if experiment.folder else ""))
    return 0


def run(args: argparse.Namespace) -> int:
    """Run a spec, print the summary table; exit status 1 if a job failed."""
    executor = executor_choice(args)
    spec = load_spec(args.spec, root=args.root, sequences=args.sequences, max_variants=args.max_variants)
    spec = dataclasses.replace(spec, max_frames=args.max_frames, experiment=args.experiment or spec.experiment)
    if args.dry_run:
        return _dry_run(spec, args.out.expanduser().resolve())
    res = run_ablation(spec, args.out, jobs=args.jobs, executor=executor, scheduler=args.scheduler,
                       progress=not args.no_progress, protocol=args.protocol)
    summary = res["summary"]
    protocol = summary["protocol"]  # --protocol, else the benchmark's own
    print(f"{spec.name}: {summary['scope']}")
    print(format_table(summary["overall"], "markdown", summary_columns("summary", protocol), protocol), end="")
    if summary["fps_note"]:
        print(f"\n{summary['fps_note']}")
    print("\n" + "\n".join(statistics_lines(summary["statistics"])))
    print(f"\n{spec.name}: {len(res['jobs'])} jobs ({res['runs']} distinct runs): {len(res['done'])} run, "
          f"{len(res['skipped'])} already done, {len(res['failed'])} failed -> {Path(args.out)}")
    variants = variant_names(res["jobs"])
    for (key, seq), message in res["failed"].items():
        print(f"  FAILED {', '.join(variants.get(key, []))} [{key}] {message}")
    print(f"open {Path(args.out) / 'report.html'}")
    return 1 if res["failed"] else 0

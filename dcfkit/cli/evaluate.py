"""``dcfkit eval`` (one-pass evaluation), ``report`` (tables and plots) and ``compare``
(two result folders side by side)."""
from __future__ import annotations

import argparse
import functools
import json
import os
import sys
from pathlib import Path
from typing import Any, Callable, Mapping

from dcfkit.analysis.compare import COLUMNS, compare_folders, counted_lines
from dcfkit.analysis.longterm_report import long_term_lines, long_term_output, score_long_term
from dcfkit.analysis.report import json_ready, named_folder, score_and_write
from dcfkit.analysis.report_html import write_html_report
from dcfkit.analysis.reset_report import reset_latex, reset_runs, reset_table, write_reset_report
from dcfkit.analysis.reset_scores import score_resets
from dcfkit.analysis.scoring import MISSING, evaluate
from dcfkit.analysis.tables import (
    columns,
    comparison_lines,
    format_table,
    noise_floor_line,
    score_line,
    statistics_lines,
)
from dcfkit.cli.common import (
    add_dataset_arguments,
    add_experiment_argument,
    add_max_frames_argument,
    add_protocol_argument,
    check_protocol,
    pixels,
)
from dcfkit.config import load_config
from dcfkit.config.overrides import parse_overrides
from dcfkit.datasets import benchmark_protocol, load_datasets, scored_sequences
from dcfkit.errors import ConfigError, printable, shown
from dcfkit.experiments import EXPERIMENTS, Experiment, get_experiment, runs_by_sequence
from dcfkit.integrations.opencv import opencv_tracker
from dcfkit.running.evaluation import check_one_pass, results_folder, run_one_pass, tracker_name
from dcfkit.store.results import load_results


def add_eval_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("configs", nargs="+", metavar="CONFIG",
                        help="tracker config YAML file(s) or shipped config names (strcf, bacf, dr2track, kcf, dsst); "
                             "'opencv:CSRT', 'opencv:KCF' or 'opencv:MOSSE' runs an OpenCV baseline")
    add_dataset_arguments(parser)
    parser.add_argument("--out", required=True, type=Path, help="results folder (OUT/<tracker>/)")
    parser.add_argument("--jobs", type=int, default=1, help="worker processes (default 1)")
    parser.add_argument("--set", dest="overrides", action="append", default=[], metavar="KEY=VALUE",
                        help="override a config value (repeatable), e.g. --set solver.iterations=3")
    parser.add_argument("--no-progress", action="store_true", help="no progress bar")
    add_max_frames_argument(parser)
    add_protocol_argument(parser, reset=True)
    add_experiment_argument(parser)


def _resolve_config(spec: str, overrides: Mapping[str, Any]) -> tuple[dict, Callable | None]:
    """(config, make_tracker) for a CONFIG argument of ``dcfkit eval``."""
    if spec.lower().startswith("opencv:"):
        factory = opencv_tracker(spec.split(":", 1)[1])
        return {"name": f"opencv-{factory.name.lower()}", "opencv": factory.name, **overrides}, factory
    return dict(load_config(spec, overrides)), None


def distinct_names(specs: list[str], resolved: list[tuple[dict, Callable | None]]
                   ) -> list[tuple[dict, Callable | None]]:
    """All configs checked before any runs: a config given twice runs once; two different
    configs with the same name (one output folder) are a :class:`ConfigError`."""
    seen: dict[str, tuple[str, dict]] = {}
    out = []
    for spec, (config, factory) in zip(specs, resolved):
        name = tracker_name(config)
        if name not in seen:
            seen[name] = (spec, config)
            out.append((config, factory))
        elif seen[name][1] != config:
            raise ConfigError(
                f"configs {shown(seen[name][0])} and {shown(spec)} are both named {shown(name)} and would write to the "
                f"same results folder; give one of them another 'name:' (--set name=... renames every CONFIG)")
    return out


def run_eval(args: argparse.Namespace) -> int:
    """Run each config on the dataset and print its scores; exit status 1 if a sequence failed."""
    experiment = check_protocol(args)
    sequences = [s.head(args.max_frames) for s in load_datasets(args.dataset, args.root, args.sequences)]
    if args.protocol is None and experiment.scoring == "otb":  # pooled benchmarks of different rules: refused
        benchmark_protocol(sequences)
    overrides = parse_overrides(args.overrides)
    resolved = distinct_names(args.configs, [_resolve_config(spec, overrides) for spec in args.configs])
    for config, _ in resolved:  # every config's folder and results checked before the first runs
        check_one_pass(config, sequences, args.out, experiment)
    status = 0
    for config, factory in resolved:
        summary = run_one_pass(config, sequences, args.out, make_tracker=factory,
                               jobs=args.jobs, progress=not args.no_progress, experiment=experiment)
        print(f"{summary['tracker']}: {len(summary['done'])} run, {len(summary['skipped'])} "
              f"already done, {len(summary['failed'])} failed -> {summary['dir']}")
        print(f"  {_scores(args, experiment, summary['tracker'], sequences)}")
        for message in summary["failed"].values():
            print(f"  FAILED {message}")
        status = status or (1 if summary["failed"] else 0)
    return status


def _scores(args: argparse.Namespace, experiment: Experiment, tracker: str, sequences: list) -> str:
    """The score line of one tracker's results, or why there is none (a test split)."""
    if all(s.ground_truth_withheld for s in sequences):
        return (f"no scores: the ground truth of these {len(sequences)} sequences is withheld after frame 1 "
                f"(a test split); submit {Path(args.out) / tracker}/<sequence>.txt to the benchmark's server "
                f"(docs/evaluation.md, 'Test splits')")
    folder = results_folder(args.out, {"name": tracker}, experiment)
    return SCORE_LINES[experiment.scoring](args, experiment, tracker, folder, scored_sequences(sequences))


def _otb_score_line(args: argparse.Namespace, experiment: Experiment, tracker: str, folder: Path,
                    sequences: list) -> str:
    by_sequence = runs_by_sequence(sequences, experiment)
    runs = [run for found in by_sequence.values() for run in found]
    scores = evaluate({tracker: load_results(folder.parent, folder.name, runs)}, sequences, protocol=args.protocol,
                      experiment=experiment, runs=by_sequence)
    line = score_line(scores.overall[0], scores.protocol.name)
    return f"{line}, {experiment.name.upper()} runs pooled per sequence" if experiment.pooled else line


def _reset_score_line(args: argparse.Namespace, experiment: Experiment, tracker: str, folder: Path,
                      sequences: list) -> str:
    row = score_resets({tracker: reset_runs(folder, sequences)}, {s.name: len(s) for s in sequences})["overall"][0]
    return (f"EAO {row['eao']:.3f}, accuracy {row['accuracy']:.3f}, {row['failures']} failures on "
            f"{row['sequences']} sequences (reset-based, {experiment.rules[experiment.rule].title})")


SCORE_LINES = {"otb": _otb_score_line, "reset": _reset_score_line}  # by Experiment.scoring


def add_report_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("out", type=Path, metavar="OUT", help="results folder of `dcfkit eval`")
    add_dataset_arguments(parser)
    parser.add_argument("--trackers", default=None,
                        help="comma-separated tracker folders (names in OUT or paths; default: all)")
    parser.add_argument("--baseline", default=None, metavar="TRACKER",
                        help="the tracker whose paired differences (Δ, CI, Wilcoxon p, won/tied/lost) every other "
                             "is compared by, e.g. the one a new component extends (default: the best)")
    parser.add_argument("--format", choices=("table", "markdown", "csv", "latex"), default="table",
                        help="format of the table printed to stdout, the long-term table after it (csv: on stderr, "
                             "so that stdout stays one table); every format names the experiment, the protocol "
                             "and a --max-frames cut (latex: a booktabs table a paper can take: each tracker's "
                             "scores with confidence intervals, its difference from the --baseline (default: the best) with "
                             "its interval, "
                             "Wilcoxon p and sequences won/tied/lost)")
    parser.add_argument("--report-dir", type=Path, default=None,
                        help="default: OUT_report beside OUT (OUT_report/<experiment> but for ope): out of the folder "
                             "whose sub-folders are trackers")
    parser.add_argument("--html", action="store_true",
                        help="also write report.html: one self-contained page with sortable tables, interactive "
                             "plots, each sequence's frames with every tracker's box, and the provenance (ope, tre, "
                             "sre)")
    add_protocol_argument(parser, reset=True)
    parser.add_argument("--skip-first", action="store_true",
                        help="do not score frame 1 (default: as the protocol; otb scores it with the ground "
                             "truth as the prediction, pysot as the file has it, got10k never)")
    parser.add_argument("--frame-weighted", action="store_true",
                        help="pool the frames of all sequences (default: as the protocol; otb and pysot "
                             "weigh sequences equally, got10k pools frames)")
    add_max_frames_argument(parser)
    parser.add_argument("--missing", choices=MISSING, default="skip",
                        help="a sequence some tracker has no result for: skip (default) scores the sequences "
                             "every tracker completed and names the others; fail scores a missing result as a "
                             "total failure, as the toolkits do")
    add_experiment_argument(parser)


def run_report(args: argparse.Namespace) -> int:
    """Print the overall table and write the report files."""
    experiment = check_protocol(args)
    sequences = [s.head(args.max_frames) for s in load_datasets(args.dataset, args.root, args.sequences)]
    trackers = [t for t in args.trackers.split(",") if t] if args.trackers else None
    if experiment.scoring != "otb":
        return OTHER_REPORTS[experiment.scoring](args, experiment, sequences, trackers)
    write = functools.partial(write_html_report if args.html else score_and_write, experiment=experiment,
                              baseline=args.baseline)
    evaluation, paths = write(args.out, sequences, trackers, args.report_dir, include_first=not args.skip_first,
                              weighting="frame" if args.frame_weighted else None, protocol=args.protocol,
                              missing=args.missing)
    protocol = evaluation.protocol.name  # --protocol, else the benchmark's
    print(format_table(evaluation.overall, args.format, columns("overall", protocol), protocol,
                       evaluation.statistics, experiment=experiment,
                       max_frames=evaluation.settings["max_frames"], datasets=evaluation.settings["datasets"]),
          end="")
    if evaluation.settings["fps_note"] and args.format in ("table", "markdown"):
        print(f"\n{evaluation.settings['fps_note']}")
    if evaluation.long_term and args.format != "table":  # the table format's comes after its notes, below
        _print_long_term(evaluation.long_term, args.format, experiment, evaluation.settings["max_frames"])
    if args.format == "table":
        for tracker, rows in evaluation.platforms.items():  # ten lines at most: records may differ per sequence
            print(f"{tracker} platform: {'; '.join(counted_lines(dict(rows), sum(n for _, n in rows)))}")
        recorded = {line for rows in evaluation.platforms.values() for line, _ in rows} - {"not recorded"}
        if len(recorded) > 1:
            print(f"warning: these results come from {len(recorded)} platforms; their boxes may part where a float "
                  f"decision is close (docs/architecture.md)", file=sys.stderr)
        for name, without in evaluation.settings["left_out"].items():
            print(f"left out: {name} (no result from {', '.join(without)}; --missing fail scores it as a failure)")
        if evaluation.long_term:
            print("\n" + long_term_lines(evaluation.long_term, brief=True), end="")
        print("\n" + "\n".join(statistics_lines(evaluation.statistics)))
        print(f"\n{len(paths)} files written to {paths[0].parent}")
        if args.html:
            print(f"open {paths[-1]}")
    return 0


def _print_long_term(record: Mapping, fmt: str, experiment: Experiment, max_frames: int | None) -> None:
    """The long-term table (or why there is none: not in LaTeX) after the OTB one, in ``fmt``;
    csv's on stderr, so that stdout stays one table (as ``dcfkit compare --format csv`` keeps its
    notes off stdout)."""
    text = long_term_output(record, fmt, experiment, max_frames)
    if fmt == "csv":
        print(text, end="", file=sys.stderr)
    elif text:
        print("\n" + text, end="")


def _reset_report(args: argparse.Namespace, experiment: Experiment, sequences: list,
                  trackers: list[str] | None) -> int:
    """``report --experiment reset``: the accuracy, failures and EAO table and the statistics."""
    if args.html:
        raise ConfigError(f"--html: reset-based runs have no report page (their tables, statistics.txt and "
                          f"reset.json are written without it); leave --html out for --experiment {experiment.name}")
    scores, paths = write_reset_report(args.out, sequences, trackers, args.report_dir, protocol=args.protocol,
                                       baseline=args.baseline)
    print(reset_latex(scores) if args.format == "latex" else reset_table(scores, "overall", args.format), end="")
    if args.format != "table":
        _print_long_term(score_long_term({}, {}, [], experiment), args.format, experiment, None)
    if args.format == "table":
        for name, without in scores["left_out"].items():
            print(f"left out: {name} (no result from {', '.join(without)})")
        print("\n" + long_term_lines(score_long_term({}, {}, [], experiment)), end="")
        print("\n" + "\n".join(statistics_lines(scores["statistics"])))
        print(f"\n{len(paths)} files written to {paths[0].parent}")
    return 0


OTHER_REPORTS = {"reset": _reset_report}  # by Experiment.scoring; "otb" is run_report's own


def add_compare_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("results", metavar="RESULTS",
                   help="folder of <sequence>.txt result files (1-based x,y,w,h), e.g. OUT/<tracker>; NAME=FOLDER "
                        "names it (the output calls each side by its NAME, else its folder's name)")
    p.add_argument("reference", metavar="REFERENCE",
                   help="folder of result files to compare with (or NAME=FOLDER); differences are RESULTS minus "
                        "REFERENCE")
    add_dataset_arguments(p, "benchmark root folder (the ground truth)")
    add_protocol_argument(p)
    p.add_argument("--experiment", choices=[n for n, e in EXPERIMENTS.items() if e.scoring == "otb"], default="ope",
                   help="ope: a file per sequence (default); tre, sre: a file per run, read from "
                        "FOLDER/<experiment>/ where FOLDER holds one, each sequence's runs pooled (as in "
                        "'dcfkit report --experiment')")
    p.add_argument("--divergence-px", type=pixels, default=2.0,
                   help="centres further apart than this (pixels) count as diverged")
    p.add_argument("--format", choices=("table", "markdown", "csv", "json"), default="table",
                   help="output format; json holds everything, with csv the closing notes (folders, "
                        "divergences, left-out sequences) go to stderr")


def _named(folder: str, experiment: str = "ope") -> tuple[str | None, Path]:
    """(its name, the folder) of a RESULTS or REFERENCE argument: ``NAME=FOLDER`` or a folder;
    its experiment's sub-folder (TRE's ``tre/``) where it holds one (an eval's tracker folder)."""
    name, path = (named_folder(Path.cwd(), folder) if "=" in folder and not os.path.isdir(folder)
                  else (None, Path(folder)))
    sub = get_experiment(experiment).folder
    return name, path / sub if sub and (path / sub).is_dir() else path


def side_names(named: tuple[tuple[str | None, Path], tuple[str | None, Path]]) -> list[str]:
    """What ``compare`` calls its two sides: each one's NAME, else its folder's name (with its
    parent's where both share it; ``RESULTS`` and ``REFERENCE`` for one folder given twice)."""
    (a, folder_a), (b, folder_b) = named
    names = [a or folder_a.resolve().name, b or folder_b.resolve().name]
    if names[0] == names[1] and not (a and b):
        names = [n or f"{f.resolve().parent.name}/{f.resolve().name}" for n, f in named]
    return [printable(n) for n in names] if names[0] != names[1] else ["RESULTS", "REFERENCE"]


def run_compare(args: argparse.Namespace) -> int:
    """Print the per-sequence comparison, each side named (:func:`side_names`)."""
    sequences = load_datasets(args.dataset, args.root, args.sequences)
    named = _named(args.results, args.experiment), _named(args.reference, args.experiment)
    res = compare_folders(named[0][1], named[1][1], sequences, args.protocol, args.divergence_px, args.experiment)
    res["names"] = ours, theirs = side_names(named)
    if args.format == "json":
        print(json.dumps(json_ready(res), indent=1))
        return 0
    pooled = get_experiment(args.experiment).pooled
    print(format_table(res["rows"] + [res["mean"]], args.format, COLUMNS, res["protocol"],
                       experiment=args.experiment if pooled else None), end="")
    notes = sys.stderr if args.format == "csv" else sys.stdout
    sides = {"results": ours, "reference": theirs}
    labels = {"only_in_results": f"only in {ours}", "only_in_reference": f"only in {theirs}"}
    left = "; ".join(f"{labels.get(k, k.replace('_', ' '))}: {', '.join(v[:10])}"
                     f"{f' and {len(v) - 10:,} more (--format json lists them)' if len(v) > 10 else ''}"
                     for k, v in res["left_out"].items() if v)
    print(f"\n{ours} (RESULTS): {res['results']}\n{theirs} (REFERENCE): {res['reference']}\n"
          f"{res['diverged']} of {len(res['rows'])} sequences diverge (centres more than "
          f"{args.divergence_px:g} px apart{'; diverges_at k:f, frame f of run k' if pooled else ''}); "
          f"precision, auc: {ours}; precision_ref, auc_ref: {theirs}; "
          f"d_ = {ours} minus {theirs}\nleft out: {left or 'none'}", file=notes)
    for side, name in sides.items():
        print(f"{name} platform: {'; '.join(res['platforms'][side])}", file=notes)
    print("\n".join(comparison_lines(res["statistics"], (ours, theirs))), file=notes)
    print(noise_floor_line(res["noise_floor"], len(res["rows"])), file=notes)
    if res["platform_differences"]:
        print(f"warning: {ours} and {theirs} come from different platforms ({'; '.join(res['platform_differences'])}); "
              f"their boxes may part where a float decision is close (docs/architecture.md)", file=sys.stderr)
    return 0

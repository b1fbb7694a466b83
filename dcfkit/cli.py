"""dcfkit: discriminative correlation filter trackers assembled from YAML.

Commands: track (one video), demo (a generated sequence, no data needed), components,
eval (one-pass evaluation on a benchmark), report, compare (two result folders side by
side), ablate."""
from __future__ import annotations

import argparse
import json
import sys
import time
import warnings
from pathlib import Path

from . import __version__
from .errors import DcfkitError


def _parse_box(text: str) -> tuple[float, ...]:
    try:
        box = tuple(float(v) for v in text.replace(" ", "").split(","))
    except ValueError:
        box = ()
    if len(box) != 4:
        raise DcfkitError(f"--box expects x,y,w,h (four numbers), got {text!r}")
    return box


def _pixels(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        value = -1.0
    if not value >= 0:
        raise argparse.ArgumentTypeError(f"expected a distance in pixels >= 0, got {text!r}")
    return value


def _frame_count(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        value = 0
    if value < 2:
        raise argparse.ArgumentTypeError(f"expected a whole number of frames >= 2, got {text!r}")
    return value


def cmd_track(args) -> int:
    from .config import parse_overrides
    from .tracker import load_tracker
    from .video import VideoWriter, check_writable, iter_frames

    tracker = load_tracker(args.config, overrides=parse_overrides(args.set))
    out = check_writable(args.out, "--out") if args.out else None
    offset = 1.0 if args.one_based else 0.0
    box = _parse_box(args.box)
    box = (box[0] - offset, box[1] - offset, box[2], box[3])
    writer = VideoWriter(args.save_video) if args.save_video else None
    boxes, seconds = [], 0.0
    try:
        for i, image in enumerate(iter_frames(args.video, args.frames)):
            start = time.perf_counter()
            if i == 0:
                tracker.init(image, box)
                current = box
            else:
                current = tracker.update(image)
            seconds += time.perf_counter() - start
            boxes.append(current)
            if writer:
                writer.write(image, {tracker.name: current}, f"frame {i + 1}")
    finally:  # an error on frame k keeps the boxes of frames 1..k-1
        if writer:
            writer.close()
        lines = [",".join(f"{v + (offset if k < 2 else 0):.3f}" for k, v in enumerate(b)) for b in boxes]
        if out and boxes:
            out.write_text("\n".join(lines) + "\n")
        elif boxes:
            print("\n".join(lines))
        if boxes:
            print(f"{tracker.name}: {len(boxes)} frames, {len(boxes) / max(seconds, 1e-9):.1f} fps", file=sys.stderr)
    return 0


def cmd_demo(args) -> int:
    from .metrics import score_sequence
    from .synthetic import make_sequence
    from .tracker import load_tracker
    from .video import VideoWriter

    writer = VideoWriter(args.save_video) if args.save_video else None  # fail before tracking
    seq = make_sequence(n_frames=args.frames, seed=args.seed)
    results = {}
    for name in args.trackers.split(","):
        tracker = load_tracker(name)
        boxes, seconds = [tuple(seq.ground_truth[0])], 0.0
        tracker.init(seq.frames[0], seq.ground_truth[0])
        distractors = [tracker.last_distractors]
        for image in seq.frames[1:]:
            start = time.perf_counter()
            boxes.append(tracker.update(image))
            seconds += time.perf_counter() - start
            distractors.append(tracker.last_distractors)
        scores = score_sequence(boxes, seq.ground_truth)
        results[tracker.name] = (boxes, scores, (len(seq.frames) - 1) / max(seconds, 1e-9), distractors)
    print(f"synthetic sequence: {len(seq.frames)} frames, a look-alike distractor passes the target")
    print(f"{'tracker':<12} {'precision@20':>12} {'AUC':>6} {'fps':>7}")
    for name, (_, scores, fps, _) in results.items():
        print(f"{name:<12} {scores['precision']:>12.3f} {scores['auc']:>6.3f} {fps:>7.1f}")
    if writer:
        for i, image in enumerate(seq.frames):
            boxes = {"ground truth": seq.ground_truth[i]}
            boxes.update({name: r[0][i] for name, r in results.items()})
            writer.write(image, boxes, f"frame {i + 1}", points={name: r[3][i] for name, r in results.items()})
        writer.close()
        print(f"annotated video: {args.save_video} (circles: the distractors each tracker repressed)")
    return 0


def cmd_components(args) -> int:
    from .docs_gen import component_rows, components_markdown
    from .registry import PluginWarning, get_registry

    with warnings.catch_warnings():  # the skipped plugins are listed below, each once
        warnings.simplefilter("ignore", PluginWarning)
        registry = get_registry()
    rows = component_rows(registry, [args.kind] if args.kind else None)
    if args.format == "json":
        print(json.dumps(rows, indent=2, default=str))
    elif args.format == "markdown":
        print(components_markdown(rows), end="")
    else:
        for row in rows:
            print(f"{row['kind']:<12} {row['name']:<22} {row['doc']}  [{row['provider']}]")
            for f in row["params"]:
                print(f"{'':<14}{f['name']} ({f['type']}, default {f['default']}): {f['help']}")
    for failure in registry.failures:
        print(f"warning: {failure}", file=sys.stderr)
    return 1 if registry.failures else 0


def cmd_compare(args) -> int:
    from .compare import COLUMNS, compare_folders
    from .datasets import load_dataset
    from .report import json_ready, format_table

    sequences = load_dataset(args.dataset, args.root, args.sequences)
    res = compare_folders(args.results, args.reference, sequences, args.protocol, args.divergence_px)
    if args.format == "json":
        print(json.dumps(json_ready(res), indent=1))
        return 0
    print(format_table(res["rows"] + [res["mean"]], args.format, COLUMNS, args.protocol), end="")
    left = "; ".join(f"{k.replace('_', ' ')}: {', '.join(v)}" for k, v in res["left_out"].items() if v)
    print(f"\nresults: {res['results']}\nreference: {res['reference']}\n"
          f"{res['diverged']} of {len(res['rows'])} sequences diverge (centres more than "
          f"{args.divergence_px:g} px apart); d_ = results minus reference\n"
          f"left out: {left or 'none'}", file=sys.stderr if args.format == "csv" else sys.stdout)
    return 0


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="dcfkit", description=__doc__)
    parser.add_argument("--version", action="version", version=f"dcfkit {__version__}")
    sub = parser.add_subparsers(dest="command", required=True)

    p = sub.add_parser("track", help="track one target through a video or a folder of frames")
    p.add_argument("config", help="config file or shipped name (strcf, bacf, dr2track)")
    src = p.add_mutually_exclusive_group(required=True)
    src.add_argument("--video", help="video file")
    src.add_argument("--frames", help="folder of image files, tracked in natural name order (frame2 before frame10)")
    p.add_argument("--box", required=True, help="initial box x,y,w,h (0-based pixels unless --one-based); "
                   "write --box=-5,10,40,30 when x is negative")
    p.add_argument("--one-based", action="store_true", help="--box and --out use 1-based (OTB toolkit) pixels")
    p.add_argument("--out", help="write one x,y,w,h line per frame here (default: stdout)")
    p.add_argument("--save-video", help="write an annotated video (.mp4, .avi, .mkv, .mov or .m4v)")
    p.add_argument("--set", action="append", metavar="KEY=VALUE", help="override a config key, e.g. label.mu=0.3")
    p.set_defaults(func=cmd_track)

    p = sub.add_parser("demo", help="run STRCF and DR²Track on a generated sequence (no data needed)")
    p.add_argument("--trackers", default="strcf,dr2track", help="comma-separated configs")
    p.add_argument("--frames", type=_frame_count, default=120, help="sequence length (at least 2)")
    p.add_argument("--seed", type=int, default=0, help="random seed of the generated sequence")
    p.add_argument("--save-video", default="dcfkit_demo.mp4", help="annotated video ('' to skip)")
    p.set_defaults(func=cmd_demo)

    p = sub.add_parser("components", help="list registered components and their parameters")
    p.add_argument("--kind", choices=("feature", "label", "regularizer", "solver", "search", "scale"))
    p.add_argument("--format", choices=("table", "markdown", "json"), default="table")
    p.set_defaults(func=cmd_components)

    from .ablation import add_ablate_arguments, cmd_ablate
    from .evaluation import add_eval_arguments, cmd_eval
    from .report import add_protocol_argument, add_report_arguments, cmd_report

    p = sub.add_parser("eval", help="one-pass evaluation of configs on a benchmark")
    add_eval_arguments(p)
    p.set_defaults(func=cmd_eval)
    p = sub.add_parser("report", help="tables and precision/success plots of evaluation results")
    add_report_arguments(p)
    p.set_defaults(func=cmd_report)
    p = sub.add_parser("compare", help="two folders of result files side by side per sequence: scores, "
                                       "their differences, box agreement (parity checks)")
    p.add_argument("results", type=Path, metavar="RESULTS",
                   help="folder of <sequence>.txt result files (1-based x,y,w,h), e.g. OUT/<tracker>")
    p.add_argument("reference", type=Path, metavar="REFERENCE", help="folder of result files to compare with")
    p.add_argument("--dataset", default="auto", help="dataset name (default: detect from --root)")
    p.add_argument("--root", required=True, type=Path, help="benchmark root folder (the ground truth)")
    p.add_argument("--sequences", default=None, help="comma-separated sequence names (default: all)")
    add_protocol_argument(p)
    p.add_argument("--divergence-px", type=_pixels, default=2.0,
                   help="centres further apart than this (pixels) count as diverged")
    p.add_argument("--format", choices=("table", "markdown", "csv", "json"), default="table",
                   help="output format; json holds everything, with csv the closing notes (folders, "
                        "divergences, left-out sequences) go to stderr")
    p.set_defaults(func=cmd_compare)
    p = sub.add_parser("ablate", help="run an ablation spec: variants x parameter grids x sequences")
    add_ablate_arguments(p)
    p.set_defaults(func=cmd_ablate)
    return parser


def _one_line_plugin_warnings(show):
    """``warnings.showwarning`` for the CLI: a plugin problem is one ``warning: ...`` line,
    not a source location inside dcfkit's registry."""
    from .registry import PluginWarning

    def showwarning(message, category, filename, lineno, file=None, line=None):
        if issubclass(category, PluginWarning):
            print(f"warning: {message}", file=sys.stderr)
        else:
            show(message, category, filename, lineno, file, line)
    return showwarning


def main(argv: list[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    with warnings.catch_warnings():
        warnings.showwarning = _one_line_plugin_warnings(warnings.showwarning)
        try:
            return args.func(args) or 0
        except DcfkitError as exc:
            print(f"dcfkit {args.command}: error: {exc}", file=sys.stderr)
            return 2
        except KeyboardInterrupt:
            print(f"dcfkit {args.command}: interrupted", file=sys.stderr)
            return 130
        except BrokenPipeError:  # e.g. piped into head
            sys.stderr.close()
            return 0


if __name__ == "__main__":
    sys.exit(main())

"""``dcfkit datasets``: every benchmark layout ``--dataset`` accepts, dcfkit's and the plugins',
with its other names, its folders and who provides it, as a table or JSON."""
from __future__ import annotations

import argparse
import json
import sys
import warnings
from pathlib import Path

from dcfkit.cli.common import add_dataset_arguments
from dcfkit.datasets import layouts, load_datasets
from dcfkit.integrations.vot import DEFAULT_FPS, export_sequences, frame_rate
from dcfkit.protocols import DEFAULT
from dcfkit.registry import PluginWarning, get_registry


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--format", choices=("table", "json"), default="table")


def dataset_rows() -> list[dict]:
    """One dict per layout: name, aliases, provider, layout (its folders), detected (whether
    ``--dataset auto`` considers it), protocol (the one its scores follow by default)."""
    return [{"name": layout.name, "aliases": list(layout.aliases), "provider": layout.provider or "dcfkit",
             "layout": layout.description, "detected": layout.detect is not None,
             "protocol": layout.protocol or DEFAULT} for layout in layouts()]


def run(args: argparse.Namespace) -> int:
    """List the layouts; exit status 1 if a plugin could not be loaded."""
    with warnings.catch_warnings():  # the skipped plugins are listed below, each once
        warnings.simplefilter("ignore", PluginWarning)
        registry = get_registry()
        rows = dataset_rows()
    if args.format == "json":
        print(json.dumps(rows, indent=2))
    else:
        for row in rows:
            print(f"{row['name']:<18} {row['layout']}  [{row['provider']}]")
            notes = ([f"also: {', '.join(row['aliases'])}"] if row["aliases"] else []) + \
                ([] if row["detected"] else ["by name only (not detected)"]) + \
                ([f"scored with --protocol {row['protocol']}"] if row["protocol"] != DEFAULT else [])
            if notes:
                print(f"{'':<19}{'; '.join(notes)}")
    for failure in registry.failures:
        print(f"warning: {failure}", file=sys.stderr)
    return 1 if registry.failures else 0


def add_export_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("format", choices=("vot",), help="vot: a VOT toolkit workspace's sequences")
    add_dataset_arguments(parser)
    parser.add_argument("--out", required=True, type=Path, help="the workspace folder (its sequences/ is written)")
    parser.add_argument("--copy", action="store_true", help="copy the frames (default: link them)")


def run_export(args: argparse.Namespace) -> int:
    """Add the sequences of a dataset to a workspace in another toolkit's layout."""
    sequences = load_datasets(args.dataset, args.root, args.sequences)
    done = export_sequences(sequences, args.out, copy=args.copy)
    already = f", {len(done['skipped'])} already there" if done["skipped"] else ""
    print(f"{len(done['written'])} sequences written to {args.out / 'sequences'}{already} (list.txt lists "
          f"{len(done['listed'])}; <sequence>/sequence, groundtruth.txt, color/)")
    for dataset in sorted({s.dataset for s in sequences if frame_rate(s) is None}):
        print(f"note: fps={DEFAULT_FPS} written for {dataset!r}, the VOT toolkit's default: dcfkit does not know "
              f"its frame rate")
    return 0

"""The ``dcfkit`` argument parser: one subcommand per command module."""
from __future__ import annotations

import argparse

from dcfkit import __version__
from dcfkit.cli import ablate, components, datasets, evaluate, search, track, trax
from dcfkit.errors import SHOWN_CHARS

DESCRIPTION = """dcfkit: discriminative correlation filter trackers assembled from YAML.

Commands: track (one video), demo (a generated sequence, no data needed), components,
datasets (the benchmark layouts --dataset accepts), eval (one-pass evaluation on a
benchmark), report, compare (two result folders side by side), ablate, search (an automated
search of the component space, judged on held-out folds), export (a dataset as a VOT
workspace's sequences), trax (serve the VOT toolkit's TraX protocol)."""

#: name -> (help, add_arguments, run)
COMMANDS = {
    "track": ("track one target through a video or a folder of frames", track.add_track_arguments, track.run_track),
    "demo": ("run STRCF and DR²Track on a generated sequence (no data needed)", track.add_demo_arguments,
             track.run_demo),
    "components": ("list registered components and their parameters", components.add_arguments, components.run),
    "datasets": ("list the benchmark layouts --dataset accepts (dcfkit's and plugins')", datasets.add_arguments,
                 datasets.run),
    "eval": ("one-pass evaluation of configs on a benchmark", evaluate.add_eval_arguments, evaluate.run_eval),
    "report": ("tables and precision/success plots of evaluation results", evaluate.add_report_arguments,
               evaluate.run_report),
    "compare": ("two folders of result files side by side per sequence: scores, their differences, box "
                "agreement (parity checks)", evaluate.add_compare_arguments, evaluate.run_compare),
    "ablate": ("run an ablation spec: variants x parameter grids x sequences", ablate.add_arguments, ablate.run),
    "search": ("search the component space and its parameters (Optuna), judged on held-out folds of sequences",
               search.add_arguments, search.run),
    "export": ("write a dataset's sequences in another toolkit's layout (vot: a VOT workspace's sequences/)",
               datasets.add_export_arguments, datasets.run_export),
    "trax": ("serve a config over the TraX protocol on stdin/stdout, for the VOT toolkit (needs dcfkit[trax])",
             trax.add_arguments, trax.run),
}


class Parser(argparse.ArgumentParser):
    """argparse's parser, but a usage error shows at most the start and end of its message:
    argparse echoes an invalid choice or unrecognized argument whole, however long."""

    def error(self, message: str):
        if len(message) > 2 * SHOWN_CHARS:  # the start names the argument, the end the valid choices
            message = f"{message[:SHOWN_CHARS]}...{message[-SHOWN_CHARS:]}"
        super().error(message)


def build_parser() -> argparse.ArgumentParser:
    parser = Parser(prog="dcfkit", description=DESCRIPTION)
    parser.add_argument("--version", action="version", version=f"dcfkit {__version__}")
    sub = parser.add_subparsers(dest="command", required=True)
    for name, (help_, add_arguments, run) in COMMANDS.items():
        p = sub.add_parser(name, help=help_)
        add_arguments(p)
        p.set_defaults(func=run)
    return parser

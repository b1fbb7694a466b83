"""The ``dcfkit`` argument parser: one subcommand per command module."""
from __future__ import annotations

import argparse

from dcfkit import __version__
from dcfkit.errors import SHOWN_CHARS

DESCRIPTION = """dcfkit: discriminative correlation filter trackers assembled from YAML.

Commands: track (one video), demo (a generated sequence, no data needed), components,
datasets (the benchmark layouts --dataset accepts), eval (one-pass evaluation on a
benchmark), report, compare (two result folders side by side), ablate, search (an automated
search of the component space, judged on held-out folds), export (a dataset as a VOT
workspace's sequences), trax (serve the VOT toolkit's TraX protocol)."""


def _track():
    from dcfkit.cli import track  # deferred: a command's module is imported when it runs (COMMANDS)
    return track


def _components():
    from dcfkit.cli import components  # deferred: a command's module is imported when it runs (COMMANDS)
    return components


def _datasets():
    from dcfkit.cli import datasets  # deferred: a command's module is imported when it runs (COMMANDS)
    return datasets


def _evaluate():
    from dcfkit.cli import evaluate  # deferred: a command's module is imported when it runs (COMMANDS)
    return evaluate


def _ablate():
    from dcfkit.cli import ablate  # deferred: a command's module is imported when it runs (COMMANDS)
    return ablate


def _search():
    from dcfkit.cli import search  # deferred: a command's module is imported when it runs (COMMANDS)
    return search


def _trax():
    from dcfkit.cli import trax  # deferred: a command's module is imported when it runs (COMMANDS)
    return trax


#: name -> (help, a loader of the module that defines it, its add_arguments, its run): a
#: command's module is imported when the command line names it, so that ``dcfkit trax`` or
#: ``dcfkit track`` starts without the analysis stack (scipy.stats) that eval and ablate load
COMMANDS = {
    "track": ("track one target through a video or a folder of frames", _track, "add_track_arguments",
              "run_track"),
    "demo": ("run STRCF and DR²Track on a generated sequence (no data needed)", _track, "add_demo_arguments",
             "run_demo"),
    "components": ("list registered components and their parameters", _components, "add_arguments", "run"),
    "datasets": ("list the benchmark layouts --dataset accepts (dcfkit's and plugins')", _datasets,
                 "add_arguments", "run"),
    "eval": ("one-pass evaluation of configs on a benchmark", _evaluate, "add_eval_arguments", "run_eval"),
    "report": ("tables and precision/success plots of evaluation results", _evaluate, "add_report_arguments",
               "run_report"),
    "compare": ("two folders of result files side by side per sequence: scores, their differences, box "
                "agreement (parity checks)", _evaluate, "add_compare_arguments", "run_compare"),
    "ablate": ("run an ablation spec: variants x parameter grids x sequences", _ablate, "add_arguments", "run"),
    "search": ("search the component space and its parameters (Optuna), judged on held-out folds of sequences",
               _search, "add_arguments", "run"),
    "export": ("write a dataset's sequences in another toolkit's layout (vot: a VOT workspace's sequences/)",
               _datasets, "add_export_arguments", "run_export"),
    "trax": ("serve a config over the TraX protocol on stdin/stdout, for the VOT toolkit (needs dcfkit[trax])",
             _trax, "add_arguments", "run"),
}


def named_command(argv: list[str]) -> str | None:
    """The command ``argv`` names (its first word that is not an option: dcfkit's own options
    take no value), or None when it names none of ``COMMANDS``."""
    first = next((word for word in argv if not word.startswith("-")), None)
    return first if first in COMMANDS else None


class Parser(argparse.ArgumentParser):
    """argparse's parser, but a usage error shows at most the start and end of its message:
    argparse echoes an invalid choice or unrecognized argument whole, however long."""

    def error(self, message: str):
        if len(message) > 2 * SHOWN_CHARS:  # the start names the argument, the end the valid choices
            message = f"{message[:SHOWN_CHARS]}...{message[-SHOWN_CHARS:]}"
        super().error(message)


def build_parser(only: str | None = None) -> argparse.ArgumentParser:
    """Every command's subparser; with ``only``, the arguments of that command alone (the
    others keep their name and help, and their modules are not imported)."""
    parser = Parser(prog="dcfkit", description=DESCRIPTION)
    parser.add_argument("--version", action="version", version=f"dcfkit {__version__}")
    sub = parser.add_subparsers(dest="command", required=True)
    for name, (help_, load, add_arguments, run) in COMMANDS.items():
        p = sub.add_parser(name, help=help_)
        if only in (None, name):
            loaded = load()
            getattr(loaded, add_arguments)(p)
            p.set_defaults(func=getattr(loaded, run))
    return parser

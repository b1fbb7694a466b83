"""``dcfkit trax``: serve one config over the TraX protocol (the VOT toolkit's), on stdin/stdout."""
from __future__ import annotations

import argparse
import sys

from dcfkit.config import load_config
from dcfkit.config.overrides import parse_overrides
from dcfkit.opencv_check import contrib_problem


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("config", help="config file or shipped name (strcf, bacf, dr2track, kcf, dsst)")
    p.add_argument("--set", action="append", metavar="KEY=VALUE", help="override a config key, e.g. label.mu=0.3")


def run(args: argparse.Namespace) -> int:
    """Check the config, then serve until the client quits (status 0); an error on a frame is
    sent to the client and printed on stderr (status 2)."""
    from dcfkit.integrations.trax import serve  # deferred: needs the optional vot-trax package

    config = load_config(args.config, parse_overrides(args.set))
    problem = contrib_problem()
    if problem:
        print(f"dcfkit trax: warning: {problem}", file=sys.stderr)
    serve(config)
    return 0

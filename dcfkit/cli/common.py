"""Argument types and options shared by several commands."""
from __future__ import annotations

import argparse
from pathlib import Path

from ..errors import DcfkitError
from ..protocols import DEFAULT, PROTOCOLS


def parse_box(text: str) -> tuple[float, ...]:
    """``x,y,w,h`` as four floats."""
    try:
        box = tuple(float(v) for v in text.replace(" ", "").split(","))
    except ValueError:
        box = ()
    if len(box) != 4:
        raise DcfkitError(f"--box expects x,y,w,h (four numbers), got {text!r}")
    return box


def pixels(text: str) -> float:
    """An argparse type: a distance in pixels >= 0."""
    try:
        value = float(text)
    except ValueError:
        value = -1.0
    if not value >= 0:
        raise argparse.ArgumentTypeError(f"expected a distance in pixels >= 0, got {text!r}")
    return value


# the demo's generated world is twice the frame; its camera drifts off it after some 265 frames
MAX_DEMO_FRAMES = 250


def frame_count(text: str) -> int:
    """An argparse type: a whole number of frames from 2 to MAX_DEMO_FRAMES."""
    try:
        value = int(text)
    except ValueError:
        value = 0
    if not 2 <= value <= MAX_DEMO_FRAMES:
        raise argparse.ArgumentTypeError(f"expected a whole number of frames from 2 to {MAX_DEMO_FRAMES}, got {text!r}")
    return value


def seed(text: str) -> int:
    """An argparse type: a random seed, a whole number >= 0 (numpy refuses negative ones)."""
    try:
        value = int(text)
    except ValueError:
        value = -1
    if value < 0:
        raise argparse.ArgumentTypeError(f"expected a whole number >= 0, got {text!r}")
    return value


def add_protocol_argument(parser: argparse.ArgumentParser) -> None:
    """``--protocol``, for the commands that print scores."""
    parser.add_argument("--protocol", choices=tuple(PROTOCOLS), default=DEFAULT,
                        help="scoring rules: otb (the OTB / UAV123 MATLAB toolkit, which computed the published "
                             "UAV123 tables), pysot or got10k; docs/evaluation.md lists the differences")


def add_dataset_arguments(parser: argparse.ArgumentParser, root_help: str = "benchmark root folder") -> None:
    """``--dataset``, ``--root`` and ``--sequences``."""
    parser.add_argument("--dataset", default="auto", help="dataset name (default: detect from --root)")
    parser.add_argument("--root", required=True, type=Path, help=root_help)
    parser.add_argument("--sequences", default=None, help="comma-separated sequence names (default: all)")

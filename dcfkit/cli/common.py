"""Argument types and options shared by several commands."""
from __future__ import annotations

import argparse
from pathlib import Path

from dcfkit.errors import ConfigError, DcfkitError, shown
from dcfkit.protocols import DEFAULT, PROTOCOLS
from dcfkit.running.scheduler import check_address


def parse_box(text: str) -> tuple[float, ...]:
    """``x,y,w,h`` as four floats."""
    try:
        box = tuple(float(v) for v in text.replace(" ", "").split(","))
    except ValueError:
        box = ()
    if len(box) != 4:
        raise DcfkitError(f"--box expects x,y,w,h (four numbers), got {shown(text)}")
    return box


def _argument_type(convert, accept, expected: str):
    """An argparse type: ``convert(text)`` if it converts and ``accept`` takes the value, else an
    error saying it ``expected`` something else."""
    def parse(text: str):
        try:
            value = convert(text)
        except ValueError:
            value = None
        if value is None or not accept(value):
            raise argparse.ArgumentTypeError(f"expected {expected}, got {shown(text)}")
        return value
    return parse


# the demo's generated world is twice the frame; its camera drifts off it after some 265 frames
MAX_DEMO_FRAMES = 250

pixels = _argument_type(float, lambda v: v >= 0, "a distance in pixels >= 0")  # NaN fails v >= 0 too
frame_count = _argument_type(int, lambda v: 2 <= v <= MAX_DEMO_FRAMES,
                             f"a whole number of frames from 2 to {MAX_DEMO_FRAMES}")
seed = _argument_type(int, lambda v: v >= 0, "a whole number >= 0")  # numpy refuses negative seeds
variant_count = _argument_type(int, lambda v: v >= 1, "a whole number of variants >= 1")


def add_protocol_argument(parser: argparse.ArgumentParser, reset: bool = False) -> None:
    """``--protocol``, for the commands that print scores; ``reset``: also the rules of the
    reset-based experiment (:func:`check_protocol` matches them to ``--experiment``)."""
    from dcfkit.experiments.vot import DEFAULT_RULE, RULES  # lazy: the parser is built before any command runs

    extra = (f"; with --experiment reset: {DEFAULT_RULE} (default: the VOT2016 toolkit's overlap, failures and "
             f"scores) or vot-toolkit (vot-toolkit 0.9's)") if reset else ""
    parser.add_argument("--protocol", choices=tuple(PROTOCOLS) + (tuple(RULES) if reset else ()), default=None,
                        help="scoring rules: otb (the OTB / UAV123 MATLAB toolkit, which computed the published "
                             "UAV123 tables), pysot, got10k or lasot (the LaSOT toolkit: absent frames fail); "
                             "default: the rules of the benchmark's published tables (lasot for LaSOT, got10k "
                             f"for GOT-10k, {DEFAULT} for the others, `dcfkit datasets` says which){extra}; "
                             "docs/evaluation.md lists the differences")


def check_protocol(args: argparse.Namespace):
    """The :class:`~dcfkit.experiments.Experiment` ``--experiment`` names, bound to ``--protocol``
    when that is one of the experiment's own rules; a :class:`ConfigError` if ``--protocol`` does
    not fit: an experiment with rules of its own (the reset-based one) takes one of them, the
    others a scoring protocol."""
    from dcfkit.experiments import EXPERIMENTS, get_experiment  # lazy: as add_protocol_argument

    experiment = get_experiment(args.experiment)
    if args.protocol is None:
        return experiment
    rules = experiment.rules
    if rules and args.protocol not in rules:
        raise ConfigError(f"--protocol {args.protocol} scores one-pass runs; --experiment {experiment.name} takes "
                          f"{' or '.join(rules)} (the toolkit whose overlap decides failures and scores)")
    owner = next((e.name for e in EXPERIMENTS.values() if args.protocol in e.rules), None)
    if not rules and owner is not None:
        raise ConfigError(f"--protocol {args.protocol} is a rule of the {owner} experiment; give --experiment "
                          f"{owner}, or for --experiment {experiment.name} one of {', '.join(PROTOCOLS)}")
    return experiment.bind(args.protocol)


def add_dataset_arguments(parser: argparse.ArgumentParser, root_help: str = "benchmark root folder") -> None:
    """``--dataset``, ``--root`` and ``--sequences``; ``--root`` repeats to pool datasets."""
    parser.add_argument("--dataset", action="append", default=None,
                        help="dataset name, as `dcfkit datasets` lists them (default: detect from --root); with "
                             "several --root, one for all or one per --root in order")
    parser.add_argument("--root", action="append", required=True, type=Path,
                        help=f"{root_help}; repeat it to pool the sequences of several roots into one evaluation "
                             f"(sequence names must differ; docs/evaluation.md, 'Pooling datasets')")
    parser.add_argument("--sequences", default=None,
                        help="comma-separated sequence names, from any --root (default: all)")


def frame_limit(text: str) -> int:
    """``--max-frames``: a whole number of frames, at least 1."""
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a whole number of frames, got {shown(text)}") from None
    if value < 1:
        raise argparse.ArgumentTypeError(f"expected at least 1 frame, got {value}")
    return value


def add_max_frames_argument(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--max-frames", type=frame_limit, default=None, metavar="N",
                        help="each sequence's first N frames only: a smoke run (its results are of the cut "
                             "sequences, never taken for full ones: score them with the same --max-frames)")


def add_experiment_argument(parser: argparse.ArgumentParser) -> None:
    from dcfkit.experiments import EXPERIMENTS  # lazy: the parser is built before any command runs

    parser.add_argument("--experiment", choices=tuple(EXPERIMENTS), default="ope",
                        help="ope: one pass from frame 1 (default); tre: 20 later starts; sre: 12 shifted or scaled "
                             "first boxes (OTB, Wu et al. 2015); reset: VOT's re-initialisation 5 frames after each "
                             "failure (accuracy, failures, EAO). Results other than ope go to OUT/<tracker>/<experiment>/")


def executor_choice(args: argparse.Namespace) -> str:
    """``--executor``, dask by default with ``--scheduler``, whose address is checked (scheme,
    HOST:PORT) before anything runs; connecting is left to the run."""
    executor = args.executor or ("dask" if args.scheduler else "local")
    if args.scheduler and executor != "dask":
        raise DcfkitError("--scheduler needs --executor dask")
    if args.scheduler:
        check_address(args.scheduler)
    return executor

"""A dcfkit tracker as a ``got10k.trackers.Tracker``, for the got10k toolkit's experiments::

    from got10k.experiments import ExperimentDTB70
    from dcfkit.integrations.got10k import Tracker

    ExperimentDTB70("data/DTB70").run(Tracker("strcf"))   # results/DTB70/strcf/<seq>.txt

got10k 0.1.3 hands over RGB PIL images (``got10k/trackers/__init__.py``; VOT's runs: an
unconverted image or a path) and the annotation files' 1-based boxes (``np.loadtxt`` in
``got10k/datasets/*.py``), writes returned boxes unchanged and calls ``init`` on one object
for every sequence. The adapter gives dcfkit BGR and 0-based boxes, returns 1-based ones, and
builds a new tracker at each ``init`` (docs/integrations.md has the table, and what goes wrong
without it). Importing this module imports got10k (``pip install "dcfkit[got10k]"``).
"""
from __future__ import annotations

import os
from typing import Any, Iterable, Mapping

import numpy as np
from PIL import Image

from dcfkit.config import load_config
from dcfkit.datasets import Sequence, read_frame
from dcfkit.errors import DcfkitError, InputError, TrackingError
from dcfkit.running.evaluation import tracker_name
from dcfkit.tracker.tracker import Tracker as DcfTracker

try:
    from got10k.experiments import ExperimentUAV123
    from got10k.trackers import Tracker as Got10kTracker
except ImportError as exc:  # the toolkit is an optional extra
    raise ModuleNotFoundError(f"dcfkit.integrations.got10k needs the got10k toolkit ({exc}), an optional extra: "
                              f'pip install "dcfkit[got10k]"', name="got10k") from exc

__all__ = ["Experiment", "SequenceList", "Tracker", "to_bgr"]

ONE_BASED = np.array([1.0, 1.0, 0.0, 0.0])  # added to (x, y, w, h): 0-based -> 1-based
ONE_BASED.setflags(write=False)  # every adapter's offset


def to_bgr(image: Any, frame: int) -> np.ndarray:
    """A frame as got10k hands it over (a PIL image of any mode, a file path, or an RGB or
    gray array) as dcfkit takes it: ``(H, W, 3)`` uint8 BGR, or the gray array unchanged.
    ``frame`` (1-based) is for the messages."""
    if isinstance(image, (str, os.PathLike)):
        return read_frame(image, f"frame {frame}")
    if isinstance(image, Image.Image):
        image = np.asarray(image if image.mode == "RGB" else image.convert("RGB"))  # as got10k's track()
    elif not isinstance(image, np.ndarray):
        raise InputError(f"frame {frame}: expected a PIL image, an RGB array or an image path, "
                         f"got {type(image).__name__}")
    return np.ascontiguousarray(image[..., ::-1]) if image.ndim == 3 else image


class Tracker(Got10kTracker):
    """A dcfkit config as a got10k tracker: ``init(image, box)``, ``update(image) -> box``.

    ``config`` is what :func:`dcfkit.load_tracker` takes (a shipped name, a path, a dict),
    ``overrides`` its dotted overrides (``{"label.mu": 0.3}``); ``name`` (default: the
    config's) names got10k's result folder. Boxes are got10k's ``(x, y, w, h)``, 1-based
    unless ``one_based=False``. ``dcf`` is the dcfkit tracker of the current sequence (its
    ``last_response``, ``last_confidence``), None before the first ``init``.
    """

    def __init__(self, config: str | os.PathLike | Mapping[str, Any], name: str | None = None,
                 overrides: Mapping[str, Any] | None = None, one_based: bool = True):
        extra = dict(overrides or {})
        if name is not None:
            extra["name"] = name
        self.config = load_config(config, extra)
        super().__init__(tracker_name(self.config), is_deterministic=True)
        self.offset = ONE_BASED if one_based else np.zeros(4)
        self.dcf: DcfTracker | None = None

    def init(self, image: Any, box) -> None:
        """A new sequence: a new dcfkit tracker, initialised on ``box``."""
        self.dcf = None  # a failed init leaves no tracker of the last sequence to update
        dcf = DcfTracker(self.config)
        dcf.init(to_bgr(image, 1), self._zero_based(box))
        self.dcf = dcf

    def update(self, image: Any) -> np.ndarray:
        """The target's box in the next frame, ``(4,) float64`` in got10k's convention."""
        if self.dcf is None:
            raise TrackingError("update() called before init()")
        frame = self.dcf.frame + 1
        try:
            image = to_bgr(image, frame)
        except DcfkitError:
            self.dcf.frame = frame  # counted, as the tracker counts the frames it refuses: numbers stay the video's
            raise
        return np.add(self.dcf.update(image), self.offset)

    def _zero_based(self, box) -> Any:
        try:
            raw = np.asarray(box)
        except ValueError:  # a ragged sequence
            return box
        if raw.dtype.kind not in "iuf" or raw.size != 4:
            return box  # not 4 numbers: dcfkit's init says what it got
        return raw.astype(np.float64).reshape(4) - self.offset


class SequenceList:
    """dcfkit's sequences as a got10k dataset: ``seq_names``, and ``dataset[i]`` or
    ``dataset[name]`` -> (frame paths, ``(N, 4)`` boxes, 1-based as got10k's datasets read them)."""

    def __init__(self, sequences: Iterable[Sequence]):
        self.sequences = list(sequences)
        self.seq_names = [s.name for s in self.sequences]

    def __len__(self) -> int:
        return len(self.sequences)

    def __getitem__(self, index: int | str) -> tuple[list[str], np.ndarray]:
        seq = self.sequences[self.seq_names.index(index) if isinstance(index, str) else index]
        return [str(f) for f in seq.frames], seq.ground_truth + ONE_BASED


class Experiment(ExperimentUAV123):
    """got10k's OTB-family experiment (``run``, ``report``, ``show``) on any sequences dcfkit
    loads, UAV123@10fps included, which got10k's own datasets cannot read. Scored as got10k's
    UAV123 experiment scores (rows of NaN ground truth left out)::

        experiment = Experiment(load_dataset("uav123_10fps", root), "UAV123_10fps")
        experiment.run(Tracker("strcf"))            # results/got10k/UAV123_10fps/strcf/<seq>.txt
        experiment.report(["strcf"])
    """

    def __init__(self, sequences: Iterable[Sequence], name: str, result_dir: str = "results/got10k",
                 report_dir: str = "results/got10k"):
        self.dataset = SequenceList(sequences)
        self.result_dir = os.path.join(result_dir, name)
        self.report_dir = os.path.join(report_dir, name)
        self.nbins_iou, self.nbins_ce = 21, 51  # got10k's OTB-family thresholds

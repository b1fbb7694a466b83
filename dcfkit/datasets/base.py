"""What every benchmark layout shares: :class:`Sequence`, :class:`DatasetError`, the readers of
frames, boxes and attribute flags, and the helpers a loader is built from (frame lists,
sequence selection). A layout module (or a plugin's) needs nothing else from dcfkit."""
from __future__ import annotations

import collections
import dataclasses
import difflib
import functools
import logging
import os
import warnings
from pathlib import Path
from typing import Iterable, Mapping

import numpy as np

from dcfkit.datasets.annotations import (
    annotation_lines,
    listed,
    parse_number,
    read_boxes,
    read_flags,
    read_frame_values,
    read_text,
)
from dcfkit.datasets.images import DatasetWarning, read_frame
from dcfkit.errors import DatasetError, DcfkitError, clip, shown

# a layout's toolkit in one import: the readers are defined beside, in annotations and images
__all__ = ["ATTRIBUTE_NAMES", "DatasetError", "DatasetWarning", "Sequence", "annotated_frames", "annotation_lines",
           "check_box_count", "count_jpgs", "first_frame_digits", "held_out_sequence", "image_sequence_folders",
           "listed", "numbered_frames", "parse_number", "read_boxes", "read_flags", "read_frame", "read_frame_values",
           "read_text", "require_root", "scored_sequences", "select_sequences", "sequence_names", "unique_names"]

log = logging.getLogger(__name__)


#: Long names of the attribute abbreviations of UAV123 (first, in the column order of its att
#: files), OTB and LaSOT; each layout module keeps its benchmark's column order.
ATTRIBUTE_NAMES = {
    "SV": "Scale Variation",
    "ARC": "Aspect Ratio Change",
    "LR": "Low Resolution",
    "FM": "Fast Motion",
    "FOC": "Full Occlusion",
    "POC": "Partial Occlusion",
    "OV": "Out-of-View",
    "BC": "Background Clutter",
    "IV": "Illumination Variation",
    "VC": "Viewpoint Change",
    "CM": "Camera Motion",
    "SOB": "Similar Object",
    "OCC": "Occlusion",
    "DEF": "Deformation",
    "MB": "Motion Blur",
    "IPR": "In-Plane Rotation",
    "OPR": "Out-of-Plane Rotation",
    "ROT": "Rotation",
}


# --------------------------------------------------------------------------- Sequence


@dataclasses.dataclass(frozen=True, eq=False)
class Sequence:
    """One benchmark sequence.

    ``frames`` holds the image paths in order; ``ground_truth`` is ``(N, 4) float64``,
    0-based ``(x, y, w, h)``, read-only, with NaN rows kept for out-of-view frames.
    ``attributes`` maps an attribute abbreviation (e.g. ``"SV"``) to whether the sequence
    has it; it is empty when the benchmark provides none. ``annotation`` is the file the
    ground truth was read from (None for sequences made in code). ``ground_truth_withheld``
    is True for a test split that publishes frame 1's box only (GOT-10k, TrackingNet): rows
    2..N are NaN, so the sequence can be tracked but not scored (:func:`scored_sequences`).
    ``start_box`` is the 0-based box the tracker starts from when it is not frame 1's ground
    truth (a run of a robustness experiment, :mod:`dcfkit.experiments`). ``cut`` is True for the
    first frames of a longer sequence (:meth:`head`: a smoke run), whose results must never
    replace the whole sequence's.
    """

    name: str
    frames: tuple[Path, ...]
    ground_truth: np.ndarray
    attributes: Mapping[str, bool] = dataclasses.field(default_factory=dict)
    dataset: str = ""
    annotation: Path | None = None
    ground_truth_withheld: bool = False
    start_box: np.ndarray | None = None
    cut: bool = False

    def __post_init__(self):
        gt = np.array(self.ground_truth, dtype=np.float64, copy=True).reshape(-1, 4)
        if len(gt) != len(self.frames):
            raise DatasetError(
                f"sequence {self.name!r}: {len(self.frames)} frames but {len(gt)} boxes")
        if not self.frames:
            raise DatasetError(f"sequence {self.name!r} has no frames"
                               + (f" ({self.annotation} holds no box)" if self.annotation else ""))
        gt.setflags(write=False)
        object.__setattr__(self, "ground_truth", gt)
        object.__setattr__(self, "frames", tuple(Path(f) for f in self.frames))
        object.__setattr__(self, "attributes", dict(self.attributes))
        if self.start_box is not None:
            object.__setattr__(self, "start_box", np.array(self.start_box, dtype=np.float64).reshape(4))

    def __len__(self) -> int:
        return len(self.frames)

    def head(self, n: int | None) -> Sequence:
        """The first ``n`` frames (all of them when ``n`` is None or not shorter): smoke runs."""
        if n is None or n >= len(self):
            return self
        if n < 1:
            raise DatasetError(f"a sequence needs at least 1 frame, got a limit of {n}")
        return dataclasses.replace(self, frames=self.frames[:n], ground_truth=self.ground_truth[:n], cut=True)

    def __repr__(self) -> str:
        flags = ",".join(k for k, v in self.attributes.items() if v)
        withheld = ", ground truth withheld" if self.ground_truth_withheld else ""
        return f"Sequence({self.dataset}/{self.name}, {len(self)} frames{withheld}{', ' + flags if flags else ''})"

    @property
    def init_box(self) -> np.ndarray:
        """The box the tracker starts from, ``(4,) float64`` 0-based: ``start_box`` if given,
        else frame 1's ground truth (which may contain NaN)."""
        return (self.ground_truth[0] if self.start_box is None else self.start_box).copy()

    def frame(self, i: int) -> np.ndarray:
        """Frame ``i`` (0-based index) as ``(H, W, 3) uint8`` BGR; a :class:`DatasetError` if
        unreadable, which numbers the frame from 1 as the benchmarks' files do."""
        return read_frame(self.frames[i], f"frame {i + 1} of sequence {self.name!r}")

    @functools.cached_property
    def image_size(self) -> tuple[int, int]:
        """``(width, height)`` of frame 1, read once per sequence (the bound of the toolkits'
        overlaps); a :class:`DatasetError` if it cannot be read."""
        height, width = self.frame(0).shape[:2]
        return width, height


# --------------------------------------------------------------------------- images


# --------------------------------------------------------------------------- annotation files


# --------------------------------------------------------------------------- frame lists


def numbered_frames(folder: Path, pattern: str, first: int, last: int, what: str) -> tuple[Path, ...]:
    """Paths ``folder / (pattern % k)`` for k in first..last; all must exist."""
    if not folder.is_dir():
        raise DatasetError(f"{what}: image folder not found: {folder}")
    present = set(os.listdir(folder))
    names = [pattern % k for k in range(first, last + 1)]
    missing = [n for n in names if n not in present]
    if missing:
        listed = ", ".join(missing[:3]) + (f" and {len(missing) - 3} more" if len(missing) > 3 else "")
        raise DatasetError(
            f"{what}: {len(missing)} of frames {pattern % first}..{pattern % last} missing "
            f"in {folder}: {listed}")
    return tuple(folder / n for n in names)


def annotated_frames(folder: Path, pattern: str, boxes: np.ndarray, anno: Path, what: str,
                     first: int = 1) -> tuple[Path, ...]:
    """Frames ``first``.. of a folder holding exactly the N annotated frames (the files of the
    ``pattern``'s type, ``.jpg`` for every benchmark but an exported one); the error names either
    the missing frames or, when the images simply run out, the annotation's length."""
    suffix = os.path.splitext(pattern)[1].lower() or ".jpg"
    n_jpgs = count_jpgs(folder, what, suffix)
    counted = f"{n_jpgs} {suffix} files in {folder}"
    last = first + len(boxes) - 1
    if n_jpgs < len(boxes) and all((folder / (pattern % k)).is_file() for k in range(first, first + n_jpgs)):
        raise DatasetError(f"{anno}: {len(boxes)} annotation lines but {counted}: either the annotation has "
                           f"extra lines or frames {pattern % (first + n_jpgs)}..{pattern % last} are missing")
    frames = numbered_frames(folder, pattern, first, last, what)
    check_box_count(boxes, n_jpgs, anno, counted)  # extra images
    return frames


def count_jpgs(folder: Path, what: str, suffix: str = ".jpg") -> int:
    """How many ``.jpg`` (or ``suffix``) files ``folder`` holds; :class:`DatasetError` if it is not
    a folder."""
    if not folder.is_dir():
        raise DatasetError(f"{what}: image folder not found: {folder}")
    return sum(1 for f in os.listdir(folder) if f.lower().endswith(suffix))


def held_out_sequence(name: str, folder: Path, pattern: str, first: int, anno: Path, dataset: str, what: str,
                      one_based: bool = True) -> Sequence:
    """A sequence of a test split: every ``.jpg`` of ``folder`` (``pattern`` numbered from
    ``first``), tracked whole, and the annotation ``anno``, which holds one box per frame or, as
    published, frame 1's only: then rows 2..N are NaN and ``ground_truth_withheld`` is set."""
    n_frames = count_jpgs(folder, what)
    frames = numbered_frames(folder, pattern, first, first + n_frames - 1, what)
    boxes = read_boxes(anno, one_based=one_based)
    withheld = len(boxes) == 1 and n_frames > 1
    if withheld:
        boxes = np.vstack([boxes, np.full((n_frames - 1, 4), np.nan)])
    else:
        check_box_count(boxes, n_frames, anno, f"{n_frames} .jpg files in {folder}; a test split's annotation may "
                                               f"also hold frame 1's box only")
    return Sequence(name, frames, boxes, {}, dataset, anno, ground_truth_withheld=withheld)


def check_box_count(boxes: np.ndarray, n_frames: int, anno: Path, frames_desc: str) -> None:
    """:class:`DatasetError` naming ``anno`` unless it has one box per frame."""
    if len(boxes) != n_frames:
        raise DatasetError(
            f"{anno}: {len(boxes)} annotation lines but {n_frames} frames ({frames_desc}); "
            f"one line per frame is required")


# --------------------------------------------------------------------------- roots and selection


def scored_sequences(sequences: Iterable[Sequence]) -> list[Sequence]:
    """The sequences whose ground truth can score a tracker: all but those whose ground truth the
    benchmark withholds after frame 1 (``ground_truth_withheld``), which are left out with a
    warning; a :class:`DatasetError` saying so when none is left (a test split, whose results
    are scored by the benchmark's server), never scores computed against NaN rows."""
    sequences = list(sequences)
    scored = [s for s in sequences if not s.ground_truth_withheld]
    withheld = [s.name for s in sequences if s.ground_truth_withheld]
    if withheld and not scored:
        dataset = sequences[0].dataset or "this dataset"
        raise DatasetError(
            f"no scores: {dataset} publishes the ground truth of frame 1 only for these {len(withheld)} sequences "
            f"(a test split: {', '.join(withheld[:5])}{' ...' if len(withheld) > 5 else ''}). Submit the result "
            f"files OUT/<tracker>/<sequence>.txt to the benchmark's evaluation server (docs/evaluation.md, "
            f"'Test splits')")
    if withheld:
        log.warning("%d of %d sequences left out of the scores: their ground truth is withheld after frame 1 "
                    "(a test split): %s", len(withheld), len(sequences), ", ".join(withheld[:10]))
    return scored


def require_root(root, what: str) -> Path:
    """``root`` as a Path (``~`` expanded); :class:`DatasetError` if it is not a folder."""
    root = Path(root).expanduser()
    if not root.is_dir():
        raise DatasetError(f"{what} root folder not found: {clip(str(root))}")
    return root


def select_sequences(available: list[str], requested: Iterable[str] | str | None, where: str,
                     annotation_of: Mapping[str, Path] | None = None) -> list[str]:
    """Names to load: all available, or the requested ones (:func:`sequence_names`; a
    case-insensitive match, each once).

    ``annotation_of`` maps the benchmark's other sequences (not available) to the annotation file
    that is missing, for a clearer error.
    """
    if requested is None:
        return available
    requested = requested if isinstance(requested, str) else list(requested)
    if not (requested.replace(",", "").strip() if isinstance(requested, str) else requested):
        raise DatasetError(f"no sequence names given for {where}")
    present = set(available)
    by_lower: dict[str, list[str]] = {}
    for name in available:
        by_lower.setdefault(name.lower(), []).append(name)
    missing = {name.lower(): path for name, path in (annotation_of or {}).items()}
    chosen = []
    for want in sequence_names(requested, f"sequences for {where}"):
        if want in present:
            chosen.append(want)
        elif len(by_lower.get(want.lower(), [])) == 1:
            chosen.append(by_lower[want.lower()][0])
        else:
            raise _not_found(want, available, where, missing.get(want.lower()))
    return unique_names(chosen, f"sequences for {where}")


def sequence_names(requested: Iterable[str] | str, where: str, error: type[DcfkitError] = DatasetError) -> list[str]:
    """The one rule for a list of sequences, from a spec or ``--sequences``: a list of names
    or one comma-separated string, each name stripped and counted once (:func:`unique_names`).
    ``error`` (naming ``where``) unless it is a non-empty list of non-blank names."""
    if isinstance(requested, str):  # "a,,b" as the shell gives it: empty items are no names
        names = [n.strip() for n in requested.split(",") if n.strip()]
    elif isinstance(requested, (list, tuple)) and all(isinstance(n, str) for n in requested):
        names = [n.strip() for n in requested]
    else:
        names = []
    if not names or not all(names):
        raise error(f"{where}: expected a non-empty list of sequence names, got {shown(requested)}")
    return unique_names(names, where)


def unique_names(names: list[str], where: str) -> list[str]:
    """``names`` each once, in order: a repeat is dropped with a :class:`DatasetWarning`, since
    a sequence counted twice weighs twice in every mean and test (and may sit in two folds)."""
    unique = list(dict.fromkeys(names))
    if len(unique) < len(names):
        repeated = [n for n, count in collections.Counter(names).items() if count > 1]
        warnings.warn(f"{where}: {', '.join(shown(n) for n in repeated[:5])}{' ...' if len(repeated) > 5 else ''} "
                      f"listed more than once: each sequence counts once ({len(unique)} in all)",
                      DatasetWarning, stacklevel=2)
    return unique


def _not_found(want: str, available: list[str], where: str, missing_annotation: Path | None) -> DatasetError:
    listed = ", ".join(available[:40]) + (" ..." if len(available) > 40 else "")
    if missing_annotation is not None:
        return DatasetError(f"sequence {shown(want)} of {where}: annotation file not found: "
                            f"{missing_annotation}. Available ({len(available)}): {listed or 'none'}")
    close = difflib.get_close_matches(want, available, n=1, cutoff=0.5)
    hint = f" Did you mean {close[0]!r}?" if close else ""
    return DatasetError(f"sequence {shown(want)} not found in {where}.{hint} "
                        f"Available ({len(available)}): {listed or 'none'}")


# --------------------------------------------------------------------------- the <seq>/img layout


def image_sequence_folders(root: Path) -> list[Path]:
    """Folders ``root/<seq>`` holding ``img/`` and a ``groundtruth_rect*.txt``: the layout that
    DTB70 and OTB share (in listing order, as detection has always sampled them). None under a
    root with ``data_seq/`` and ``anno/``: that is a UAV123 or UAVDT root, whatever else it holds."""
    if (root / "data_seq").is_dir() and (root / "anno").is_dir():
        return []
    return [p for p in root.iterdir() if p.is_dir() and (p / "img").is_dir()
            and any(p.glob("groundtruth_rect*.txt"))]


def first_frame_digits(folders: list[Path], sample: int = 10) -> set[int]:
    """Lengths of the first frame names (without extension) in the first ``sample`` ``img/``
    folders: ``{5}`` for DTB70's ``00001.jpg``, ``{4}`` for OTB's ``0001.jpg``. Hidden files
    (``.DS_Store``, macOS's ``._00001.jpg``) are no frames."""
    return {len(os.path.splitext(f)[0]) for p in folders[:sample]
            for f in sorted(n for n in os.listdir(p / "img") if not n.startswith("."))[:1]}

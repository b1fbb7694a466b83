"""Benchmark sequences: UAV123 (+@10fps, 20L), DTB70, UAVDT, OTB, each in its own layout.

Conventions
-----------
* Boxes in memory are ``(x, y, w, h)`` float64 in **0-based** pixel coordinates of the
  top-left corner. Benchmark annotation files are **1-based** (OTB convention), so the
  loaders subtract 1 from x and y (w and h are unchanged). Result files written by
  :mod:`dcfkit.evaluation` add the 1 back, so they score unchanged in the MATLAB / pysot
  toolkits.
* A row of NaN marks a frame where the target is out of view. Such rows are kept (the
  frame still exists and the tracker still sees it); :mod:`dcfkit.metrics` skips them.
* Images are decoded by OpenCV (:func:`read_frame`): ``(H, W, 3) uint8``, **BGR** channel order.

Only sequences present on disk are listed; the official UAV123 tables shipped in
``dcfkit/data`` give the image folder and frame range of each UAV123 sequence and are
read on first use. See ``docs/evaluation.md`` for the layouts.
"""
from __future__ import annotations

import csv
import dataclasses
import difflib
import functools
import importlib.resources
import io
import os
import re
from pathlib import Path
from typing import Callable, Iterable, Mapping

import numpy as np

from .errors import DcfkitError

__all__ = [
    "ATTRIBUTE_NAMES",
    "DATASETS",
    "DatasetError",
    "Sequence",
    "detect_dataset",
    "dtb70",
    "load_dataset",
    "otb",
    "read_boxes",
    "read_frame",
    "uav123",
    "uav123_10fps",
    "uav123_20l",
    "uavdt",
]


class DatasetError(DcfkitError, ValueError):
    """A benchmark folder, annotation file or sequence name is wrong (the message says where)."""


#: Long names of the UAV123 attribute abbreviations (column order of the att files).
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
}


# --------------------------------------------------------------------------- Sequence


@dataclasses.dataclass(frozen=True, eq=False)
class Sequence:
    """One benchmark sequence.

    ``frames`` holds the image paths in order; ``ground_truth`` is ``(N, 4) float64``,
    0-based ``(x, y, w, h)``, read-only, with NaN rows kept for out-of-view frames.
    ``attributes`` maps an attribute abbreviation (e.g. ``"SV"``) to whether the sequence
    has it; it is empty when the benchmark provides none. ``annotation`` is the file the
    ground truth was read from (None for sequences made in code).
    """

    name: str
    frames: tuple[Path, ...]
    ground_truth: np.ndarray
    attributes: Mapping[str, bool] = dataclasses.field(default_factory=dict)
    dataset: str = ""
    annotation: Path | None = None

    def __post_init__(self):
        gt = np.array(self.ground_truth, dtype=np.float64, copy=True).reshape(-1, 4)
        if len(gt) != len(self.frames):
            raise DatasetError(
                f"sequence {self.name!r}: {len(self.frames)} frames but {len(gt)} boxes")
        gt.setflags(write=False)
        object.__setattr__(self, "ground_truth", gt)
        object.__setattr__(self, "frames", tuple(Path(f) for f in self.frames))
        object.__setattr__(self, "attributes", dict(self.attributes))

    def __len__(self) -> int:
        return len(self.frames)

    def __repr__(self) -> str:
        flags = ",".join(k for k, v in self.attributes.items() if v)
        return f"Sequence({self.dataset}/{self.name}, {len(self)} frames{', ' + flags if flags else ''})"

    @property
    def init_box(self) -> np.ndarray:
        """Frame 0's ground truth box, ``(4,) float64`` 0-based (may contain NaN)."""
        return self.ground_truth[0].copy()

    def frame(self, i: int) -> np.ndarray:
        """Frame ``i`` (0-based) as ``(H, W, 3) uint8`` BGR; :class:`DatasetError` if unreadable."""
        return read_frame(self.frames[i], f"frame {i} of sequence {self.name!r}")


def read_frame(path: str | os.PathLike, what: str = "frame") -> np.ndarray:
    """A BGR image; :class:`DatasetError` naming the file when it is missing, not an image, or
    a truncated JPEG (``cv2.imread`` would return one grey below the cut, with a warning only).
    A JPEG that lacks just its end-of-image marker, a common defect, is read as imread would."""
    import cv2

    try:
        data = np.fromfile(os.fspath(path), np.uint8)
    except OSError as exc:
        reason = "file does not exist" if not os.path.exists(path) else exc.strerror
        raise DatasetError(f"cannot read {what}: {path} ({reason})") from None
    image = cv2.imdecode(data, cv2.IMREAD_COLOR) if data.size else None
    if image is None and _missing_end_marker(data.tobytes()):
        image = cv2.imdecode(np.concatenate([data, _JPEG_END]), cv2.IMREAD_COLOR)
        if image is not None and (image[-8:, -8:] == 128).all():  # libjpeg's fill for missing data
            raise DatasetError(f"cannot read {what}: {path} (truncated JPEG: the image data stops "
                               f"before its end)")
    if image is None:
        raise DatasetError(f"cannot read {what}: {path} (not a readable image)")
    return image


_JPEG_END = np.array([0xFF, 0xD9], np.uint8)


def _missing_end_marker(data: bytes) -> bool:
    """A JPEG whose last scan (SOS marker) has no end-of-image marker after it (markers cannot
    occur inside entropy-coded data, where 0xFF is stuffed)."""
    return data.startswith(b"\xff\xd8") and data.rfind(b"\xff\xd9") < data.rfind(b"\xff\xda")


# --------------------------------------------------------------------------- annotation files

_SEPARATORS = re.compile(r"[,\s]+")


def _read_text(path: Path) -> str:
    """A benchmark text file (UTF-8, optional BOM); :class:`DatasetError` naming it otherwise."""
    try:
        return path.read_text(encoding="utf-8-sig")
    except FileNotFoundError:
        raise DatasetError(f"annotation file not found: {path}") from None
    except UnicodeDecodeError as exc:
        raise DatasetError(f"{path}: not a text annotation file (byte {exc.start} is not UTF-8)") from None
    except OSError as exc:
        raise DatasetError(f"cannot read {path}: {exc.strerror}") from None


def read_boxes(path: str | os.PathLike, one_based: bool = True) -> np.ndarray:
    """Read one ``x,y,w,h`` box per line (commas, tabs or spaces) as ``(N, 4) float64``.

    With ``one_based`` (the benchmark convention), 1 is subtracted from x and y so the
    result is 0-based. ``NaN`` values are kept. Trailing blank lines are ignored; a blank
    or malformed line inside the file is a :class:`DatasetError` naming file and line.
    """
    path = Path(path)
    lines = _read_text(path).rstrip().splitlines()
    boxes = np.empty((len(lines), 4), dtype=np.float64)
    for n, line in enumerate(lines):
        fields = [f for f in _SEPARATORS.split(line.strip()) if f]
        try:
            if len(fields) != 4:
                raise ValueError
            boxes[n] = [float(f) for f in fields]
        except ValueError:
            raise DatasetError(
                f"{path}, line {n + 1}: expected 4 numbers 'x,y,w,h' separated by commas, "
                f"tabs or spaces, got {line.strip()!r}") from None
    if one_based:
        boxes[:, :2] -= 1.0
    return boxes


def _read_flags(path: Path, names: tuple[str, ...]) -> dict[str, bool]:
    fields = [f for f in _SEPARATORS.split(_read_text(path).strip()) if f]
    if len(fields) != len(names) or any(f not in ("0", "1") for f in fields):
        raise DatasetError(
            f"{path}, line 1: expected {len(names)} 0/1 flags ({' '.join(names)}), "
            f"got {' '.join(fields)!r}")
    return {name: f == "1" for name, f in zip(names, fields)}


# --------------------------------------------------------------------------- packaged tables


def _table_rows(filename: str) -> list[dict[str, str]]:
    text = (importlib.resources.files("dcfkit") / "data" / filename).read_text(encoding="utf-8")
    body = "\n".join(line for line in text.splitlines() if line and not line.startswith("#"))
    return list(csv.DictReader(io.StringIO(body), delimiter="\t"))


@functools.lru_cache(maxsize=None)
def _uav_table() -> dict[str, dict[str, tuple[str, int, int]]]:
    """subset -> sequence -> (folder, first frame, last frame), 1-based inclusive."""
    table: dict[str, dict[str, tuple[str, int, int]]] = {}
    for row in _table_rows("uav123_sequences.tsv"):
        table.setdefault(row["subset"], {})[row["sequence"]] = (
            row["folder"], int(row["start_frame"]), int(row["end_frame"]))
    return table


@functools.lru_cache(maxsize=None)
def _uav_attribute_table() -> tuple[tuple[str, ...], dict[str, dict[str, bool]]]:
    rows = _table_rows("uav123_attributes.tsv")
    names = tuple(k for k in rows[0] if k != "sequence")
    return names, {r["sequence"]: {k: r[k] == "1" for k in names} for r in rows}


# --------------------------------------------------------------------------- helpers


def _numbered_frames(folder: Path, pattern: str, first: int, last: int, what: str) -> tuple[Path, ...]:
    """Paths ``folder / (pattern % k)`` for k in first..last; all must exist."""
    if not folder.is_dir():
        raise DatasetError(f"{what}: image folder not found: {folder}")
    present = set(os.listdir(folder))
    names = [pattern % k for k in range(first, last + 1)]
    missing = [n for n in names if n not in present]
    if missing:
        shown = ", ".join(missing[:3]) + (f" and {len(missing) - 3} more" if len(missing) > 3 else "")
        raise DatasetError(
            f"{what}: {len(missing)} of frames {pattern % first}..{pattern % last} missing "
            f"in {folder}: {shown}")
    return tuple(folder / n for n in names)


def _annotated_frames(folder: Path, pattern: str, boxes: np.ndarray, anno: Path, what: str) -> tuple[Path, ...]:
    """Frames 1..N of a folder holding exactly the N annotated ``.jpg`` frames; the error names
    either the missing frames or, when the images simply run out, the annotation's length."""
    if not folder.is_dir():
        raise DatasetError(f"{what}: image folder not found: {folder}")
    present = set(os.listdir(folder))
    n_jpgs = sum(1 for f in present if f.lower().endswith(".jpg"))
    counted = f"{n_jpgs} .jpg files in {folder}"
    if n_jpgs < len(boxes) and all(pattern % k in present for k in range(1, n_jpgs + 1)):
        raise DatasetError(f"{anno}: {len(boxes)} annotation lines but {counted}: either the annotation has "
                           f"extra lines or frames {pattern % (n_jpgs + 1)}..{pattern % len(boxes)} are missing")
    frames = _numbered_frames(folder, pattern, 1, len(boxes), what)
    _check_count(boxes, n_jpgs, anno, counted)  # extra images
    return frames


def _check_count(boxes: np.ndarray, n_frames: int, anno: Path, frames_desc: str):
    if len(boxes) != n_frames:
        raise DatasetError(
            f"{anno}: {len(boxes)} annotation lines but {n_frames} frames ({frames_desc}); "
            f"one line per frame is required")


def _select(available: list[str], requested: Iterable[str] | None, where: str,
            annotation_of: Mapping[str, Path] | None = None) -> list[str]:
    """Names to load: all available, or the requested ones (case-insensitive match, each once).

    ``annotation_of`` maps the benchmark's other sequences (not available) to the annotation
    file that is missing, for a clearer error."""
    if requested is None:
        return available
    if isinstance(requested, str):
        requested = [s for s in requested.split(",") if s.strip()]
    if not requested:
        raise DatasetError(f"no sequence names given for {where}")
    by_lower: dict[str, list[str]] = {}
    for name in available:
        by_lower.setdefault(name.lower(), []).append(name)
    missing = {name.lower(): path for name, path in (annotation_of or {}).items()}
    chosen = []
    for want in requested:
        want = want.strip()
        if want in available:
            chosen.append(want)
        elif len(by_lower.get(want.lower(), [])) == 1:
            chosen.append(by_lower[want.lower()][0])
        else:
            shown = ", ".join(available[:40]) + (" ..." if len(available) > 40 else "")
            if want.lower() in missing:
                raise DatasetError(f"sequence {want!r} of {where}: annotation file not found: "
                                   f"{missing[want.lower()]}. Available ({len(available)}): {shown or 'none'}")
            close = difflib.get_close_matches(want, available, n=1, cutoff=0.5)
            hint = f" Did you mean {close[0]!r}?" if close else ""
            raise DatasetError(
                f"sequence {want!r} not found in {where}.{hint} "
                f"Available ({len(available)}): {shown or 'none'}")
    return list(dict.fromkeys(chosen))


def _require_dir(root: Path, what: str) -> Path:
    root = Path(root).expanduser()
    if not root.is_dir():
        raise DatasetError(f"{what} root folder not found: {root}")
    return root


# --------------------------------------------------------------------------- UAV123 family

# Folder names under data_seq/ and anno/ that hold each subset (first found wins).
# UAV20L uses the UAV123 images; its annotations are in anno/UAV20L in the official release.
_UAV_SUBSETS = {
    "UAV123": {"anno": ("UAV123",), "data": ("UAV123",)},
    "UAV123_10fps": {"anno": ("UAV123_10fps",), "data": ("UAV123_10fps",)},
    "UAV123_20L": {"anno": ("UAV20L", "UAV123_20L"), "data": ("UAV20L", "UAV123_20L", "UAV123")},
}


def _uav_layout(root: Path, subset: str) -> tuple[Path, Path]:
    """(annotation folder, image folder) for ``subset``, nested or flat variant."""
    names = _UAV_SUBSETS[subset]
    anno_root, data_root = root / "anno", root / "data_seq"
    for folder in (anno_root, data_root):
        if not folder.is_dir():
            raise DatasetError(
                f"{subset}: folder not found: {folder} (expected ROOT/data_seq and ROOT/anno "
                f"under {root})")
    anno = next((anno_root / n for n in names["anno"] if (anno_root / n).is_dir()), anno_root)
    data = next((data_root / n for n in names["data"] if (data_root / n).is_dir()), data_root)
    return anno, data


def _uav_subset(subset: str, dataset: str, root, sequences) -> list[Sequence]:
    root = _require_dir(root, subset)
    anno_dir, data_dir = _uav_layout(root, subset)
    table = _uav_table()[subset]
    available = [name for name in table if (anno_dir / f"{name}.txt").is_file()]
    attr_names, packaged = _uav_attribute_table()
    same_as_uav123 = _uav_table()["UAV123"]
    out = []
    absent = {name: anno_dir / f"{name}.txt" for name in table if name not in available}
    for name in _select(available, sequences, f"{subset} at {root}", absent):
        folder, first, last = table[name]
        anno = anno_dir / f"{name}.txt"
        boxes = read_boxes(anno)
        _check_count(boxes, last - first + 1, anno, f"{folder} {first}..{last} in the official table")
        frames = _numbered_frames(data_dir / folder, "%06d.jpg", first, last, f"{subset} {name}")
        att_file = anno_dir / "att" / f"{name}.txt"
        if att_file.is_file():
            attributes = _read_flags(att_file, attr_names)
        elif subset != "UAV123_20L" or same_as_uav123.get(name) == table[name]:
            # UAV20L sequences share attributes only with identical UAV123 sequences
            attributes = packaged.get(name, {})
        else:
            attributes = {}
        out.append(Sequence(name, frames, boxes, attributes, dataset, anno))
    return out


def uav123(root, sequences=None) -> list[Sequence]:
    """UAV123: ``ROOT/data_seq/UAV123/<folder>/%06d.jpg``, ``ROOT/anno/UAV123/<seq>.txt``."""
    return _uav_subset("UAV123", "uav123", root, sequences)


def uav123_10fps(root, sequences=None) -> list[Sequence]:
    """UAV123@10fps: ``ROOT/data_seq/UAV123_10fps/<folder>/%06d.jpg``, ``ROOT/anno/UAV123_10fps/<seq>.txt``."""
    return _uav_subset("UAV123_10fps", "uav123_10fps", root, sequences)


def uav123_20l(root, sequences=None) -> list[Sequence]:
    """UAV20L: annotations in ``ROOT/anno/UAV20L`` (or ``UAV123_20L``), images in ``data_seq/UAV123``."""
    return _uav_subset("UAV123_20L", "uav123_20l", root, sequences)


# --------------------------------------------------------------------------- DTB70, UAVDT, OTB


def dtb70(root, sequences=None) -> list[Sequence]:
    """DTB70: ``ROOT/<seq>/img/%05d.jpg`` and ``ROOT/<seq>/groundtruth_rect.txt``."""
    root = _require_dir(root, "DTB70")
    available = sorted(p.name for p in root.iterdir() if (p / "groundtruth_rect.txt").is_file())
    out = []
    for name in _select(available, sequences, f"DTB70 at {root}"):
        anno = root / name / "groundtruth_rect.txt"
        boxes = read_boxes(anno)
        img = root / name / "img"
        frames = _annotated_frames(img, "%05d.jpg", boxes, anno, f"DTB70 {name}")
        out.append(Sequence(name, frames, boxes, {}, "dtb70", anno))
    return out


def uavdt(root, sequences=None) -> list[Sequence]:
    """UAVDT (single object): ``ROOT/data_seq/<seq>/img%06d.jpg``, ``ROOT/anno/<seq>_gt.txt``."""
    root = _require_dir(root, "UAVDT")
    anno_dir = root / "anno"
    if not anno_dir.is_dir():
        raise DatasetError(f"UAVDT: folder not found: {anno_dir}")
    available = sorted(p.name[: -len("_gt.txt")] for p in anno_dir.glob("*_gt.txt"))
    out = []
    for name in _select(available, sequences, f"UAVDT at {root}"):
        anno = anno_dir / f"{name}_gt.txt"
        boxes = read_boxes(anno)
        img = root / "data_seq" / name
        frames = _annotated_frames(img, "img%06d.jpg", boxes, anno, f"UAVDT {name}")
        out.append(Sequence(name, frames, boxes, {}, "uavdt", anno))
    return out


# OTB sequences whose image folder holds more frames than are annotated (as in the
# got10k and pysot toolkits): name -> first and last image number used.
_OTB_FRAME_RANGES = {
    "David": (300, 770),
    "Football1": (1, 74),
    "Freeman3": (1, 460),
    "Freeman4": (1, 283),
    "Diving": (1, 215),
}


def _otb_targets(root: Path) -> dict[str, Path]:
    """Sequence name -> annotation file; multi-target folders give ``Name-1``, ``Name-2``."""
    targets = {}
    for folder in sorted(p for p in root.iterdir() if p.is_dir()):
        if (folder / "groundtruth_rect.txt").is_file():
            targets[folder.name] = folder / "groundtruth_rect.txt"
            continue
        numbered = sorted(
            (p for p in folder.glob("groundtruth_rect.*.txt") if _read_text(p).strip()),
            key=lambda p: p.name)
        if len(numbered) == 1:
            targets[folder.name] = numbered[0]
        else:
            for p in numbered:
                targets[f"{folder.name}-{p.name.split('.')[1]}"] = p
    return targets


def otb(root, sequences=None) -> list[Sequence]:
    """OTB-2013/2015: ``ROOT/<seq>/img/*.jpg`` and ``ROOT/<seq>/groundtruth_rect.txt``.

    Multi-target sequences (``groundtruth_rect.1.txt`` …) are named ``Jogging-1`` etc.;
    David, Football1, Freeman3, Freeman4 and Diving use the frame ranges of the OTB toolkit.
    """
    root = _require_dir(root, "OTB")
    targets = _otb_targets(root)
    out = []
    for name in _select(sorted(targets), sequences, f"OTB at {root}"):
        anno = targets[name]
        boxes = read_boxes(anno)
        img = anno.parent / "img"
        if not img.is_dir():
            raise DatasetError(f"OTB {name}: image folder not found: {img}")
        numbered = {}
        for f in os.listdir(img):
            stem, ext = os.path.splitext(f)
            if ext.lower() == ".jpg" and stem.isdigit():
                if int(stem) in numbered:
                    raise DatasetError(f"OTB {name}: {numbered[int(stem)].name} and {f} in {img} are both "
                                       f"frame {int(stem)}")
                numbered[int(stem)] = img / f
        if anno.parent.name in _OTB_FRAME_RANGES:
            first, last = _OTB_FRAME_RANGES[anno.parent.name]
            _check_count(boxes, last - first + 1, anno, f"frames {first}..{last}, as in the OTB toolkit")
        else:
            _check_count(boxes, len(numbered), anno, f"{len(numbered)} numbered .jpg files in {img}")
            first = min(numbered, default=1)
            last = first + len(boxes) - 1
        missing = [k for k in range(first, last + 1) if k not in numbered]
        if missing:
            raise DatasetError(
                f"OTB {name}: frames {missing[:3]}{' ...' if len(missing) > 3 else ''} "
                f"missing in {img} (expected frames {first}..{last})")
        frames = tuple(numbered[k] for k in range(first, last + 1))
        out.append(Sequence(name, frames, boxes, {}, "otb", anno))
    return out


# --------------------------------------------------------------------------- registry + detection

DATASETS: dict[str, Callable[..., list[Sequence]]] = {
    "uav123": uav123,
    "uav123_10fps": uav123_10fps,
    "uav123_20l": uav123_20l,
    "dtb70": dtb70,
    "uavdt": uavdt,
    "otb": otb,
}

_ALIASES = {
    "uav123@10fps": "uav123_10fps",
    "uav123_10": "uav123_10fps",
    "uav10fps": "uav123_10fps",
    "uav20l": "uav123_20l",
    "uav123@20l": "uav123_20l",
    "otb100": "otb",
    "otb2015": "otb",
    "otb2013": "otb",
    "otb50": "otb",
}


def canonical_name(name: str) -> str:
    """Canonical dataset name for ``name`` (case-insensitive, ``-``/``@`` accepted)."""
    key = str(name).strip().lower()
    key = _ALIASES.get(key, key)
    key = _ALIASES.get(key.replace("-", "_"), key.replace("-", "_"))
    if key not in DATASETS:
        raise DatasetError(
            f"unknown dataset {name!r}; valid names: {', '.join(DATASETS)} "
            f"(case-insensitive)")
    return key


def load_dataset(name: str | None, root, sequences: Iterable[str] | str | None = None) -> list[Sequence]:
    """Sequences of dataset ``name`` under ``root`` (all present ones, or those named).

    ``name`` is case-insensitive; ``None`` or ``"auto"`` uses :func:`detect_dataset`.
    ``sequences`` may be a list of names or one comma-separated string.
    """
    if name is None or str(name).lower() == "auto":
        name = detect_dataset(root)
    key = canonical_name(name)
    loaded = DATASETS[key](root, sequences)
    if not loaded:
        doc = ((DATASETS[key].__doc__ or "").splitlines() or [""])[0].partition(":")[2]  # layout (if docstrings)
        layout = f"; expected {doc.strip().rstrip('.').replace('``', '')}" if doc else ""
        raise DatasetError(f"no {key} sequences under {root}{layout}")
    return loaded


def _uav_subset_by_length(anno_dir: Path) -> set[str]:
    """UAV subsets consistent with the annotation files' names and line counts."""
    table = _uav_table()
    candidates = set(_UAV_SUBSETS)
    for anno in sorted(anno_dir.glob("*.txt"))[:5]:
        n = len(_read_text(anno).rstrip().splitlines())
        match = {s for s in table if anno.stem in table[s]
                 and table[s][anno.stem][2] - table[s][anno.stem][1] + 1 == n}
        candidates &= match
    return candidates


def detect_dataset(root) -> str:
    """Dataset name from the folder layout under ``root``; :class:`DatasetError` if ambiguous."""
    root = _require_dir(root, "dataset")
    anno, data = root / "anno", root / "data_seq"
    if anno.is_dir() and data.is_dir():
        if any(anno.glob("*_gt.txt")):
            return "uavdt"
        found = []
        for subset, names in _UAV_SUBSETS.items():
            if any((anno / n).is_dir() for n in names["anno"]):
                found.append(subset)
        if len(found) == 1:
            return canonical_name(found[0])
        if not found:  # flat variant: anno/<seq>.txt, decide by sequence lengths
            found = sorted(_uav_subset_by_length(anno))
            if len(found) == 1:
                return canonical_name(found[0])
        raise DatasetError(
            f"cannot tell which UAV123 subset {root} holds (candidates: "
            f"{', '.join(found) or 'none'}); pass the dataset name (uav123, uav123_10fps, uav123_20l)")
    seq_dirs = [p for p in root.iterdir() if p.is_dir() and (p / "img").is_dir()
                and any(p.glob("groundtruth_rect*.txt"))]
    if seq_dirs:
        hint = root.name.lower()
        if "dtb" in hint:
            return "dtb70"
        if "otb" in hint or "tb100" in hint or "tb50" in hint:
            return "otb"
        widths = {len(os.path.splitext(f)[0]) for p in seq_dirs[:10]
                  for f in sorted(os.listdir(p / "img"))[:1]}
        if widths == {5}:
            return "dtb70"
        if widths == {4}:
            return "otb"
        raise DatasetError(
            f"{root} has the <seq>/img + groundtruth_rect.txt layout shared by DTB70 and OTB "
            f"and the frame names do not tell which; pass the dataset name (dtb70 or otb)")
    raise DatasetError(
        f"no known benchmark layout under {root}: expected data_seq/ + anno/ (UAV123, UAVDT) "
        f"or <seq>/img/ + groundtruth_rect.txt (DTB70, OTB)")

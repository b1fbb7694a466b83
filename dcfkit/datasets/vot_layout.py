"""VOT (VOT2013 to VOT2022, short- and long-term): ``ROOT/<seq>/groundtruth.txt``, one region a
frame, with the images in ``ROOT/<seq>/color/%08d.jpg`` (VOT2020 on, or where the ``sequence``
file's ``channels.color`` says) or ``ROOT/<seq>/%08d.jpg`` (up to VOT2019); ``ROOT/list.txt``.

Regions are in **0-based** image coordinates (the VOT toolkit rasterises a rectangle at array
index ``round(x)`` and offsets masks by array indices), so they are read unchanged:

* ``x,y,w,h``: a rectangle, as it is; NaN values (an absent target in VOT-LT) give a NaN row.
* ``x1,y1,x2,y2,...`` (6 or more values, an even count): a polygon, turned into an axis-aligned
  box by one of :data:`POLYGON_RULES` (:func:`polygon_box`).
* ``m<x0>,<y0>,<w>,<h>,<run lengths>`` (VOT2020 on): a segmentation mask, turned into the
  smallest box holding its pixels (:func:`mask_box`); an empty mask (no target) gives a NaN row.

Per-frame tags (``*.tag``, ``*.label``) are not read: dcfkit's attributes are per sequence.
"""
from __future__ import annotations

import posixpath
import re
from pathlib import Path

import numpy as np

from dcfkit.datasets.annotations import annotation_lines, listed, parse_number, read_text
from dcfkit.datasets.base import DatasetError, Sequence, annotated_frames, require_root, select_sequences
from dcfkit.datasets.layout import Evidence, register_layout
from dcfkit.errors import shown

#: How a polygon becomes a box: ``bounds`` the smallest box holding it (the VOT toolkit's
#: ``Polygon.convert(RegionType.RECTANGLE)``, pytracking's VOT loader); ``area`` pysot's
#: ``get_axis_aligned_bbox`` (and the got10k toolkit's VOT corners-to-rectangle): a box centred on
#: the corners' mean, the bounds scaled to the polygon's area, plus 1 in w and h. Its corner is
#: got10k's ``_corner2rect`` (``cx - w/2``); pysot's test scripts place it at ``cx - (w-1)/2``,
#: half a pixel to the right and down.
POLYGON_RULES = ("bounds", "area")
# one integer field of at most 99 digits, as in color/%08d.jpg
_PATTERN = re.compile(r"^[^%]*%(?:0?\d{1,2})?d[^%]*$", re.ASCII)
_MASK = re.compile(r"-?\d{1,10}(?:,-?\d{1,10}){3,}", re.ASCII)  # x0,y0,w,h,runs...: int64 holds their sums
_SEPARATORS = re.compile(r"[,\s]+")  # VOT writes commas; some copies have tabs or spaces
_GOT10K_FILES = ("meta_info.ini", "absence.label", "cover.label")  # GOT-10k's folders are otherwise VOT-like


def polygon_box(points: np.ndarray, rule: str = "bounds") -> np.ndarray:
    """The ``(4,)`` box ``x, y, w, h`` of a ``(K, 2)`` polygon under ``rule`` (NaN if a corner
    is NaN); ValueError for ``area`` with other than 4 corners or a polygon without area."""
    if np.isnan(points).any():
        return np.full(4, np.nan)
    low, high = points.min(axis=0), points.max(axis=0)
    if rule == "bounds":
        return np.concatenate([low, high - low])
    if len(points) != 4:
        raise ValueError(f"the 'area' rule takes 4 corners, not {len(points)} (use the 'bounds' rule: layout vot)")
    extent = high - low
    if extent.prod() <= 0:
        raise ValueError("the polygon has no area")
    area = np.linalg.norm(points[0] - points[1]) * np.linalg.norm(points[1] - points[2])
    size = np.sqrt(area / extent.prod()) * extent + 1
    return np.concatenate([points.mean(axis=0) - size / 2, size])


def mask_box(text: str) -> np.ndarray:
    """The box of a VOT mask ``x0,y0,w,h,run,run,...`` (the ``m`` removed): runs of 0s and 1s
    alternate, row by row, in the ``w`` x ``h`` region at ``(x0, y0)``. The box holds every
    pixel set: ``x = x0 + first column``, ``w = last - first column + 1`` (the VOT toolkit's
    ``Mask.convert`` gives ``last - first``). NaN if none is set; ValueError if malformed."""
    if not _MASK.fullmatch(text):
        raise ValueError("a mask is whole numbers x0,y0,w,h,runs... of at most 10 digits each")
    fields = [int(f) for f in text.split(",")]
    x0, y0, width, height = fields[:4]
    runs = np.array(fields[4:], dtype=np.int64)
    if width < 0 or height < 0 or (runs < 0).any():
        raise ValueError("negative size or run length")
    ends = np.cumsum(runs)
    if len(runs) and ends[-1] > width * height:
        raise ValueError(f"the run lengths add up to {ends[-1]}, more than the {width}x{height} region holds")
    ones = (np.arange(len(runs)) % 2 == 1) & (runs > 0)
    if not ones.any():
        return np.full(4, np.nan)
    first, last = (ends - runs)[ones], ends[ones] - 1  # pixel indices (row-major) of each run of 1s
    top, bottom = first // width, last // width
    wraps = bottom > top  # a run over a row's end covers every column
    left = np.where(wraps, 0, first % width).min()
    right = np.where(wraps, width - 1, last % width).max()
    return np.array([x0 + left, y0 + top.min(), right - left + 1, bottom.max() - top.min() + 1], dtype=np.float64)


def region_box(line: str, rule: str = "bounds") -> np.ndarray:
    """The ``(4,)`` 0-based box of one ``groundtruth.txt`` line (values separated by commas, tabs
    or spaces; a mask by commas); ValueError if malformed."""
    text = line.strip()
    if text.startswith("m"):
        return mask_box(text[1:])
    values = [parse_number(f) for f in _SEPARATORS.split(text) if f]
    if len(values) == 4:
        return np.array(values, dtype=np.float64)
    if len(values) >= 6 and len(values) % 2 == 0:
        return polygon_box(np.array(values).reshape(-1, 2), rule)
    raise ValueError(f"{len(values)} values")


def read_regions(path: Path, rule: str = "bounds") -> np.ndarray:
    """``(N, 4) float64`` boxes of a VOT ``groundtruth.txt``; :class:`DatasetError` naming file
    and line for a line that is no region."""
    text = read_text(path).rstrip()
    lines = annotation_lines(text) if text else []
    boxes = np.empty((len(lines), 4), dtype=np.float64)
    for n, line in enumerate(lines):
        try:
            boxes[n] = region_box(line, rule)
        except ValueError as exc:
            raise DatasetError(f"{path}, line {n + 1}: expected a region (x,y,w,h; a polygon x1,y1,x2,y2,... of 6 "
                               f"or more values, an even count; or a mask m<x0>,<y0>,<w>,<h>,<runs>), got "
                               f"{shown(line.strip())}: {exc}") from None
    return boxes


def read_properties(path: Path) -> dict[str, str]:
    """``key=value`` lines of a VOT ``sequence`` file (others ignored)."""
    pairs = (line.split("=", 1) for line in read_text(path).splitlines() if "=" in line)
    return {key.strip(): value.strip() for key, value in pairs}


def image_pattern(folder: Path) -> str:
    """Where the frames are, relative to the sequence folder: the ``sequence`` file's
    ``channels.color`` (a folder means ``<folder>/%08d.jpg``); without a ``sequence`` file or a
    channel in it, ``color/%08d.jpg`` if that folder exists, else ``%08d.jpg``."""
    meta = folder / "sequence"
    channels = {k: v for k, v in read_properties(meta).items() if k.startswith("channels.")} if meta.is_file() else {}
    if not channels:  # as the VOT toolkit: no channel listed, the default one
        return "color/%08d.jpg" if (folder / "color").is_dir() else "%08d.jpg"
    if "channels.color" not in channels:
        raise DatasetError(f"{meta}: no channels.color entry (dcfkit reads the color channel; channels: "
                           f"{', '.join(channels)})")
    pattern = channels["channels.color"].replace("\\", "/")
    if not posixpath.splitext(pattern)[1]:
        pattern = posixpath.join(pattern, "%08d.jpg")
    parts = pattern.split("/")
    if pattern.startswith("/") or ".." in parts or not _PATTERN.match(pattern) or "%" in "/".join(parts[:-1]):
        raise DatasetError(f"{meta}: channels.color={channels['channels.color']!r} is not a frame pattern inside "
                           f"the sequence folder such as color/%08d.jpg")
    return pattern


def _load_sequence(name: str, folder: Path, rule: str, dataset: str) -> Sequence:
    anno = folder / "groundtruth.txt"
    boxes = read_regions(anno, rule)
    subfolder, file_pattern = posixpath.split(image_pattern(folder))
    frames = annotated_frames(folder / subfolder, file_pattern, boxes, anno, f"VOT {name}")
    return Sequence(name, frames, boxes, {}, dataset, anno)


def _load(root, sequences, rule: str, dataset: str) -> list[Sequence]:
    root = require_root(root, "VOT")
    available = sorted(p.name for p in root.iterdir() if listed(p / "groundtruth.txt"))
    return [_load_sequence(name, root / name, rule, dataset)
            for name in select_sequences(available, sequences, f"VOT at {root}")]


def vot(root, sequences=None) -> list[Sequence]:
    """VOT sequences, a polygon turned into the smallest box holding it (rule ``bounds``)."""
    return _load(root, sequences, "bounds", "vot")


def vot_area(root, sequences=None) -> list[Sequence]:
    """VOT sequences, a polygon turned into pysot's box of the same area (rule ``area``)."""
    return _load(root, sequences, "area", "vot_area")


def _looks_like_vot(folder: Path) -> bool:
    has_frames = (folder / "color").is_dir() or (folder / "sequence").is_file() or (folder / "00000001.jpg").is_file()
    return has_frames and not any((folder / f).is_file() for f in _GOT10K_FILES)


def detect_vot(root: Path) -> Evidence:
    """Sequence folders with ``groundtruth.txt`` and ``color/``, a ``sequence`` file or
    ``00000001.jpg``: by the root's name (``vot``), else by ``list.txt``, else by folders only."""
    sample = [p for p in sorted(root.iterdir()) if (p / "groundtruth.txt").is_file()][:5]
    if not sample or not all(_looks_like_vot(p) for p in sample):
        return Evidence.NONE
    if "vot" in root.name.lower():
        return Evidence.NAME
    return Evidence.FILES if (root / "list.txt").is_file() else Evidence.FOLDERS


register_layout("vot", vot, "ROOT/<seq>/color/%08d.jpg (or ROOT/<seq>/%08d.jpg), ROOT/<seq>/groundtruth.txt "
                "(rectangles, polygons as their bounding box, masks), ROOT/list.txt, 0-based", detect=detect_vot)
register_layout("vot_area", vot_area, "vot's layout, polygons as pysot's box of the same area around their centre")

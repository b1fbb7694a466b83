"""UAV123 and its subsets UAV123@10fps and UAV20L: ``ROOT/data_seq/<subset>/<folder>/%06d.jpg``
and ``ROOT/anno/<subset>/<seq>.txt`` (or without the ``<subset>`` folders).

Which image folder and frame range each sequence uses comes from the official table shipped
in ``dcfkit/data``, read on first use; so do the attributes when there is no att file.
"""
from __future__ import annotations

import csv
import functools
import importlib.resources
import io
from pathlib import Path
from typing import Callable

from dcfkit.datasets.annotations import listed, read_boxes, read_flags, read_text
from dcfkit.datasets.base import (
    DatasetError,
    Sequence,
    check_box_count,
    numbered_frames,
    require_root,
    select_sequences,
)
from dcfkit.datasets.layout import Evidence, register_layout

# Folder names under data_seq/ and anno/ that hold each subset (first found wins).
# UAV20L uses the UAV123 images; its annotations are in anno/UAV20L in the official release.
_SUBSET_FOLDERS = {
    "UAV123": {"anno": ("UAV123",), "data": ("UAV123",)},
    "UAV123_10fps": {"anno": ("UAV123_10fps",), "data": ("UAV123_10fps",)},
    "UAV123_20L": {"anno": ("UAV20L", "UAV123_20L"), "data": ("UAV20L", "UAV123_20L", "UAV123")},
}


# --------------------------------------------------------------------------- packaged tables


def _table_rows(filename: str) -> list[dict[str, str]]:
    # anchored on the dcfkit package: the tables stay in dcfkit/data, shared by all of dcfkit
    text = (importlib.resources.files("dcfkit") / "data" / filename).read_text(encoding="utf-8")
    body = "\n".join(line for line in text.splitlines() if line and not line.startswith("#"))
    return list(csv.DictReader(io.StringIO(body), delimiter="\t"))


@functools.lru_cache(maxsize=None)
def uav123_sequence_table() -> dict[str, dict[str, tuple[str, int, int]]]:
    """The official table: subset -> sequence -> (image folder, first frame, last frame),
    1-based inclusive."""
    table: dict[str, dict[str, tuple[str, int, int]]] = {}
    for row in _table_rows("uav123_sequences.tsv"):
        table.setdefault(row["subset"], {})[row["sequence"]] = (
            row["folder"], int(row["start_frame"]), int(row["end_frame"]))
    return table


@functools.lru_cache(maxsize=None)
def _attribute_table() -> tuple[tuple[str, ...], dict[str, dict[str, bool]]]:
    """(attribute names in column order, sequence -> attribute -> flag) of all UAV123 sequences."""
    rows = _table_rows("uav123_attributes.tsv")
    names = tuple(k for k in rows[0] if k != "sequence")
    return names, {r["sequence"]: {k: r[k] == "1" for k in names} for r in rows}


# --------------------------------------------------------------------------- loading


def _subset_folders(root: Path, subset: str) -> tuple[Path, Path]:
    """(annotation folder, image folder) for ``subset``, nested or flat variant."""
    names = _SUBSET_FOLDERS[subset]
    anno_root, data_root = root / "anno", root / "data_seq"
    for folder in (anno_root, data_root):
        if not folder.is_dir():
            raise DatasetError(
                f"{subset}: folder not found: {folder} (expected ROOT/data_seq and ROOT/anno "
                f"under {root})")
    anno = next((anno_root / n for n in names["anno"] if (anno_root / n).is_dir()), anno_root)
    data = next((data_root / n for n in names["data"] if (data_root / n).is_dir()), data_root)
    return anno, data


def _attributes(subset: str, name: str, anno_dir: Path) -> dict[str, bool]:
    """The att file's flags if there is one, else the packaged ones (or none)."""
    attr_names, packaged = _attribute_table()
    att_file = anno_dir / "att" / f"{name}.txt"
    if att_file.is_file():
        return read_flags(att_file, attr_names)
    table = uav123_sequence_table()
    if subset != "UAV123_20L" or table["UAV123"].get(name) == table[subset][name]:
        # UAV20L sequences share attributes only with identical UAV123 sequences
        return packaged.get(name, {})
    return {}


def _load_subset(subset: str, dataset: str, root, sequences) -> list[Sequence]:
    root = require_root(root, subset)
    anno_dir, data_dir = _subset_folders(root, subset)
    table = uav123_sequence_table()[subset]
    available = [name for name in table if listed(anno_dir / f"{name}.txt")]
    absent = {name: anno_dir / f"{name}.txt" for name in table if name not in available}
    out = []
    for name in select_sequences(available, sequences, f"{subset} at {root}", absent):
        folder, first, last = table[name]
        anno = anno_dir / f"{name}.txt"
        boxes = read_boxes(anno)
        check_box_count(boxes, last - first + 1, anno, f"{folder} {first}..{last} in the official table")
        frames = numbered_frames(data_dir / folder, "%06d.jpg", first, last, f"{subset} {name}")
        out.append(Sequence(name, frames, boxes, _attributes(subset, name, anno_dir), dataset, anno))
    return out


def uav123(root, sequences=None) -> list[Sequence]:
    """UAV123: ``ROOT/data_seq/UAV123/<folder>/%06d.jpg``, ``ROOT/anno/UAV123/<seq>.txt``."""
    return _load_subset("UAV123", "uav123", root, sequences)


def uav123_10fps(root, sequences=None) -> list[Sequence]:
    """UAV123@10fps: ``ROOT/data_seq/UAV123_10fps/<folder>/%06d.jpg``, ``ROOT/anno/UAV123_10fps/<seq>.txt``."""
    return _load_subset("UAV123_10fps", "uav123_10fps", root, sequences)


def uav123_20l(root, sequences=None) -> list[Sequence]:
    """UAV20L: annotations in ``ROOT/anno/UAV20L`` (or ``UAV123_20L``), images in ``data_seq/UAV123``."""
    return _load_subset("UAV123_20L", "uav123_20l", root, sequences)


# --------------------------------------------------------------------------- detection


def _subsets_by_length(anno_dir: Path) -> set[str]:
    """Subsets consistent with the names and line counts of the (first five) annotation files."""
    table = uav123_sequence_table()
    candidates = set(_SUBSET_FOLDERS)
    for anno in sorted(anno_dir.glob("*.txt"))[:5]:
        n = len(read_text(anno).rstrip().splitlines())
        candidates &= {s for s in table if anno.stem in table[s]
                       and table[s][anno.stem][2] - table[s][anno.stem][1] + 1 == n}
    return candidates


def _subset_evidence(root: Path) -> dict[str, Evidence]:
    """How specifically ``root`` looks like each subset (absent: not at all)."""
    anno = root / "anno"
    # anno/<seq>_gt.txt is UAVDT's naming: such a root has always been taken for UAVDT
    if not (anno.is_dir() and (root / "data_seq").is_dir()) or any(anno.glob("*_gt.txt")):
        return {}
    named = [s for s, names in _SUBSET_FOLDERS.items() if any((anno / n).is_dir() for n in names["anno"])]
    if named:
        return dict.fromkeys(named, Evidence.NAME)
    # flat variant (anno/<seq>.txt): the sequence lengths tell the subsets apart
    by_length = _subsets_by_length(anno)
    return {s: Evidence.FILES if s in by_length else Evidence.FOLDERS for s in _SUBSET_FOLDERS}


def _detector(subset: str) -> Callable[[Path], Evidence]:
    """The ``detect`` of one subset (the three are told apart together, by :func:`_subset_evidence`)."""
    def detect(root: Path) -> Evidence:
        return _subset_evidence(root).get(subset, Evidence.NONE)
    return detect


register_layout("uav123", uav123, "ROOT/data_seq/UAV123/<folder>/%06d.jpg, ROOT/anno/UAV123/<seq>.txt",
                detect=_detector("UAV123"))
register_layout("uav123_10fps", uav123_10fps,
                "ROOT/data_seq/UAV123_10fps/<folder>/%06d.jpg, ROOT/anno/UAV123_10fps/<seq>.txt",
                detect=_detector("UAV123_10fps"), aliases=("uav123@10fps", "uav123_10", "uav10fps"))
register_layout("uav123_20l", uav123_20l,
                "ROOT/data_seq/UAV123/<folder>/%06d.jpg (or UAV20L/), ROOT/anno/UAV20L/<seq>.txt (or UAV123_20L/)",
                detect=_detector("UAV123_20L"), aliases=("uav20l", "uav123@20l"))

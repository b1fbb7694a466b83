"""UAVDT, single-object tracking: ``ROOT/data_seq/<seq>/img%06d.jpg``, ``ROOT/anno/<seq>_gt.txt``."""
from __future__ import annotations

from pathlib import Path

from dcfkit.datasets.annotations import read_boxes
from dcfkit.datasets.base import DatasetError, Sequence, annotated_frames, require_root, select_sequences
from dcfkit.datasets.layout import Evidence, register_layout


def uavdt(root, sequences=None) -> list[Sequence]:
    """UAVDT (single object): ``ROOT/data_seq/<seq>/img%06d.jpg``, ``ROOT/anno/<seq>_gt.txt``."""
    root = require_root(root, "UAVDT")
    anno_dir = root / "anno"
    if not anno_dir.is_dir():
        raise DatasetError(f"UAVDT: folder not found: {anno_dir}")
    available = sorted(p.name[: -len("_gt.txt")] for p in anno_dir.glob("*_gt.txt"))
    out = []
    for name in select_sequences(available, sequences, f"UAVDT at {root}"):
        anno = anno_dir / f"{name}_gt.txt"
        boxes = read_boxes(anno)
        frames = annotated_frames(root / "data_seq" / name, "img%06d.jpg", boxes, anno, f"UAVDT {name}")
        out.append(Sequence(name, frames, boxes, {}, "uavdt", anno))
    return out


def detect_uavdt(root: Path) -> Evidence:
    """UAV123's data_seq/ + anno/ folders, told apart by the ``_gt.txt`` annotation names."""
    anno = root / "anno"
    if anno.is_dir() and (root / "data_seq").is_dir() and any(anno.glob("*_gt.txt")):
        return Evidence.FILES
    return Evidence.NONE


register_layout("uavdt", uavdt, "ROOT/data_seq/<seq>/img%06d.jpg, ROOT/anno/<seq>_gt.txt (single object)",
                detect=detect_uavdt)

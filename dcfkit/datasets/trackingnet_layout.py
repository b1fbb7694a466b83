"""TrackingNet: chunk folders ``ROOT/TEST`` and ``ROOT/TRAIN_0`` … ``ROOT/TRAIN_11`` (any case),
each holding ``frames/<seq>/<i>.jpg`` numbered from 0 and ``anno/<seq>.txt``; ROOT may also
be one chunk folder.

Boxes are ``x,y,w,h`` a line, **0-based** pixels (the devkit's ``generate_BB_frames.py`` draws
them at ``int(x)`` on the image array; they come from YouTube-BB's fractions of the image
width), so they are read as they are; some stick out of the image, with negative x or y.
TEST publishes frame 0's box only: its sequences are tracked over every frame and marked
``ground_truth_withheld`` (results go to the server, 0-based: see docs/evaluation.md).
"""
from __future__ import annotations

import re
from pathlib import Path

from dcfkit.datasets.annotations import read_boxes
from dcfkit.datasets.base import (
    DatasetError,
    Sequence,
    annotated_frames,
    held_out_sequence,
    require_root,
    select_sequences,
)
from dcfkit.datasets.layout import Evidence, register_layout

_TRAIN_CHUNK = re.compile(r"^train_\d+$", re.IGNORECASE)


def _is_chunk(folder: Path) -> bool:
    return (folder / "frames").is_dir() and (folder / "anno").is_dir()


def chunk_folders(root: Path, test: bool) -> list[Path]:
    """The TEST chunk (``test``) or the TRAIN_<k> chunks under ``root``, or ``root`` itself when
    it is such a chunk."""
    def wanted(folder: Path) -> bool:
        return folder.name.lower() == "test" if test else _TRAIN_CHUNK.match(folder.name) is not None
    if wanted(root) and _is_chunk(root):
        return [root]
    return sorted((p for p in root.iterdir() if wanted(p) and _is_chunk(p)),
                  key=lambda p: int(p.name.split("_")[1]) if not test else 0)


def _train_sequence(name: str, chunk: Path) -> Sequence:
    anno = chunk / "anno" / f"{name}.txt"
    boxes = read_boxes(anno, one_based=False)
    frames = annotated_frames(chunk / "frames" / name, "%d.jpg", boxes, anno, f"TrackingNet {name}", first=0)
    return Sequence(name, frames, boxes, {}, "trackingnet_train", anno)


def _test_sequence(name: str, chunk: Path) -> Sequence:
    return held_out_sequence(name, chunk / "frames" / name, "%d.jpg", 0, chunk / "anno" / f"{name}.txt",
                             "trackingnet", f"TrackingNet {name}", one_based=False)


def _sequences_in(chunks: list[Path]) -> dict[str, Path]:
    """Sequence name -> its chunk, for every ``anno/<seq>.txt``."""
    found: dict[str, Path] = {}
    for chunk in chunks:
        for anno in sorted((chunk / "anno").glob("*.txt")):
            if anno.stem in found:
                raise DatasetError(f"TrackingNet: sequence {anno.stem!r} is in both {found[anno.stem]} and {chunk}")
            found[anno.stem] = chunk
    return found


def _load(root, sequences, test: bool) -> list[Sequence]:
    what = "TrackingNet TEST" if test else "TrackingNet TRAIN"
    root = require_root(root, what)
    chunks = chunk_folders(root, test)
    if not chunks:
        raise DatasetError(f"{what}: no chunk folder ({'TEST' if test else 'TRAIN_<k>'} with frames/ and anno/) "
                           f"under {root}, and it is not one itself")
    found = _sequences_in(chunks)
    load_one = _test_sequence if test else _train_sequence
    return [load_one(name, found[name]) for name in select_sequences(list(found), sequences, f"{what} at {root}")]


def trackingnet(root, sequences=None) -> list[Sequence]:
    """TrackingNet's test set: ``ROOT/TEST/frames/<seq>/%d.jpg``, ``ROOT/TEST/anno/<seq>.txt``."""
    return _load(root, sequences, test=True)


def trackingnet_train(root, sequences=None) -> list[Sequence]:
    """TrackingNet's training chunks: ``ROOT/TRAIN_<k>/frames/<seq>/%d.jpg``, ``anno/<seq>.txt``."""
    return _load(root, sequences, test=False)


def _detector(test: bool):
    def detect(root: Path) -> Evidence:
        return Evidence.NAME if chunk_folders(root, test) else Evidence.NONE
    return detect


register_layout("trackingnet", trackingnet, "ROOT/TEST/frames/<seq>/%d.jpg (from 0), ROOT/TEST/anno/<seq>.txt "
                "(frame 0's box only: scored by the server), 0-based", detect=_detector(test=True))
register_layout("trackingnet_train", trackingnet_train, "ROOT/TRAIN_<k>/frames/<seq>/%d.jpg (from 0), "
                "ROOT/TRAIN_<k>/anno/<seq>.txt, 0-based", detect=_detector(test=False))

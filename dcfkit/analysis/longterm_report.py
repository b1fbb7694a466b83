"""The long-term table of ``dcfkit report``: VOT-LT tracking precision, recall and F per tracker.

:func:`score_long_term` reads each tracker's ``<seq>.confidence`` files
(:func:`dcfkit.store.results.read_confidence`) beside the boxes the report scores and applies
:func:`dcfkit.analysis.longterm.long_term_scores`; :func:`long_term_files` writes
``longterm.txt``, ``.md``, ``.csv`` and the curves, ``longterm_curves.csv``. A tracker without a
confidence file for a scored sequence (imported or published results), or with one that is
malformed, is left out of the long-term table, with the reason under it and in ``report.json``:
its OTB scores are still reported. Only one-pass runs (OPE) are scored: a TRE or SRE run starts
mid-sequence or from a shifted box, which the measures do not define; the report says so.
"""
from __future__ import annotations

import csv
import io
import logging
from pathlib import Path
from typing import Mapping
from typing import Sequence as Seq

import numpy as np

from dcfkit.analysis.latex import long_term_table
from dcfkit.analysis.longterm import RESOLUTION, frame_overlaps, long_term_scores, predicted_scores
from dcfkit.analysis.setting import experiment_line
from dcfkit.analysis.tables import format_rows
from dcfkit.datasets import DatasetError, Sequence
from dcfkit.errors import DcfkitError, clip
from dcfkit.experiments import Experiment, get_experiment
from dcfkit.store.results import ResultStore, read_confidence

__all__ = ["LONG_TERM_COLUMNS", "LONG_TERM_FILES", "MEASURES", "long_term_files", "long_term_lines",
           "long_term_output", "score_long_term"]

log = logging.getLogger(__name__)

MEASURES = ("long-term measures: tracking precision Pr, recall Re and F = max over thresholds tau of "
            "2 Pr Re / (Pr + Re) (Lukezic et al. 2018, 'Now you see me'; vot-toolkit 0.9 longterm.py), per-sequence "
            f"curves averaged over sequences, {RESOLUTION} thresholds from the tracker's confidences (column 3 "
            "'score' of <seq>.confidence, else column 1 'peak'), vot-toolkit overlaps (rounded boxes, bounded by "
            "the image); frame 1 counts in Re only")
LONG_TERM_COLUMNS = ("tracker", "f", "precision", "recall", "threshold", "sequences", "absent")
LONG_TERM_FILES = ("longterm.txt", "longterm.md", "longterm.csv", "longterm_curves.csv")


class NoConfidence(DatasetError):
    """A tracker's results have no confidence file (imported or published results): not damage."""


def score_long_term(folders: Mapping[str, Path], results: Mapping[str, Mapping], sequences: Seq[Sequence],
                    experiment: str | Experiment = "ope") -> dict:
    """The ``long_term`` record of a report: ``rows`` (best F first: ``f``, ``precision``, ``recall``,
    ``threshold`` at max F, ``sequences`` scored, ``absent``: of them, those with frames whose ground
    truth is absent), ``curves`` (tracker -> ``thresholds``, ``precision``, ``recall``, ``f``),
    ``left_out`` (tracker -> why), ``unbounded`` (the sequences whose frame 1 could not be read for the
    image size: their overlaps are the continuous IoU); or only ``skipped`` (why) for an experiment
    other than OPE.

    ``folders`` and ``results``: tracker -> folder, and tracker -> sequence -> result, of the report;
    a sequence a tracker has no result for (``--missing fail``) predicts nothing.
    """
    exp = get_experiment(experiment)
    if exp.pooled or exp.scoring != "otb" or not exp.first_box:  # not one run per sequence from frame 1
        return {"skipped": f"long-term measures are computed for one-pass runs (OPE) only, not for {exp.name.upper()}: "
                           f"they score one run of each whole sequence from its first box"}
    absent = sum(not np.isfinite(s.ground_truth).all() for s in sequences)
    read, left_out = {}, {}
    for tracker, folder in folders.items():
        try:
            read[tracker] = [_read(folder, results[tracker].get(s.name), s) for s in sequences]
        except DatasetError as exc:  # the table says why; a damaged file is worth a warning too
            left_out[tracker] = str(exc)
            log.log(logging.INFO if isinstance(exc, NoConfidence) else logging.WARNING,
                    "no long-term scores for %r: %s", tracker, exc)
    sizes, unread = _image_sizes(sequences) if read else ({}, [])
    rows, curves = [], {}
    for tracker, found in read.items():
        scores = long_term_scores((*frame_overlaps(boxes, s.ground_truth, sizes.get(s.name)),
                                   predicted_scores(confidence, boxes, len(s)))
                                  for s, (boxes, confidence) in zip(sequences, found))
        rows.append({"tracker": tracker, **{k: scores[k] for k in ("f", "precision", "recall", "threshold")},
                     "sequences": scores["sequences"], "absent": absent})
        curves[tracker] = {"thresholds": scores["thresholds"], "precision": scores["precision_curve"],
                           "recall": scores["recall_curve"], "f": scores["f_curve"]}
    rows.sort(key=lambda r: -r["f"])
    return {"measures": MEASURES, "rows": rows, "curves": curves, "left_out": left_out, "unbounded": unread}


def _read(folder: Path, result, seq: Sequence) -> tuple[np.ndarray, np.ndarray]:
    """(boxes, confidence) of one tracker's ``result`` on ``seq``; a :class:`DatasetError` naming the
    file when its confidences are missing, malformed or not one a box."""
    if result is None:  # no result (--missing fail): no prediction
        return np.empty((0, 4)), np.empty(0)
    boxes = np.asarray(getattr(result, "boxes", result), dtype=np.float64)
    store = ResultStore(folder)
    path = store.confidence_path(seq.name)
    if not path.is_file():
        raise NoConfidence(f"no {clip(str(path))} (results imported or written without confidences)")
    recorded = (store.sidecar(seq.name) or {}).get("confidence_sha256")
    confidence = read_confidence(path, recorded if isinstance(recorded, str) else None)
    if len(confidence) != len(boxes):
        raise DatasetError(f"{clip(str(path))} has {len(confidence)} lines for the {len(boxes)} boxes of "
                           f"{clip(str(store.boxes_path(seq.name)))}")
    return boxes, confidence


def _image_sizes(sequences: Seq[Sequence]) -> tuple[dict[str, tuple[int, int]], list[str]]:
    """(sequence -> (width, height) of its frame 1, the sequences whose frame 1 cannot be read: their
    overlaps are the continuous, unbounded IoU, and the table says so)."""
    sizes, unread = {}, []
    for seq in sequences:
        try:
            sizes[seq.name] = seq.image_size
        except DcfkitError as exc:
            log.warning("long-term overlaps of %r are not bounded by the image: %s", seq.name, exc)
            unread.append(seq.name)
    return sizes, unread


def long_term_lines(record: Mapping, fmt: str = "table", brief: bool = False) -> str:
    """The long-term table (``table`` or ``markdown``) with what it measures, the sequences whose
    overlaps are not bounded by the image, the trackers without scores and why (``brief``: one line
    when no tracker has scores), or the reason it was skipped."""
    if "skipped" in record:
        return record["skipped"] + "\n"
    if brief and not record["rows"]:  # imported or published results only: the reasons are in the files
        return "long-term measures: no tracker has a confidence file for every sequence scored\n"
    text = MEASURES + "\n\n" + format_rows(record["rows"], fmt, LONG_TERM_COLUMNS)
    if record["unbounded"]:
        names = record["unbounded"]
        text += (f"\noverlaps of {len(names)} sequences are the continuous IoU, not bounded by the image (their frame "
                 f"1 cannot be read): {', '.join(names[:10])}{' ...' if len(names) > 10 else ''}\n")
    if record["left_out"]:
        text += "\n" + "".join(f"no long-term scores for {tracker}: {why}\n" for tracker, why in record["left_out"].items())
    return text


def long_term_output(record: Mapping, fmt: str, experiment: str | Experiment = "ope",
                     max_frames: int | None = None) -> str:
    """The long-term part of ``dcfkit report``'s printed output in ``fmt``: ``table`` and ``markdown``
    as :func:`long_term_lines` (brief), ``csv`` as ``longterm.csv``, ``latex`` a booktabs table
    (:func:`dcfkit.analysis.latex.long_term_table`, its caption naming the experiment and the
    measures). Without a table (a skipped experiment, no tracker with scores) the line saying why,
    but in LaTeX: nothing (a paper's table takes no notes, as the fps note's rule)."""
    if fmt in ("table", "markdown") or "skipped" in record or not record["rows"]:
        return "" if fmt == "latex" else long_term_lines(record, fmt if fmt == "markdown" else "table", brief=True)
    if fmt == "csv":
        return format_rows(record["rows"], "csv", LONG_TERM_COLUMNS)
    setting = [experiment_line(experiment, max_frames), MEASURES,
               "Absent: of the sequences scored, those with frames whose target is absent"]
    return long_term_table(record["rows"], LONG_TERM_COLUMNS, setting, list(record["left_out"]))


def long_term_files(record: Mapping, experiment: str | Experiment, max_frames: int | None, write) -> None:
    """Write ``longterm.txt``, ``.md``, ``.csv`` and ``longterm_curves.csv`` (tracker, threshold,
    precision, recall, f: one row per threshold, highest first) with ``write(name, text)``; none for a
    skipped experiment (``report.json`` holds the reason)."""
    if "skipped" in record:
        return
    head = experiment_line(experiment, max_frames) + "\n"
    write("longterm.txt", head + long_term_lines(record, "table"))
    write("longterm.md", head + long_term_lines(record, "markdown"))
    write("longterm.csv", format_rows(record["rows"], "csv", LONG_TERM_COLUMNS))
    buf = io.StringIO()
    out = csv.writer(buf, lineterminator="\n")
    out.writerow(["tracker", "threshold", "precision", "recall", "f"])
    for tracker, c in record["curves"].items():
        for row in zip(c["thresholds"], c["precision"], c["recall"], c["f"]):
            out.writerow([tracker, *(repr(float(v)) for v in row)])
    write("longterm_curves.csv", buf.getvalue())

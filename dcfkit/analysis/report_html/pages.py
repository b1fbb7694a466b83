"""The report page of ``dcfkit report --html``: :func:`write_html_report`."""
from __future__ import annotations

from pathlib import Path
from typing import Iterable, Mapping
from typing import Sequence as Seq

from dcfkit.analysis.report import columns, default_report_dir, score_folders, write_files
from dcfkit.analysis.report_html import sections
from dcfkit.analysis.report_html.document import write_page
from dcfkit.analysis.report_html.provenance import this_process
from dcfkit.datasets import Sequence, scored_sequences
from dcfkit.protocols import Protocol

PAGE = "report.html"


def evaluation_sections(evaluation: Mapping, sequences: Seq[Sequence], results: Mapping[str, Mapping],
                        trackers: Seq[str]) -> list[dict]:
    """The plots, the per-attribute and per-sequence tables and the frames of an evaluation
    (:func:`dcfkit.analysis.scoring.evaluate`), in page order, for ``trackers``."""
    protocol = evaluation.protocol.name
    out = [sections.curve_charts(evaluation, trackers), sections.attribute_charts(evaluation, trackers)]
    if evaluation.per_attribute:
        out.append(sections.table("per-attribute", "Per attribute", evaluation.per_attribute,
                                  columns("per_attribute", protocol), trackers, filterable=True))
    out.append(sections.table("per-sequence", "Per sequence", evaluation.per_sequence,
                              columns("per_sequence", protocol), trackers, filterable=True))
    out.append(sections.gallery(sequences, results, trackers, evaluation.per_sequence))
    return [s for s in out if s is not None]


def report_page(evaluation: Mapping, sequences: Seq[Sequence], results: Mapping[str, Mapping],
                folders: Mapping[str, Path]) -> dict:
    """The page of a report on ``sequences``: ``results`` (tracker -> sequence -> result) read
    from ``folders`` (tracker -> folder) and scored as ``evaluation``."""
    protocol = evaluation.protocol
    trackers = [r["tracker"] for r in evaluation.overall]
    datasets = sorted({s.dataset for s in sequences if s.dataset})
    overall = sections.table("overall", "Overall", evaluation.overall, columns("overall", protocol.name),
                             trackers, note=" ".join(filter(None, (evaluation.settings.get("fps_note"),
                                                                    "Click a column's name to sort by it."))))
    statistics = sections.statistics_table(evaluation.statistics, trackers)
    on = ", ".join(datasets) or "sequences"
    return {"title": f"dcfkit report: {sections.count(len(trackers), 'tracker')} on {on}",
            "protocol": protocol.describe(),
            "subtitle": f"{sections.count(len(sequences), 'sequence')}, {sum(len(s) for s in sequences)} frames",
            "trackers": trackers,
            "sections": [overall, *([statistics] if statistics else []),
                         *evaluation_sections(evaluation, sequences, results, trackers),
                         sections.provenance(folders, [s.name for s in sequences], trackers, this_process())]}


def write_html_report(out_dir, sequences: Seq[Sequence], trackers: Iterable[str] | None = None, report_dir=None,
                      include_first: bool = True, weighting: str | None = None,
                      protocol: str | Protocol | None = None, *, missing: str = "skip") -> tuple[dict, list[Path]]:
    """:func:`dcfkit.analysis.report.score_and_write` plus ``report.html``: one self-contained page with
    the tables (sortable, filterable), the plots, every sequence's frames with the boxes, and
    what produced the results. Returns (evaluation, paths), the page last."""
    report_dir = default_report_dir(out_dir, report_dir)
    sequences = scored_sequences(sequences)  # the page shows the frames of the sequences scored only
    folders, results, evaluation = score_folders(out_dir, sequences, trackers, report_dir, include_first,
                                                 weighting, protocol, missing=missing)
    paths = write_files(evaluation, report_dir)
    page = report_page(evaluation, sequences, results, folders)
    return evaluation, paths + [write_page(page, report_dir / PAGE)]

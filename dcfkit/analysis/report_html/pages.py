"""The report page of ``dcfkit report --html``: :func:`write_html_report`."""
from __future__ import annotations

from pathlib import Path
from typing import Iterable, Mapping
from typing import Sequence as Seq

from dcfkit.analysis.report import default_report_dir, score_folders, write_files
from dcfkit.analysis.report_html import sections
from dcfkit.analysis.report_html.document import write_page
from dcfkit.analysis.report_html.provenance import this_process
from dcfkit.analysis.setting import cut_phrase, experiment_line
from dcfkit.analysis.tables import columns
from dcfkit.datasets import Sequence, scored_sequences
from dcfkit.experiments import Experiment, get_experiment, runs_by_sequence
from dcfkit.protocols import Protocol

PAGE = "report.html"


def evaluation_sections(evaluation: Mapping, sequences: Seq[Sequence], results: Mapping[str, Mapping],
                        trackers: Seq[str]) -> list[dict]:
    """The plots, the long-term measures (when the report scored them), the per-attribute and
    per-sequence tables and the frames of an evaluation (:func:`dcfkit.analysis.scoring.evaluate`),
    in page order, for ``trackers``."""
    protocol = evaluation.protocol.name
    out = [sections.curve_charts(evaluation, trackers), sections.attribute_charts(evaluation, trackers),
           sections.long_term(evaluation.long_term, trackers)]
    if evaluation.per_attribute:
        out.append(sections.table("per-attribute", "Per attribute", evaluation.per_attribute,
                                  columns("per_attribute", protocol), trackers, filterable=True))
    out.append(sections.table("per-sequence", "Per sequence", evaluation.per_sequence,
                              columns("per_sequence", protocol), trackers, filterable=True))
    out.append(sections.gallery(sequences, results, trackers, evaluation.per_sequence))
    return [s for s in out if s is not None]


def report_page(evaluation: Mapping, sequences: Seq[Sequence], results: Mapping[str, Mapping],
                folders: Mapping[str, Path], report_dir: Path | None = None) -> dict:
    """The page of a report on ``sequences``: ``results`` (tracker -> sequence or run name ->
    result) read from ``folders`` (tracker -> folder, shown relative to ``report_dir``) and scored
    as ``evaluation``. Under TRE or SRE the frames show each sequence's first run (TRE's from
    frame 1, SRE's first shifted box)."""
    protocol, experiment = evaluation.protocol, get_experiment(evaluation.settings.get("experiment", "ope"))
    cut = evaluation.settings.get("max_frames")
    trackers = [r["tracker"] for r in evaluation.overall]
    datasets = sorted({s.dataset for s in sequences if s.dataset})
    overall = sections.table("overall", "Overall", evaluation.overall, columns("overall", protocol.name),
                             trackers, note=" ".join(filter(None, (evaluation.settings.get("fps_note"),
                                                                    "Click a column's name to sort by it."))))
    statistics = sections.statistics_table(evaluation.statistics, trackers)
    by_sequence = runs_by_sequence(sequences, experiment)
    body = evaluation_sections(evaluation, sequences, _first_runs(results, sequences, by_sequence), trackers)
    if experiment.folder:  # runs of their own: a sequence's frames show one of them
        for section in body:
            if section["id"] == "frames":
                section["note"] += f" {experiment.name.upper()}: the boxes of each sequence's first run."
    on = ", ".join(datasets) or "sequences"
    kind = f" ({experiment.name.upper()})" if experiment.folder else ""
    return {"title": f"dcfkit report{kind}: {sections.count(len(trackers), 'tracker')} on {on}",
            "protocol": f"{experiment_line(experiment, cut)}; {protocol.describe()}",
            "subtitle": f"{sections.count(len(sequences), 'sequence')}, {sum(len(s) for s in sequences)} frames"
                        f"{cut_phrase(cut)}",
            "trackers": trackers,
            "sections": [overall, *([statistics] if statistics else []), *body,
                         sections.provenance(folders, [r.name for runs in by_sequence.values() for r in runs],
                                             trackers, this_process(), base=report_dir)]}


def _first_runs(results: Mapping[str, Mapping], sequences: Seq[Sequence],
                by_sequence: Mapping[str, list[Sequence]]) -> dict[str, dict]:
    """tracker -> sequence name -> the result of its first run, when that run spans the whole
    sequence (a one-pass result is its sequence's only run)."""
    first = {s.name: by_sequence[s.name][0] for s in sequences
             if by_sequence.get(s.name) and len(by_sequence[s.name][0]) == len(s)}
    return {t: {name: found[run.name] for name, run in first.items() if run.name in found}
            for t, found in results.items()}


def write_html_report(out_dir, sequences: Seq[Sequence], trackers: Iterable[str] | None = None, report_dir=None,
                      include_first: bool = True, weighting: str | None = None,
                      protocol: str | Protocol | None = None, *, missing: str = "skip",
                      experiment: str | Experiment = "ope", baseline: str | None = None) -> tuple[dict, list[Path]]:
    """:func:`dcfkit.analysis.report.score_and_write` plus ``report.html``: one self-contained page with
    the tables (sortable, filterable), the plots, every sequence's frames with the boxes, and
    what produced the results. ``experiment``: one pass, ``tre`` or ``sre`` (reset-based runs
    have no page). Returns (evaluation, paths), the page last."""
    report_dir = default_report_dir(out_dir, report_dir, experiment)
    sequences = scored_sequences(sequences)  # the page shows the frames of the sequences scored only
    folders, results, evaluation = score_folders(out_dir, sequences, trackers, report_dir, include_first,
                                                 weighting, protocol, missing=missing, experiment=experiment,
                                                 baseline=baseline)
    paths = write_files(evaluation, report_dir)
    page = report_page(evaluation, sequences, results, folders, report_dir)
    return evaluation, paths + [write_page(page, report_dir / PAGE)]

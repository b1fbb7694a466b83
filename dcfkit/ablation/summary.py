"""Scoring an ablation's stored runs: tables, summary.json and plots."""
from __future__ import annotations

import contextlib
import json
import logging
from pathlib import Path

from dcfkit.ablation.experiment import cut_title, scope_line
from dcfkit.ablation.layout import variant_folders
from dcfkit.ablation.page import ablation_page
from dcfkit.ablation.published import STATUS, read_published
from dcfkit.ablation.sensitivity import plot_sensitivity, sensitivity_file
from dcfkit.ablation.spec import AblationSpec, Job, expand
from dcfkit.ablation.spec_keys import data_record
from dcfkit.analysis.latex import comparison_table
from dcfkit.analysis.plots import plot_curves, plot_title
from dcfkit.analysis.report import json_ready
from dcfkit.analysis.report_html import PAGE, write_page
from dcfkit.analysis.scoring import evaluate, protocol_record
from dcfkit.analysis.setting import experiment_line
from dcfkit.analysis.statistics import versus_baseline
from dcfkit.analysis.tables import format_table, statistics_files
from dcfkit.datasets import Sequence
from dcfkit.experiments import runs_by_sequence
from dcfkit.protocols import DEFAULT, get_protocol
from dcfkit.running.layout import store_folder
from dcfkit.store.files import atomic_write, read_json
from dcfkit.store.provenance import shared_path
from dcfkit.store.results import ResultStore
from dcfkit.store.timing import fps_note

SUMMARY_COLUMNS = ("variant", "precision", "auc", "fps", "sequences", "failed")
SEQUENCE_COLUMNS = ("variant", "sequence", "precision", "auc", "fps", "frames", "status")


def summary_columns(table: str, protocol: str = DEFAULT) -> tuple[str, ...]:
    """:data:`SUMMARY_COLUMNS` (``table="summary"``) or :data:`SEQUENCE_COLUMNS`
    (``"per_sequence"``), with AO, SR@0.5 and SR@0.75 after the AUC under ``got10k``."""
    base = SUMMARY_COLUMNS if table == "summary" else SEQUENCE_COLUMNS
    i = base.index("auc") + 1
    return base[:i] + get_protocol(protocol).overlap_keys + base[i:]


_WORST_FIRST = ("failed", "damaged", "missing", "done")


def _status(folder: Path, key: str, runs: list[Sequence]) -> tuple[str, str | None]:
    """A sequence's status in its store (done, failed, damaged, missing: its runs' worst) and
    the first error if failed."""
    store = ResultStore(folder)
    found = [store.status(run, key) for run in runs]
    status = min(found, key=_WORST_FIRST.index)
    failed = [run for run, s in zip(runs, found) if s == "failed"]
    return status, (read_json(store.error_path(failed[0].name)) or {}).get("error") if failed else None


def summarize(spec: AblationSpec, out, sequences: list, jobs: list[Job] | None = None,
              protocol: str | None = None, runs: dict[str, list[Sequence]] | None = None) -> dict:
    """Score the stored results of ``jobs`` under ``protocol`` (by default the benchmark's,
    :func:`dcfkit.analysis.scoring.evaluate`) and write the tables,
    ``summary.json`` and plots, each naming the protocol.

    precision is the precision at 20 px, auc the area under the success curve (and under
    ``got10k`` also ao, sr50, sr75), fps the mean per-sequence frames per second of tracker
    time, of runs timed alone only (:mod:`dcfkit.store.timing`, ``fps_measured``). A job
    without result (failed or not run) is scored as a total failure and counted in ``failed``. ``statistics`` compares each variant with the
    grid's base (when it names a variant) or the first variant
    (:func:`~dcfkit.analysis.statistics.versus_baseline`); the spec's published results are
    scored and compared beside the variants (key and status ``published``). Under a spec's ``tre`` or ``sre``
    experiment a sequence's runs (``runs``, by default made here) are pooled. Returns ``{"overall",
    "per_sequence", "statistics", "jobs", "files", "protocol"`` (the
    :class:`~dcfkit.protocols.Protocol`), ``"scope"`` (the line naming the experiment, protocol and
    ``--max-frames`` cut: :func:`~dcfkit.ablation.experiment.scope_line`, heading every output) and
    ``"fps_note"}`` (whose fps is left out and why: :func:`dcfkit.store.timing.fps_note`).
    """
    out = Path(out)
    jobs = jobs if jobs is not None else expand(spec, sequences)
    keys = {j.variant: j.key for j in jobs}
    runs = runs if runs is not None else runs_by_sequence(sequences, spec.experiment)
    folders = variant_folders(spec, output_names(spec))
    status, stored = _stored_runs(spec, out, runs, jobs, folders)
    results = {variant: stored[variant] for variant in keys}
    published = read_published(spec.published, sequences)
    with _quiet(logging.getLogger("dcfkit.analysis.scoring")):  # missing runs are counted in 'failed'
        scores = evaluate({**results, **published}, sequences, protocol=protocol, experiment=spec.experiment,
                          runs=runs)
    protocol = scores.protocol
    states = {(v, s.name): status[v, s.name] for v in keys for s in sequences}
    states.update({(name, s.name): (STATUS if s.name in found else "missing", None)
                   for name, found in published.items() for s in sequences})
    overall, per_sequence = _rows(scores, {**keys, **dict.fromkeys(published, STATUS)}, sequences, states, protocol)
    variants = [*keys, *published]
    baseline = spec.grid.base if spec.grid is not None and spec.grid.base in keys else variants[0]
    statistics = versus_baseline(scores.per_sequence, variants, (protocol.rank_key, "precision"), baseline)
    job_rows = [{"variant": j.variant, "sequence": j.sequence, "key": j.key,
                 "status": status[j.variant, j.sequence][0], "error": status[j.variant, j.sequence][1]} for j in jobs]
    info = {"spec": shared_path(spec.path, out), "name": spec.name, "description": spec.description,
            "protocol": protocol_record(scores.protocol), "experiment": spec.experiment,
            "max_frames": spec.max_frames, "scope": scope_line(spec.experiment, protocol.name, spec.max_frames),
            "fps_note": fps_note(overall, "variant"),
            **data_record(spec, out), "sequences": [s.name for s in sequences], "folders": folders,
            "overall": overall, "per_sequence": per_sequence, "statistics": statistics, "jobs": job_rows,
            "grid": ({"base": spec.grid.base, "mode": spec.grid.mode,
                      "parameters": {k: {"label": lab, "values": vals}
                                     for k, (lab, vals) in spec.grid.parameters.items()}}
                     if spec.grid else None)}
    files = _write_files(spec, out, info, scores.curves, protocol)
    files.append(_write_latex(spec, out, info["statistics"], protocol, scores.settings.get("max_frames")))
    page = ablation_page(spec, out, info, summary_columns("summary", protocol), scores, sequences,
                         {**results, **published}, keys)
    files.append(write_page(page, out / PAGE))
    return {"overall": overall, "per_sequence": per_sequence, "statistics": statistics, "jobs": job_rows,
            "files": files, "protocol": protocol, "scope": info["scope"], "fps_note": info["fps_note"]}


def _stored_runs(spec: AblationSpec, out: Path, runs: dict[str, list[Sequence]], jobs: list[Job],
                 folders: dict[str, str]) -> tuple[dict, dict]:
    """``status[variant, sequence]`` = (status, error) and ``stored[variant]`` = the intact results
    (run name -> result) of the sequences whose every run is done, read from each variant's
    folder (``folders``: :func:`~dcfkit.ablation.layout.variant_folders`)."""
    status: dict[tuple[str, str], tuple[str, str | None]] = {}
    stored: dict[str, dict] = {}
    by_variant: dict[str, list[Job]] = {}
    for job in jobs:
        by_variant.setdefault(job.variant, []).append(job)
    for variant, found in by_variant.items():
        folder = store_folder(out, folders[variant], spec.experiment)
        names = list(dict.fromkeys(j.sequence for j in found))
        for name in names:
            status[variant, name] = _status(folder, found[0].key, runs[name])
        done = [run for n in names if status[variant, n][0] == "done" for run in runs[n]]
        stored[variant] = ResultStore(folder).load(done) if done else {}
    return status, stored


def _rows(scores: dict, keys: dict, sequences: list[Sequence], status: dict, protocol: str) -> tuple[list, list]:
    """The summary's rows (one per variant, spec order, then the published results) and
    per-sequence rows; ``status[variant, sequence]`` is (status, error)."""
    extra = get_protocol(protocol).overlap_keys
    frames = {s.name: len(s) for s in sequences}
    order = {v: i for i, v in enumerate(keys)}
    seq_order = {s.name: i for i, s in enumerate(sequences)}
    overall = sorted(({"variant": r["tracker"], "precision": r["precision"], "auc": r["auc"],
                       **{k: r[k] for k in extra}, "fps": r["fps"], "fps_measured": r["fps_measured"],
                       "sequences": r["sequences"], "failed": r["missing"], "key": keys[r["tracker"]]}
                      for r in scores.overall), key=lambda r: order[r["variant"]])
    per_sequence = sorted(({"variant": r["tracker"], "sequence": r["sequence"], "precision": r["precision"],
                            "auc": r["auc"], **{k: r[k] for k in extra}, "fps": r["fps"],
                            "fps_measured": r["fps_measured"], "frames": frames[r["sequence"]],
                            "status": status[r["tracker"], r["sequence"]][0]}
                           for r in scores.per_sequence),
                          key=lambda r: (order[r["variant"]], seq_order[r["sequence"]]))
    return overall, per_sequence


def _write_files(spec: AblationSpec, out: Path, info: dict, curves: dict, protocol: str) -> list[Path]:
    """summary/per_sequence tables (Markdown, CSV), summary.json and the plots."""
    files = []
    for stem in ("summary", "per_sequence"):
        for fmt, ext in (("markdown", "md"), ("csv", "csv")):
            path = out / f"{stem}.{ext}"
            table = format_table(info["overall" if stem == "summary" else stem], fmt, summary_columns(stem, protocol),
                                 protocol)
            if fmt == "markdown":  # named: its experiment, protocol and cut; after it, whose fps is left out
                table = f"# {spec.name}: {info['scope']}\n\n{table}" + (f"\n{info['fps_note']}\n"
                                                                        if info["fps_note"] else "")
            atomic_write(path, table)
            files.append(path)
    setting = {"protocol": get_protocol(protocol).name, "experiment": spec.experiment,
               **({} if spec.max_frames is None else {"max_frames": spec.max_frames})}
    for name, content in statistics_files(info["statistics"], [info["scope"]], setting).items():
        atomic_write(out / name, content)
        files.append(out / name)
    path = out / "summary.json"
    atomic_write(path, json.dumps(json_ready(info), indent=1, ensure_ascii=False, default=str) + "\n")
    files.append(path)
    if spec.grid is not None:
        files += plot_sensitivity(spec, info["overall"], out, protocol)
    else:  # named variants: the OTB plots, one curve each
        for kind in ("precision", "success"):
            title = plot_title(kind, spec.experiment) + cut_title(spec.max_frames)
            files += plot_curves(curves, kind, out / kind, title=title, protocol=protocol)
    return files


def _write_latex(spec: AblationSpec, out: Path, statistics: dict, protocol, max_frames: int | None) -> Path:
    """``summary.tex``: the variants compared with the baseline as a LaTeX table
    (:func:`~dcfkit.analysis.latex.comparison_table`), the experiment and protocol in its caption."""
    path = out / "summary.tex"
    setting = [f"ablation {spec.name}", experiment_line(spec.experiment, max_frames), get_protocol(protocol).describe()]
    atomic_write(path, comparison_table(statistics, setting, name="Variant"))
    return path


@contextlib.contextmanager
def _quiet(logger: logging.Logger):
    level = logger.level
    logger.setLevel(logging.ERROR)
    try:
        yield
    finally:
        logger.setLevel(level)


def output_names(spec: AblationSpec) -> list[str]:
    """Every file :func:`summarize` writes into the output folder."""
    plots = ([sensitivity_file(key) for key in spec.grid.parameters] if spec.grid is not None else
             [f"{kind}.{ext}" for kind in ("precision", "success") for ext in ("png", "svg")])
    tables = [f"{stem}.{ext}" for stem in ("summary", "per_sequence") for ext in ("md", "csv")]
    return tables + ["summary.tex", "summary.json", PAGE] + plots



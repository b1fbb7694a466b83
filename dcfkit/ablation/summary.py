"""Scoring an ablation's stored runs: tables, summary.json and plots."""
from __future__ import annotations

import contextlib
import json
import logging
import math
from pathlib import Path
from typing import Any, Mapping

from ..datasets import Sequence
from ..protocols import DEFAULT, get_protocol
from ..report import evaluate, format_table, json_ready, plot_curves, save_figure
from ..results import ResultStore, atomic_write, read_json
from .spec import AblationSpec, Job, expand, format_value, job_dir

SUMMARY_COLUMNS = ("variant", "precision", "auc", "fps", "sequences", "failed")
SEQUENCE_COLUMNS = ("variant", "sequence", "precision", "auc", "fps", "frames", "status")


def summary_columns(table: str, protocol: str = DEFAULT) -> tuple[str, ...]:
    """:data:`SUMMARY_COLUMNS` (``table="summary"``) or :data:`SEQUENCE_COLUMNS`
    (``"per_sequence"``), with AO, SR@0.5 and SR@0.75 after the AUC under ``got10k``."""
    base = SUMMARY_COLUMNS if table == "summary" else SEQUENCE_COLUMNS
    i = base.index("auc") + 1
    return base[:i] + get_protocol(protocol).overlap_keys + base[i:]


def _status(folder: Path, seq: Sequence) -> tuple[str, str | None]:
    """The run's status in its store (done, failed, damaged, missing) and its error if failed."""
    store = ResultStore(folder)
    status = store.status(seq, folder.name)
    return status, (read_json(store.error_path(seq.name)) or {}).get("error") if status == "failed" else None


def summarize(spec: AblationSpec, out, sequences: list, jobs: list[Job] | None = None,
              protocol: str = DEFAULT) -> dict:
    """Score the stored results of ``jobs`` under ``protocol`` and write the tables,
    ``summary.json`` and plots, each naming the protocol.

    precision is the precision at 20 px, auc the area under the success curve (and under
    ``got10k`` also ao, sr50, sr75), fps the mean per-sequence frames per second of tracker
    time (:mod:`dcfkit.report`). A job without result (failed or not run) is scored as a
    total failure and counted in ``failed``. Returns ``{"overall", "per_sequence", "jobs",
    "files"}``.
    """
    out = Path(out)
    jobs = jobs if jobs is not None else expand(spec, sequences)
    keys = {j.variant: j.key for j in jobs}
    status, stored = _stored_runs(spec, out, sequences, jobs)
    with _quiet(logging.getLogger("dcfkit.report")):  # missing runs are counted in 'failed'
        scores = evaluate({variant: stored[key] for variant, key in keys.items()}, sequences, protocol=protocol)
    overall, per_sequence = _rows(scores, keys, sequences, status, protocol)
    job_rows = [{"variant": j.variant, "sequence": j.sequence, "key": j.key,
                 "status": status[j.key, j.sequence][0], "error": status[j.key, j.sequence][1]} for j in jobs]
    info = {"spec": str(spec.path), "name": spec.name, "description": spec.description,
            "protocol": scores["protocol"],
            "dataset": spec.dataset, "root": str(spec.root), "sequences": [s.name for s in sequences],
            "overall": overall, "per_sequence": per_sequence, "jobs": job_rows,
            "grid": ({"base": spec.grid.base, "mode": spec.grid.mode,
                      "parameters": {k: {"label": lab, "values": vals}
                                     for k, (lab, vals) in spec.grid.parameters.items()}}
                     if spec.grid else None)}
    files = _write_files(spec, out, info, scores["curves"], protocol)
    return {"overall": overall, "per_sequence": per_sequence, "jobs": job_rows, "files": files}


def _stored_runs(spec: AblationSpec, out: Path, sequences: list[Sequence], jobs: list[Job]) -> tuple[dict, dict]:
    """``status[key, sequence]`` = (status, error) and ``stored[key]`` = the intact results."""
    by_name = {s.name: s for s in sequences}
    status: dict[tuple[str, str], tuple[str, str | None]] = {}
    stored: dict[str, dict] = {}
    for key in dict.fromkeys(j.key for j in jobs):
        folder = job_dir(out, spec.dataset, key)
        names = list(dict.fromkeys(j.sequence for j in jobs if j.key == key))
        for name in names:
            status[key, name] = _status(folder, by_name[name])
        done = [by_name[n] for n in names if status[key, n][0] == "done"]
        stored[key] = ResultStore(folder).load(done) if done else {}
    return status, stored


def _rows(scores: dict, keys: dict, sequences: list[Sequence], status: dict, protocol: str) -> tuple[list, list]:
    """The summary's rows (one per variant, spec order) and per-sequence rows."""
    extra = get_protocol(protocol).overlap_keys
    frames = {s.name: len(s) for s in sequences}
    order = {v: i for i, v in enumerate(keys)}
    seq_order = {s.name: i for i, s in enumerate(sequences)}
    overall = sorted(({"variant": r["tracker"], "precision": r["precision"], "auc": r["auc"],
                       **{k: r[k] for k in extra}, "fps": r["fps"],
                       "sequences": r["sequences"], "failed": r["missing"], "key": keys[r["tracker"]]}
                      for r in scores["overall"]), key=lambda r: order[r["variant"]])
    per_sequence = sorted(({"variant": r["tracker"], "sequence": r["sequence"], "precision": r["precision"],
                            "auc": r["auc"], **{k: r[k] for k in extra}, "fps": r["fps"],
                            "frames": frames[r["sequence"]],
                            "status": status[keys[r["tracker"]], r["sequence"]][0]}
                           for r in scores["per_sequence"]),
                          key=lambda r: (order[r["variant"]], seq_order[r["sequence"]]))
    return overall, per_sequence


def _write_files(spec: AblationSpec, out: Path, info: dict, curves: dict, protocol: str) -> list[Path]:
    """summary/per_sequence tables (Markdown, CSV), summary.json and the plots."""
    files = []
    for stem in ("summary", "per_sequence"):
        for fmt, ext in (("markdown", "md"), ("csv", "csv")):
            path = out / f"{stem}.{ext}"
            atomic_write(path, format_table(info["overall" if stem == "summary" else stem], fmt,
                                            summary_columns(stem, protocol), protocol))
            files.append(path)
    path = out / "summary.json"
    atomic_write(path, json.dumps(json_ready(info), indent=1, ensure_ascii=False, default=str) + "\n")
    files.append(path)
    if spec.grid is not None:
        files += plot_sensitivity(spec, info["overall"], out, protocol)
    else:  # named variants: the OTB plots, one curve each
        for kind in ("precision", "success"):
            files += plot_curves(curves, kind, out / kind, protocol=protocol)
    return files


@contextlib.contextmanager
def _quiet(logger: logging.Logger):
    level = logger.level
    logger.setLevel(logging.ERROR)
    try:
        yield
    finally:
        logger.setLevel(level)


def _get_dotted(config: Any, key: str) -> Any:
    node = config
    for part in key.split("."):
        if isinstance(node, list) and part.lstrip("-").isdigit() and -len(node) <= int(part) < len(node):
            node = node[int(part)]
        elif isinstance(node, Mapping) and part in node:
            node = node[part]
        else:
            return None
    return node


def _is_number(value: Any) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)


def plot_sensitivity(spec: AblationSpec, overall: list[dict], out, protocol: str = DEFAULT) -> list[Path]:
    """Fig. 6 of the paper: per grid parameter, precision and AUC against its value.

    Sweep: the grid points of that parameter (the others at the base). Product: the mean
    over the other parameters' values, with their min-max as a band. The base value is a
    dotted vertical line. Writes ``OUT/sensitivity_<key>.png``; returns the paths.
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg  # lazy: matplotlib is slow to import,
    from matplotlib.figure import Figure  # and only plots need it

    grid = spec.grid
    rows = {r["variant"]: r for r in overall}
    points = [v for v in spec.variants if v.values]
    paths = []
    for key, (label, values) in grid.parameters.items():
        numeric = all(_is_number(v) for v in values)
        names = [format_value(v) for v in values]
        xs = [float(v) for v in values] if numeric else list(range(len(values)))
        fig = Figure(figsize=(4.6, 3.6))
        FigureCanvasAgg(fig)
        ax = fig.add_subplot(1, 1, 1)
        for metric, legend, colour, marker in (("precision", "precision@20", "C3", "o"),
                                               ("auc", "AUC", "C0", "s")):
            mean, low, high = [], [], []
            for name in names:
                scores = [rows[p.name][metric] for p in points
                          if key in p.values and format_value(p.values[key]) == name]
                scores = [s for s in scores if s is not None and math.isfinite(s)]
                mean.append(sum(scores) / len(scores) if scores else math.nan)
                low.append(min(scores) if scores else math.nan)
                high.append(max(scores) if scores else math.nan)
            ax.plot(xs, mean, color=colour, marker=marker, linewidth=1.8, label=legend)
            if grid.mode == "product" and len(grid.parameters) > 1:
                ax.fill_between(xs, low, high, color=colour, alpha=0.15, linewidth=0)
        base = _get_dotted(grid.base_config, key)
        base_x = (float(base) if numeric and _is_number(base) else
                  names.index(format_value(base)) if not numeric and format_value(base) in names else None)
        if base_x is not None:
            ax.axvline(base_x, color="0.5", linestyle=":", linewidth=1, label=f"base ({format_value(base)})")
        ax.set_xticks(xs)
        ax.set_xticklabels(names)
        ax.set_xlabel(label if label == key else f"{label} ({key})")
        ax.set_ylabel("score")
        what = "mean over the other parameters" if grid.mode == "product" and len(grid.parameters) > 1 else \
            "others at the base"
        n_seq = overall[0]["sequences"] if overall else 0
        ax.set_title(f"{label} on {spec.dataset} ({n_seq} sequences), {what} [protocol {protocol}]", fontsize=9)
        ax.grid(True, linestyle=":", linewidth=0.6)
        ax.legend(fontsize=8)
        fig.tight_layout()
        path = Path(out) / _sensitivity_file(key)
        save_figure(fig, path)
        paths.append(path)
    return paths


def _sensitivity_file(key: str) -> str:
    return "sensitivity_" + "".join(c if c.isalnum() or c in "._-" else "_" for c in key) + ".png"


def output_names(spec: AblationSpec) -> list[str]:
    """Every file :func:`summarize` writes into the output folder."""
    plots = ([_sensitivity_file(key) for key in spec.grid.parameters] if spec.grid is not None else
             [f"{kind}.{ext}" for kind in ("precision", "success") for ext in ("png", "svg")])
    return [f"{stem}.{ext}" for stem in ("summary", "per_sequence") for ext in ("md", "csv")] + ["summary.json"] + plots



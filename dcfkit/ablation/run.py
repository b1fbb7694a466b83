"""Running an ablation spec: one run plan (:mod:`dcfkit.running.plan`) of its variants, each
stored under its folder ``OUT/<variant>/[<experiment>/]`` (:mod:`dcfkit.ablation.layout`),
each distinct (run key, run) tracked once; then the summary."""
from __future__ import annotations

import json
from pathlib import Path

from dcfkit.ablation.layout import CONFIGS, variant_entries, variant_folders, warn_old_layout
from dcfkit.ablation.spec import AblationSpec, Job, expand, variant_names
from dcfkit.ablation.summary import output_names, summarize
from dcfkit.datasets import benchmark_protocol
from dcfkit.errors import DcfkitError, shown
from dcfkit.running.plan import RunPlan
from dcfkit.running.progress import RunBar
from dcfkit.running.runner import usable_cores
from dcfkit.store.files import atomic_write, ensure_writable, exclusive, read_json
from dcfkit.store.provenance import LABEL_KEYS, dcfkit_version


def ablation_plan(spec: AblationSpec, out: Path, sequences: list, version: str | None = None) -> RunPlan:
    """The run plan of ``spec``'s variants on ``sequences`` under ``out``."""
    folders = variant_folders(spec, output_names(spec))
    return RunPlan(variant_entries(spec, folders), sequences, spec.experiment, out, "the ablation's results", version)


def run_ablation(spec: AblationSpec, out, jobs: int | None = None, executor: str = "local",
                 scheduler: str | None = None, progress: bool = True, protocol: str | None = None) -> dict:
    """Run every job of ``spec`` not already done under ``out``, then write the summary
    (scored under ``protocol``, see :mod:`dcfkit.protocols`; by default the rules of the
    benchmark's published tables, :func:`~dcfkit.datasets.benchmark_protocol`).

    ``executor`` is ``"local"`` (``jobs`` spawned worker processes, default: the usable
    cores; ``jobs=1`` runs in this process) or ``"dask"`` (``Client(scheduler)``, or a
    ``LocalCluster`` of ``jobs`` single-threaded worker processes when ``scheduler`` is
    None; workers need the dataset and ``out`` at the same paths). A failing job is
    recorded (``.error``) and does not stop the others.

    Returns a plain dict: ``jobs`` (the :class:`Job` list), ``runs`` (distinct
    (key, run) pairs; a run is a sequence, or one of its runs in the spec's ``experiment``),
    ``done`` / ``skipped`` / ``failed`` (run -> message) and
    ``summary`` (what :func:`summarize` returned).
    """
    jobs = jobs if jobs is not None else usable_cores()
    if jobs < 1:
        raise DcfkitError(f"jobs must be >= 1, got {jobs}")
    if executor not in ("local", "dask"):
        raise DcfkitError(f"executor must be 'local' or 'dask', got {shown(executor)}")
    out = Path(out).expanduser().resolve()
    seqs = spec.load_sequences()
    if protocol is None:  # pooled benchmarks scored by different rules: refused before any run
        benchmark_protocol(seqs)
    version = dcfkit_version()
    job_list = expand(spec, seqs, version)
    warn_old_layout(out, "dcfkit ablate", "OUT/<variant>/")
    plan = ablation_plan(spec, out, seqs, version)
    ensure_writable(out, output_names(spec), "the ablation")
    with exclusive(out / ".lock", "dcfkit ablate", f"to {out}"):
        _write_configs(out, job_list, version)
        variants = variant_names(job_list)
        plan.run("dcfkit ablate", jobs, executor, scheduler,
                 RunBar(spec.name, progress, lambda shared: variants[shared.task.key]))
        result = {"jobs": job_list, **_outcome(plan)}
        result["summary"] = summarize(spec, out, seqs, job_list, protocol, plan.by_sequence)
    return result


def _write_configs(out: Path, job_list: list[Job], version: str) -> None:
    """``OUT/configs/<key>.json`` for each run key, (re)written where missing or damaged."""
    ensure_writable(out / CONFIGS, sorted({f"{j.key}.json" for j in job_list}), "the ablation's configs")
    for job in {j.key: j for j in job_list}.values():
        path = out / CONFIGS / f"{job.key}.json"
        if (read_json(path) or {}).get("key") != job.key:  # missing or damaged: (re)write the record
            stripped = {k: v for k, v in job.config.items() if k not in LABEL_KEYS}
            atomic_write(path, json.dumps({"key": job.key, "dcfkit_version": version, "config": stripped},
                                          indent=1) + "\n")


def _outcome(plan: RunPlan) -> dict:
    """``runs`` (the distinct (key, run) pairs), ``done`` and ``failed`` (tracked now), ``skipped``."""
    pairs = list(dict.fromkeys((p.key, run.name) for p in plan.entries for run in p.runs))
    tracked = {(s.task.key, s.task.seq.name): result for s, result in plan.tracked}
    return {"runs": len(pairs), "done": [pair for pair, r in tracked.items() if r["status"] == "done"],
            "skipped": [pair for pair in pairs if pair not in tracked],
            "failed": {pair: r["error"] for pair, r in tracked.items() if r["status"] != "done"}}

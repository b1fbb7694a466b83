"""Running an ablation spec's jobs: each distinct (run key, sequence) once, through
:func:`dcfkit.running.runner.execute`, into ``OUT/jobs/<dataset>/<key>/``."""
from __future__ import annotations

import contextlib
import json
from pathlib import Path

from dcfkit.ablation.experiment import runs_dir
from dcfkit.ablation.spec import AblationSpec, Job, expand, job_dir, variant_names
from dcfkit.ablation.summary import output_names, summarize
from dcfkit.datasets import benchmark_protocol
from dcfkit.errors import DcfkitError, shown
from dcfkit.experiments import runs_by_sequence
from dcfkit.store.files import atomic_write, ensure_writable, exclusive, read_json
from dcfkit.store.provenance import LABEL_KEYS, dcfkit_version
from dcfkit.store.results import ResultStore
from dcfkit.running.runner import RunTask, execute, usable_cores, warm_up_compiled


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
    runs = runs_by_sequence(seqs, spec.experiment)
    tasks: dict[tuple[str, str], RunTask] = {}
    for job in job_list:
        for run in runs[job.sequence]:
            tasks.setdefault((job.key, run.name), RunTask(job.config, run, runs_dir(job_dir(out, spec.dataset, job.key), spec.experiment), job.key))
    ensure_writable(out, output_names(spec), "the ablation")
    with exclusive(out / ".lock", "dcfkit ablate", f"to {out}"):
        _prepare(out, tasks.values(), job_list, version)
        todo = sorted((t for t in tasks.values() if not ResultStore(t.folder).is_done(t.seq, t.key)),
                      key=lambda t: -len(t.seq))  # longest first: the workers end together
        for task in todo:
            ResultStore(task.folder).refuse_to_shorten(task.seq)
        result = {"jobs": job_list, "runs": len(tasks), "done": [],
                  "skipped": [k for k, t in tasks.items() if t not in todo], "failed": {}}
        _run(spec, result, todo, len(tasks), variant_names(job_list), jobs, executor, scheduler, progress, version)
        result["summary"] = summarize(spec, out, seqs, job_list, protocol, runs)
    return result


def _prepare(out: Path, tasks, job_list: list[Job], version: str) -> None:
    """Before anything runs: stale temporary files removed, every result folder checked
    writable, and ``OUT/configs/<key>.json`` written for each run key."""
    # left by a killed run (in a run key's folder or its experiment's sub-folder); never read
    for stale in [*(out / "jobs").glob("*/*/.*.tmp"), *(out / "jobs").glob("*/*/*/.*.tmp")]:
        with contextlib.suppress(OSError):
            stale.unlink()
    by_folder: dict[Path, list[str]] = {}
    for task in tasks:
        by_folder.setdefault(task.folder, []).extend(ResultStore(task.folder).file_names(task.seq.name))
    for folder, names in by_folder.items():
        ensure_writable(folder, names, "the ablation's results")
    ensure_writable(out / "configs", sorted({f"{j.key}.json" for j in job_list}), "the ablation's configs")
    for job in {j.key: j for j in job_list}.values():
        path = out / "configs" / f"{job.key}.json"
        if (read_json(path) or {}).get("key") != job.key:  # missing or damaged: (re)write the record
            stripped = {k: v for k, v in job.config.items() if k not in LABEL_KEYS}
            atomic_write(path, json.dumps({"key": job.key, "dcfkit_version": version, "config": stripped},
                                          indent=1) + "\n")


def _run(spec, result, todo, total, variants, jobs, executor, scheduler, progress, version) -> None:
    """Execute ``todo`` with a progress bar in runs, recording each outcome in ``result``."""
    from tqdm.auto import tqdm  # lazy: tqdm.auto probes for Jupyter on import

    warm_up_compiled(todo)  # numba compiles here, not in the first jobs the bar times
    bar = tqdm(total=total, initial=total - len(todo), unit="job", desc=spec.name,
               disable=None if progress and todo else True, dynamic_ncols=True)  # None: on a terminal only

    def on_result(task: RunTask, res: dict) -> None:
        if res["status"] == "done":
            result["done"].append((task.key, task.seq.name))
        else:
            result["failed"][task.key, task.seq.name] = res["error"]
            bar.write(f"FAILED {', '.join(variants[task.key])}: {res['error']}")
        bar.set_postfix_str(f"{variants[task.key][0]} / {task.seq.name}", refresh=False)
        bar.update(1)

    try:
        execute(todo, on_result, jobs=jobs, executor=executor, scheduler=scheduler, version=version)
    finally:
        bar.close()

"""Ablation runs: named variants and parameter grids of tracker configs, run on a benchmark.

A spec (YAML, see ``docs/ablation.md``) names a dataset, variants (a config plus dotted
overrides) and optionally a grid of parameter values around a base config. It expands to
a deterministic job list, one :class:`Job` per (variant, sequence), each carrying the fully
resolved config of :func:`dcfkit.config.load_config`.

Results are stored per *run*, keyed by what determines the boxes::

    OUT/jobs/<dataset>/<key>/<sequence>.txt          1-based x,y,w,h per frame
    OUT/jobs/<dataset>/<key>/<sequence>.json         sidecar (times, fps, config hash); marks done
    OUT/jobs/<dataset>/<key>/<sequence>.error.json   instead, when the tracker raised
    OUT/configs/<key>.json                           the config behind <key>

``key`` is :func:`dcfkit.evaluation.config_hash` of the resolved config without its
``name`` and ``description`` (which do not change a box) plus the dcfkit version and the
versions of the plugin packages it uses, so two variants with the same parameters (the
base point of every one-at-a-time sweep) share one run. The files are written by
:mod:`dcfkit.evaluation`'s one-sequence runner: temporary file + ``os.replace``, sidecar
last. A rerun skips runs whose sidecar has the key and whose ``.txt`` has one line per
frame; failed runs are retried.

Runs go to a local process pool (spawned workers, one BLAS/OpenMP/OpenCV thread each,
killed with the parent) or to dask.distributed. Then ``OUT/summary.{md,csv}``,
``OUT/per_sequence.{md,csv}``, ``OUT/summary.json`` and, for a grid, one
``OUT/sensitivity_<parameter>.png`` per parameter (else ``OUT/precision`` and
``OUT/success`` plots, PNG and SVG) are written.
"""
from __future__ import annotations

import argparse
import contextlib
import dataclasses
import itertools
import json
import logging
import math
import os
from pathlib import Path
from typing import Any, Iterable, Mapping

import yaml

from .errors import ConfigError, DcfkitError
from .protocols import DEFAULT, get_protocol
from .report import add_protocol_argument, format_table

__all__ = [
    "AblationSpec",
    "Grid",
    "Job",
    "Variant",
    "add_ablate_arguments",
    "cmd_ablate",
    "expand",
    "job_key",
    "load_spec",
    "plot_sensitivity",
    "run_ablation",
    "summarize",
]

SPEC_KEYS = ("name", "description", "dataset", "sequences", "variants", "grid")
VARIANT_KEYS = ("config", "overrides", "description")
GRID_KEYS = ("base", "overrides", "mode", "parameters")
GRID_MODES = ("sweep", "product")
#: Config keys that label a tracker but do not change its boxes: left out of the run key.
LABEL_KEYS = ("name", "description")


# --------------------------------------------------------------------------- spec


@dataclasses.dataclass(frozen=True)
class Variant:
    """One row of the ablation table: ``config`` is the fully resolved config dict;
    ``values`` holds the grid parameter values that define it (empty for a named variant)."""

    name: str
    config: dict
    source: str
    overrides: dict = dataclasses.field(default_factory=dict)
    values: dict = dataclasses.field(default_factory=dict)


@dataclasses.dataclass(frozen=True)
class Grid:
    """A parameter grid around ``base`` (a variant name or a config): ``parameters`` maps a
    dotted key to ``(label, values)``; ``mode`` is ``sweep`` (one at a time) or ``product``."""

    base: str
    mode: str
    parameters: dict
    base_config: dict


@dataclasses.dataclass(frozen=True)
class AblationSpec:
    """A validated spec (:func:`load_spec`): every variant's config already resolved."""

    path: Path
    name: str
    description: str
    dataset: str              # canonical dataset name
    root: Path | None         # absolute; None when neither the spec nor --root gives one
    root_origin: str          # where root came from, for error messages
    sequences: tuple | None   # None: every sequence present under root
    variants: tuple           # of Variant: named variants first, then the grid's, in spec order
    grid: Grid | None

    def load_sequences(self) -> list:
        """The :class:`dcfkit.datasets.Sequence` objects to run: the spec's subset, else all under root."""
        from .datasets import load_dataset

        if self.root is None:
            raise ConfigError(f"{self.path}: dataset.root is not given; pass --root DIR "
                              f"(the {self.dataset} benchmark folder)")
        if not self.root.is_dir():
            hint = "" if self.root_origin == "--root" else f"; pass --root DIR (the {self.dataset} benchmark folder)"
            raise ConfigError(f"{self.path}: dataset root {self.root} ({self.root_origin}) is not a folder{hint}")
        return load_dataset(self.dataset, self.root, list(self.sequences) if self.sequences is not None else None)


@dataclasses.dataclass(frozen=True)
class Job:
    """One tracker run to do: ``variant`` on ``sequence`` with the resolved ``config``;
    ``key`` names the run's result folder (see :func:`job_key`)."""

    variant: str
    config: dict
    sequence: str
    key: str


def job_key(config: Mapping, version: str | None = None) -> str:
    """Result key of a resolved config: its hash without ``name``/``description``, with the dcfkit version."""
    from .evaluation import config_hash

    return config_hash({k: v for k, v in config.items() if k not in LABEL_KEYS}, version)


def variant_names(jobs: Iterable[Job]) -> dict[str, list[str]]:
    """key -> the names of the variants that share that run, in spec order."""
    names: dict[str, list[str]] = {}
    for job in jobs:
        if job.variant not in names.setdefault(job.key, []):
            names[job.key].append(job.variant)
    return names


def _find_spec(source: str | os.PathLike) -> Path:
    path = Path(source)
    if path.is_file():
        return path.resolve()
    from .config import shipped_config_dir

    folder = shipped_config_dir() / "ablations"
    for candidate in (folder / path, folder / f"{path}.yaml"):
        if candidate.is_file() and candidate.suffix in (".yaml", ".yml"):
            return candidate.resolve()
    shipped = [p.stem for p in sorted(folder.glob("*.yaml")) if _is_spec_file(p)] if folder.is_dir() else []
    raise ConfigError(f"ablation spec not found: {source}"
                      + (f"; shipped specs: {', '.join(shipped)}" if shipped else ""))


def _is_spec_file(path: Path) -> bool:
    with contextlib.suppress(OSError, yaml.YAMLError):
        data = yaml.safe_load(path.read_text(encoding="utf-8"))
        return isinstance(data, dict) and ("variants" in data or "grid" in data)
    return False


def _mapping(value: Any, where: str, what: str) -> dict:
    if value is None:
        return {}
    if not isinstance(value, Mapping):
        raise ConfigError(f"{where}: expected {what}, got {type(value).__name__} {value!r}")
    return dict(value)


def _check_keys(data: Mapping, valid: tuple, where: str) -> None:
    from .params import closest

    for key in data:
        if key not in valid:
            raise ConfigError(f"{where}: unknown key '{key}'{closest(key, valid)}; valid keys: {', '.join(valid)}")


def _overrides(value: Any, where: str) -> dict:
    out = _mapping(value, where, "a mapping of dotted keys to values, e.g. {label.mu: 0.3}")
    for key in out:
        if not isinstance(key, str) or not key.strip():
            raise ConfigError(f"{where}: keys must be dotted config keys such as label.mu, got {key!r}")
    return out


def _load(spec_path: Path, config: Any, overrides: Mapping, where: str, key: str) -> tuple[dict, str]:
    """Resolve ``config`` (relative to the spec file, else a shipped name) with ``overrides``.

    ``where`` names the spec entry in errors, ``key`` the spec key holding ``config``."""
    from .config import load_config, shipped_config

    if not isinstance(config, str) or not config.strip():
        raise ConfigError(f"{spec_path}: {key}: expected a config file or shipped name "
                          f"(e.g. ../dr2track.yaml or dr2track), got {config!r}")
    local = spec_path.parent / config
    found = local if local.is_file() else shipped_config(config)  # never the working directory
    if found is None:
        raise ConfigError(f"{spec_path}: {where}: config '{config}' not found (looked for {local} and for "
                          f"a shipped config of that name)")
    source = str(found)
    try:
        return load_config(source, overrides), source
    except DcfkitError as exc:
        try:
            load_config(source)
        except DcfkitError:
            raise ConfigError(f"{spec_path}: {where}: {exc}") from None
        raise ConfigError(f"{spec_path}: {where} overrides ({', '.join(overrides)}): {exc}") from None


def _format_value(value: Any) -> str:
    if isinstance(value, str):
        return value
    return yaml.safe_dump(value, default_flow_style=True, width=10**6).strip().removesuffix("...").strip()


def _parse_grid(spec_path: Path, data: Any, named: dict[str, Variant]) -> tuple[Grid, list[Variant]]:
    grid = _mapping(data, f"{spec_path}: grid", "a mapping with base, mode and parameters")
    _check_keys(grid, GRID_KEYS, f"{spec_path}: grid")
    mode = grid.get("mode", "sweep")
    if mode not in GRID_MODES:
        raise ConfigError(f"{spec_path}: grid.mode: expected one of {', '.join(GRID_MODES)}, got {mode!r}")
    base = grid.get("base")
    if base is None:
        raise ConfigError(f"{spec_path}: grid.base: missing; name a variant or a config (e.g. dr2track)")
    extra = _overrides(grid.get("overrides"), f"{spec_path}: grid.overrides")
    if isinstance(base, str) and base in named:
        base_source = named[base].source
        base_overrides = {**named[base].overrides, **extra}
    else:
        base_source, base_overrides = base, extra
    base_config, base_source = _load(spec_path, base_source, base_overrides, "grid.base", "grid.base")

    params = _mapping(grid.get("parameters"), f"{spec_path}: grid.parameters",
                      "a mapping of dotted keys to value lists, e.g. {label.mu: [0, 0.1, 0.25]}")
    if not params:
        raise ConfigError(f"{spec_path}: grid.parameters: empty; give at least one dotted key with a list of values")
    parsed: dict[str, tuple[str, list]] = {}
    for key, entry in params.items():
        where = f"{spec_path}: grid.parameters.{key}"
        label = key
        if isinstance(entry, Mapping):
            _check_keys(entry, ("values", "label"), where)
            label = str(entry.get("label") or key)
            entry = entry.get("values")
        if not isinstance(entry, list) or not entry:
            raise ConfigError(f"{where}: expected a non-empty list of values (or {{label: ..., values: [...]}}), "
                              f"got {entry!r}")
        names = [_format_value(v) for v in entry]
        dup = next((n for n in names if names.count(n) > 1), None)
        if dup is not None:
            raise ConfigError(f"{where}: value {dup} is listed twice")
        parsed[str(key)] = (label, list(entry))
    labels = [label for label, _ in parsed.values()]
    dup = next((lab for lab in labels if labels.count(lab) > 1), None)
    if dup is not None:
        raise ConfigError(f"{spec_path}: grid.parameters: two parameters share the label {dup!r}")

    if mode == "sweep":
        points = [{key: value} for key, (_, values) in parsed.items() for value in values]
    else:
        keys = list(parsed)
        points = [dict(zip(keys, combo)) for combo in itertools.product(*(parsed[k][1] for k in keys))]
    variants = []
    for point in points:
        name = ", ".join(f"{parsed[k][0]}={_format_value(v)}" for k, v in point.items())
        where = "grid (" + ", ".join(f"{k}={_format_value(v)}" for k, v in point.items()) + ")"
        config, _ = _load(spec_path, base_source, {**base_overrides, **point}, where, "grid.base")
        variants.append(Variant(name, config, base_source, {**base_overrides, **point}, dict(point)))
    return Grid(str(base), mode, parsed, base_config), variants


def load_spec(source: str | os.PathLike, root: str | os.PathLike | None = None,
              sequences: Iterable[str] | str | None = None) -> AblationSpec:
    """Read and validate an ablation spec (a path, or a shipped name such as ``table3``).

    ``root`` replaces the spec's ``dataset.root`` (relative to the working directory);
    the spec's own root is relative to the spec file. ``sequences`` (names, or one
    comma-separated string) replaces the spec's subset. Every variant's config is resolved
    here, so a wrong key or value fails before anything runs; errors name the spec file
    and the key.
    """
    from .config import _read_yaml
    from .datasets import DatasetError, canonical_name

    path = _find_spec(source)
    data = _read_yaml(path)
    _check_keys(data, SPEC_KEYS, str(path))

    dataset = data.get("dataset")
    if isinstance(dataset, str):
        dataset = {"name": dataset}
    dataset = _mapping(dataset, f"{path}: dataset", "a mapping {name: uav123_10fps, root: path}")
    _check_keys(dataset, ("name", "root"), f"{path}: dataset")
    if not dataset.get("name"):
        raise ConfigError(f"{path}: dataset.name: missing (e.g. uav123_10fps, dtb70, uavdt, otb)")
    try:
        dataset_name = canonical_name(str(dataset["name"]))
    except DatasetError as exc:
        raise ConfigError(f"{path}: dataset.name: {exc}") from None
    if root is not None:
        root_path, origin = Path(root).expanduser().resolve(), "--root"
    elif dataset.get("root"):
        root_path = (path.parent / Path(str(dataset["root"])).expanduser()).resolve()
        origin = f"dataset.root {dataset['root']!r} relative to the spec"
    else:
        root_path, origin = None, "not given"

    where = f"{path}: sequences"
    if sequences is None:
        sequences = data.get("sequences")
    else:
        where = "--sequences (replacing the spec's sequences)"
    if isinstance(sequences, str):
        sequences = [s.strip() for s in sequences.split(",") if s.strip()]
    if sequences is not None:
        if not isinstance(sequences, (list, tuple)) or not sequences or \
                not all(isinstance(s, str) and s for s in sequences):
            raise ConfigError(f"{where}: expected a non-empty list of sequence names, got {sequences!r}")
        sequences = tuple(dict.fromkeys(sequences))

    raw_variants = _mapping(data.get("variants"), f"{path}: variants",
                            "a mapping of variant names to {config: ..., overrides: {...}}")
    named: dict[str, Variant] = {}
    for name, entry in raw_variants.items():
        where = f"variants.{name}"
        if str(name) in named:  # YAML keys 1 and "1" (or true and "True") are one name here
            raise ConfigError(f"{path}: {where}: variant names must be unique, and {name!r} is given twice")
        if isinstance(entry, str):
            entry = {"config": entry}
        entry = _mapping(entry, f"{path}: {where}", "{config: path-or-name, overrides: {dotted.key: value}}")
        _check_keys(entry, VARIANT_KEYS, f"{path}: {where}")
        if "config" not in entry:
            raise ConfigError(f"{path}: {where}.config: missing (a config file relative to the spec, "
                              f"or a shipped name such as dr2track)")
        overrides = _overrides(entry.get("overrides"), f"{path}: {where}.overrides")
        config, src = _load(path, entry["config"], overrides, where, f"{where}.config")
        named[str(name)] = Variant(str(name), config, src, overrides)

    grid, grid_variants = None, []
    if data.get("grid") is not None:
        grid, grid_variants = _parse_grid(path, data["grid"], named)
    for v in grid_variants:
        if v.name in named:
            raise ConfigError(f"{path}: grid point {v.name!r} has the same name as variants.{v.name}; "
                              f"rename the variant")
    if not named and not grid_variants:
        raise ConfigError(f"{path}: no variants and no grid: nothing to run")

    return AblationSpec(path=path, name=str(data.get("name") or path.stem),
                        description=str(data.get("description") or ""), dataset=dataset_name,
                        root=root_path, root_origin=origin, sequences=sequences,
                        variants=tuple(named.values()) + tuple(grid_variants), grid=grid)


def expand(spec: AblationSpec, sequences: Iterable | None = None, version: str | None = None) -> list[Job]:
    """The job list: every variant (spec order) on every sequence (dataset or given order).

    ``sequences`` are names or :class:`dcfkit.datasets.Sequence` objects; default: the
    spec's subset, else every sequence under the spec's root.
    """
    if sequences is None:
        sequences = spec.sequences if spec.sequences is not None else spec.load_sequences()
    names = [s if isinstance(s, str) else s.name for s in sequences]
    from .evaluation import dcfkit_version

    version = version if version is not None else dcfkit_version()
    keys = {v.name: job_key(v.config, version) for v in spec.variants}
    return [Job(v.name, v.config, seq, keys[v.name]) for v in spec.variants for seq in names]


# --------------------------------------------------------------------------- running


def _job_dir(out: Path, dataset: str, key: str) -> Path:
    return out / "jobs" / dataset / key


_worker_ready = False


def _track(config: dict, seq, job_dir: str, key: str, version: str) -> dict:
    """Run one (config, sequence) and write its files (``dcfkit.evaluation``'s runner)."""
    from .evaluation import track_sequence

    folder = Path(job_dir)
    folder.mkdir(parents=True, exist_ok=True)
    return track_sequence(config, seq, folder, None, key, version)


def _run_job(config: dict, seq, job_dir: str, key: str, version: str) -> dict:
    """:func:`_track` in a worker process (pool or dask)."""
    global _worker_ready
    from .evaluation import dcfkit_version, plugin_versions, worker_init

    if not _worker_ready:  # dask workers have no initializer: one OpenCV thread each
        worker_init()
        _worker_ready = True
    if dcfkit_version() != version:
        raise DcfkitError(f"this worker runs dcfkit {dcfkit_version()}, the client {version}; "
                          f"install the same version on every worker")
    if job_key(config, version) != key:
        raise DcfkitError(f"this worker's plugins ({', '.join(plugin_versions(config)) or 'none'}) are not the "
                          f"client's: install the same plugin versions on every worker")
    return _track(config, seq, job_dir, key, version)


@dataclasses.dataclass(frozen=True)
class _Task:
    key: str
    variant: str
    config: dict
    seq: Any  # dcfkit.datasets.Sequence
    folder: Path


def _record_crash(task: _Task, exc: BaseException, version: str) -> dict:
    """A task that died outside the tracker (worker killed, unpicklable, scheduler lost)."""
    from .evaluation import crash_message, record_failure

    return record_failure(task.folder, task.seq, task.config.get("name"), crash_message(task.seq, exc), exc,
                          task.key, version)


def _run_inline(tasks, version, on_result):
    for task in tasks:
        on_result(task, _track(task.config, task.seq, str(task.folder), task.key, version))


def _run_pool(tasks, jobs, version, on_result):
    from .evaluation import run_pool

    run_pool({i: (_run_job, t.config, t.seq, str(t.folder), t.key, version) for i, t in enumerate(tasks)}, jobs,
             lambda i, result: on_result(tasks[i], result), lambda i, exc: _record_crash(tasks[i], exc, version))


def _run_dask(tasks, jobs, scheduler, version, on_result):
    try:
        from distributed import Client, LocalCluster, as_completed as dask_completed
    except ImportError:
        raise DcfkitError("--executor dask needs dask.distributed: pip install 'dcfkit[dask]'") from None
    from .evaluation import single_threaded_env

    with contextlib.ExitStack() as stack:
        if scheduler:
            client = stack.enter_context(Client(scheduler))
        else:
            with single_threaded_env():  # inherited by the worker processes
                cluster = stack.enter_context(LocalCluster(
                    n_workers=max(1, min(jobs, len(tasks))), threads_per_worker=1, processes=True,
                    dashboard_address=None))
            client = stack.enter_context(Client(cluster))
        futures = [client.submit(_run_job, t.config, t.seq, str(t.folder), t.key, version,
                                 key=f"dcfkit-ablate-{t.key}-{t.seq.dataset}-{t.seq.name}", pure=False)
                   for t in tasks]
        by_key = {f.key: t for f, t in zip(futures, tasks)}
        try:
            for future in dask_completed(futures):
                task = by_key[future.key]
                try:
                    result = future.result()
                except Exception as exc:
                    result = _record_crash(task, exc, version)
                on_result(task, result)
        except BaseException:
            client.cancel(futures)
            raise


def run_ablation(spec: AblationSpec, out, jobs: int | None = None, executor: str = "local",
                 scheduler: str | None = None, progress: bool = True, protocol: str = DEFAULT) -> dict:
    """Run every job of ``spec`` not already done under ``out``, then write the summary
    (scored under ``protocol``, see :mod:`dcfkit.protocols`).

    ``executor`` is ``"local"`` (``jobs`` spawned worker processes, default: the usable
    cores; ``jobs=1`` runs in this process) or ``"dask"`` (``Client(scheduler)``, or a
    ``LocalCluster`` of ``jobs`` single-threaded worker processes when ``scheduler`` is
    None; workers need the dataset and ``out`` at the same paths). A failing job is
    recorded (``.error.json``) and does not stop the others.

    Returns a plain dict: ``jobs`` (the :class:`Job` list), ``runs`` (distinct
    (key, sequence) pairs), ``done`` / ``skipped`` / ``failed`` (run -> message) and
    ``summary`` (what :func:`summarize` returned).
    """
    from .evaluation import atomic_write, dcfkit_version, exclusive, is_done, make_dir, read_json

    if executor not in ("local", "dask"):
        raise DcfkitError(f"executor must be 'local' or 'dask', got {executor!r}")
    jobs = jobs if jobs is not None else _usable_cores()
    if jobs < 1:
        raise DcfkitError(f"--jobs must be >= 1, got {jobs}")
    out = Path(out).expanduser().resolve()
    seqs = spec.load_sequences()
    version = dcfkit_version()
    job_list = expand(spec, seqs, version)
    by_name = {s.name: s for s in seqs}

    make_dir(out)
    with exclusive(out / ".lock", "dcfkit ablate", f"to {out}"):
        for stale in (out / "jobs").glob("*/*/.*.tmp"):  # left by a killed run; never read
            with contextlib.suppress(OSError):
                stale.unlink()
        tasks: dict[tuple[str, str], _Task] = {}
        variants = variant_names(job_list)
        for job in job_list:
            if (job.key, job.sequence) not in tasks:
                tasks[job.key, job.sequence] = _Task(job.key, job.variant, job.config, by_name[job.sequence],
                                                     _job_dir(out, spec.dataset, job.key))
        for folder in {t.folder for t in tasks.values()} | {out / "configs"}:  # before anything runs
            make_dir(folder)
        for job in {j.key: j for j in job_list}.values():
            path = out / "configs" / f"{job.key}.json"
            if (read_json(path) or {}).get("key") != job.key:  # missing or damaged: (re)write the record
                stripped = {k: v for k, v in job.config.items() if k not in LABEL_KEYS}
                atomic_write(path, json.dumps({"key": job.key, "dcfkit_version": version,
                                               "config": stripped}, indent=1) + "\n")
        finished = {k for k, t in tasks.items() if is_done(t.folder, t.seq, t.key)}
        todo = sorted((t for k, t in tasks.items() if k not in finished),
                      key=lambda t: -len(t.seq))  # longest first: the workers end together
        result = {"jobs": job_list, "runs": len(tasks), "done": [],
                  "skipped": [k for k in tasks if k in finished], "failed": {}}

        from tqdm.auto import tqdm

        bar = tqdm(total=len(tasks), initial=len(tasks) - len(todo), unit="job", desc=spec.name,
                   disable=not progress or not todo, dynamic_ncols=True)

        def on_result(task: _Task, res: dict) -> None:
            if res["status"] == "done":
                result["done"].append((task.key, task.seq.name))
            else:
                result["failed"][task.key, task.seq.name] = res["error"]
                bar.write(f"FAILED {', '.join(variants[task.key])}: {res['error']}")
            bar.set_postfix_str(f"{task.variant} / {task.seq.name}", refresh=False)
            bar.update(1)

        try:
            if todo:
                if executor == "dask":
                    _run_dask(todo, jobs, scheduler, version, on_result)
                elif jobs == 1 or len(todo) == 1:
                    _run_inline(todo, version, on_result)
                else:
                    _run_pool(todo, jobs, version, on_result)
        finally:
            bar.close()
        result["summary"] = summarize(spec, out, seqs, job_list, protocol)
    return result


def _usable_cores() -> int:
    with contextlib.suppress(AttributeError):
        return max(1, len(os.sched_getaffinity(0)))
    return max(1, os.cpu_count() or 1)


# --------------------------------------------------------------------------- summary

SUMMARY_COLUMNS = ("variant", "precision", "auc", "fps", "sequences", "failed")
SEQUENCE_COLUMNS = ("variant", "sequence", "precision", "auc", "fps", "frames", "status")


def summary_columns(table: str, protocol: str = DEFAULT) -> tuple[str, ...]:
    """:data:`SUMMARY_COLUMNS` (``table="summary"``) or :data:`SEQUENCE_COLUMNS`
    (``"per_sequence"``), with AO, SR@0.5 and SR@0.75 after the AUC under ``got10k``."""
    base = SUMMARY_COLUMNS if table == "summary" else SEQUENCE_COLUMNS
    i = base.index("auc") + 1
    return base[:i] + get_protocol(protocol).overlap_keys + base[i:]


def _status(folder: Path, seq) -> tuple[str, str | None]:
    from .evaluation import is_done, read_json

    if is_done(folder, seq, folder.name):
        return "done", None
    err = read_json(folder / f"{seq.name}.error.json")
    if err is not None and err.get("config_hash") == folder.name:
        return "failed", err.get("error")
    return "missing", None


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
    from .evaluation import load_results
    from .report import json_ready, evaluate

    out = Path(out)
    jobs = jobs if jobs is not None else expand(spec, sequences)
    by_name = {s.name: s for s in sequences}
    keys = {j.variant: j.key for j in jobs}
    status: dict[tuple[str, str], tuple[str, str | None]] = {}
    stored: dict[str, dict] = {}
    for key in dict.fromkeys(keys.values()):
        folder = _job_dir(out, spec.dataset, key)
        names = [j.sequence for j in jobs if j.key == key]
        for name in dict.fromkeys(names):
            status[key, name] = _status(folder, by_name[name])
        done = [by_name[n] for n in dict.fromkeys(names) if status[key, n][0] == "done"]
        stored[key] = load_results(folder.parent, key, done) if done else {}
    results = {variant: stored[key] for variant, key in keys.items()}
    with _quiet(logging.getLogger("dcfkit.report")):  # missing runs are counted in 'failed'
        scores = evaluate(results, sequences, protocol=protocol)
    extra = get_protocol(protocol).overlap_keys

    order = {v: i for i, v in enumerate(keys)}
    seq_order = {s.name: i for i, s in enumerate(sequences)}
    overall = sorted(({"variant": r["tracker"], "precision": r["precision"], "auc": r["auc"],
                       **{k: r[k] for k in extra}, "fps": r["fps"],
                       "sequences": r["sequences"], "failed": r["missing"], "key": keys[r["tracker"]]}
                      for r in scores["overall"]), key=lambda r: order[r["variant"]])
    per_sequence = sorted(({"variant": r["tracker"], "sequence": r["sequence"], "precision": r["precision"],
                            "auc": r["auc"], **{k: r[k] for k in extra}, "fps": r["fps"],
                            "frames": len(by_name[r["sequence"]]),
                            "status": status[keys[r["tracker"]], r["sequence"]][0]}
                           for r in scores["per_sequence"]),
                          key=lambda r: (order[r["variant"]], seq_order[r["sequence"]]))
    job_rows = [{"variant": j.variant, "sequence": j.sequence, "key": j.key,
                 "status": status[j.key, j.sequence][0], "error": status[j.key, j.sequence][1]} for j in jobs]

    from .evaluation import atomic_write

    files = []
    for stem, rows in (("summary", overall), ("per_sequence", per_sequence)):
        for fmt, ext in (("markdown", "md"), ("csv", "csv")):
            path = out / f"{stem}.{ext}"
            atomic_write(path, format_table(rows, fmt, summary_columns(stem, protocol), protocol))
            files.append(path)
    info = {"spec": str(spec.path), "name": spec.name, "description": spec.description,
            "protocol": scores["protocol"],
            "dataset": spec.dataset, "root": str(spec.root), "sequences": [s.name for s in sequences],
            "overall": overall, "per_sequence": per_sequence, "jobs": job_rows,
            "grid": ({"base": spec.grid.base, "mode": spec.grid.mode,
                      "parameters": {k: {"label": lab, "values": vals}
                                     for k, (lab, vals) in spec.grid.parameters.items()}}
                     if spec.grid else None)}
    path = out / "summary.json"
    atomic_write(path, json.dumps(json_ready(info), indent=1, ensure_ascii=False, default=str) + "\n")
    files.append(path)
    if spec.grid is not None:
        files += plot_sensitivity(spec, overall, out, protocol)
    else:  # named variants: the OTB plots, one curve each
        from .report import plot_curves

        for kind in ("precision", "success"):
            files += plot_curves(scores["curves"], kind, out / kind, protocol=protocol)
    return {"overall": overall, "per_sequence": per_sequence, "jobs": job_rows, "files": files}


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
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    grid = spec.grid
    rows = {r["variant"]: r for r in overall}
    points = [v for v in spec.variants if v.values]
    paths = []
    for key, (label, values) in grid.parameters.items():
        numeric = all(_is_number(v) for v in values)
        names = [_format_value(v) for v in values]
        xs = [float(v) for v in values] if numeric else list(range(len(values)))
        fig = Figure(figsize=(4.6, 3.6))
        FigureCanvasAgg(fig)
        ax = fig.add_subplot(1, 1, 1)
        for metric, legend, colour, marker in (("precision", "precision@20", "C3", "o"),
                                               ("auc", "AUC", "C0", "s")):
            mean, low, high = [], [], []
            for name in names:
                scores = [rows[p.name][metric] for p in points
                          if key in p.values and _format_value(p.values[key]) == name]
                scores = [s for s in scores if s is not None and math.isfinite(s)]
                mean.append(sum(scores) / len(scores) if scores else math.nan)
                low.append(min(scores) if scores else math.nan)
                high.append(max(scores) if scores else math.nan)
            ax.plot(xs, mean, color=colour, marker=marker, linewidth=1.8, label=legend)
            if grid.mode == "product" and len(grid.parameters) > 1:
                ax.fill_between(xs, low, high, color=colour, alpha=0.15, linewidth=0)
        base = _get_dotted(grid.base_config, key)
        base_x = (float(base) if numeric and _is_number(base) else
                  names.index(_format_value(base)) if not numeric and _format_value(base) in names else None)
        if base_x is not None:
            ax.axvline(base_x, color="0.5", linestyle=":", linewidth=1, label=f"base ({_format_value(base)})")
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
        safe = "".join(c if c.isalnum() or c in "._-" else "_" for c in key)
        path = Path(out) / f"sensitivity_{safe}.png"
        fig.savefig(path, dpi=150)
        paths.append(path)
    return paths


# --------------------------------------------------------------------------- CLI


def add_ablate_arguments(parser: argparse.ArgumentParser) -> argparse.ArgumentParser:
    """Arguments of ``dcfkit ablate``."""
    parser.add_argument("spec", metavar="SPEC",
                        help="ablation spec YAML, or a shipped name (table3, sensitivity)")
    parser.add_argument("--out", required=True, type=Path,
                        help="results folder (OUT/jobs/..., OUT/summary.md, ...); reruns resume")
    parser.add_argument("--jobs", type=int, default=None,
                        help="worker processes (default: the usable cores); with dask and no "
                             "--scheduler, the LocalCluster's workers")
    parser.add_argument("--executor", choices=("local", "dask"), default=None,
                        help="local process pool (default) or dask.distributed (default with --scheduler)")
    parser.add_argument("--scheduler", default=None, metavar="ADDR",
                        help="dask scheduler address, e.g. tcp://10.0.0.5:8786 (default: a LocalCluster)")
    parser.add_argument("--root", type=Path, default=None,
                        help="benchmark root folder (default: the spec's dataset.root, relative to the spec)")
    parser.add_argument("--sequences", default=None,
                        help="comma-separated sequence names (default: the spec's, else all)")
    add_protocol_argument(parser)
    parser.add_argument("--dry-run", action="store_true",
                        help="list the jobs and whether each is done; run nothing")
    parser.add_argument("--no-progress", action="store_true", help="no progress bar")
    return parser


def cmd_ablate(args: argparse.Namespace) -> int:
    """``dcfkit ablate``: run a spec, print the summary table; exit status 1 if a job failed."""
    executor = args.executor or ("dask" if args.scheduler else "local")
    if args.scheduler and executor != "dask":
        raise DcfkitError("--scheduler needs --executor dask")
    spec = load_spec(args.spec, root=args.root, sequences=args.sequences)
    if args.dry_run:
        from .evaluation import is_done

        seqs = spec.load_sequences()
        by_name = {s.name: s for s in seqs}
        out = args.out.expanduser().resolve()
        jobs = expand(spec, seqs)
        for job in jobs:
            done = is_done(_job_dir(out, spec.dataset, job.key), by_name[job.sequence], job.key)
            print(f"{'done' if done else 'todo'}  {job.key}  {job.variant}  {job.sequence}")
        print(f"{len(jobs)} jobs, {len({(j.key, j.sequence) for j in jobs})} distinct runs")
        return 0
    res = run_ablation(spec, args.out, jobs=args.jobs, executor=executor, scheduler=args.scheduler,
                       progress=not args.no_progress, protocol=args.protocol)

    summary = res["summary"]
    print(format_table(summary["overall"], "markdown", summary_columns("summary", args.protocol), args.protocol),
          end="")
    print(f"\n{spec.name}: {len(res['jobs'])} jobs ({res['runs']} distinct runs): {len(res['done'])} run, "
          f"{len(res['skipped'])} already done, {len(res['failed'])} failed -> {Path(args.out)}")
    variants = variant_names(res["jobs"])
    for (key, seq), message in res["failed"].items():
        print(f"  FAILED {', '.join(variants.get(key, []))} [{key}] {message}")
    return 1 if res["failed"] else 0

"""Ablation runs: named variants and parameter grids of tracker configs, run on a benchmark.

A spec (YAML, see ``docs/ablation.md``) names a dataset, variants (a config plus dotted
overrides) and optionally a grid of parameter values around a base config. It expands to
a deterministic job list, one :class:`Job` per (variant, sequence), each carrying the fully
resolved config of :func:`dcfkit.config.load_config`.

Results are stored per *run*, keyed by what determines the boxes::

    OUT/jobs/<dataset>/<key>/<sequence>.txt          1-based x,y,w,h per frame
    OUT/jobs/<dataset>/<key>/<sequence>.time         seconds per frame (as dcfkit eval)
    OUT/jobs/<dataset>/<key>/<sequence>.confidence   peak,apce per frame (as dcfkit eval)
    OUT/jobs/<dataset>/<key>/<sequence>.json         sidecar (times, fps, config hash); marks done
    OUT/jobs/<dataset>/<key>/<sequence>.error        instead, when the tracker raised
    OUT/configs/<key>.json                           the config behind <key>

``key`` is :func:`dcfkit.running.provenance.run_key` of the resolved config (``dcfkit eval`` uses the
same key), so two variants with the same parameters (the base point of every one-at-a-time
sweep) share one run. Each ``OUT/jobs/<dataset>/<key>/`` is a
:class:`dcfkit.running.results.ResultStore`, written by :mod:`dcfkit.running.runner`: a rerun skips intact
runs and retries failed and damaged ones.

Runs go to a local process pool (spawned workers, one BLAS/OpenMP/OpenCV thread each,
killed with the parent) or to dask.distributed. Then ``OUT/summary.{md,csv}``,
``OUT/per_sequence.{md,csv}``, ``OUT/summary.json`` and, for a grid, one
``OUT/sensitivity_<parameter>.png`` per parameter (else ``OUT/precision`` and
``OUT/success`` plots, PNG and SVG) and ``OUT/report.html`` (:mod:`dcfkit.analysis.report_html`: the
variants with their config changes from the base, sensitivity plots, tables, plots, frames) are
written.
"""
from __future__ import annotations

from dcfkit.ablation.run import run_ablation
from dcfkit.ablation.sensitivity import plot_sensitivity, sensitivity
from dcfkit.ablation.spec import AblationSpec, Grid, Job, Variant, expand, job_dir, load_spec, variant_names
from dcfkit.ablation.summary import SEQUENCE_COLUMNS, SUMMARY_COLUMNS, summarize, summary_columns

__all__ = ["AblationSpec", "Grid", "Job", "SEQUENCE_COLUMNS", "SUMMARY_COLUMNS", "Variant", "expand", "job_dir",
           "load_spec", "plot_sensitivity", "run_ablation", "sensitivity", "summarize", "summary_columns",
           "variant_names"]

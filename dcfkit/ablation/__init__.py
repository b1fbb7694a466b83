"""Ablation runs: named variants and parameter grids of tracker configs, run on a benchmark.

A spec (YAML, docs/ablation.md) names a dataset, variants (a config plus dotted overrides)
and optionally a grid around a base config. It expands to one :class:`Job` per (variant,
sequence) with its resolved config; each variant's runs are stored in ``OUT/<variant>/`` (a
:class:`~dcfkit.store.results.ResultStore`, as ``dcfkit eval``'s tracker folders:
:mod:`dcfkit.ablation.layout`), variants with the same parameters (one run key) share each
run, tracked once, and a rerun skips intact runs. Runs go to
a local process pool or dask.distributed; the summary tables, plots and ``report.html``
follow (docs/ablation.md lists the files).
"""
from __future__ import annotations

from dcfkit.ablation.layout import variant_folders
from dcfkit.ablation.run import run_ablation
from dcfkit.ablation.sensitivity import plot_sensitivity, sensitivity
from dcfkit.ablation.spec import AblationSpec, Grid, Job, Variant, expand, load_spec, variant_names
from dcfkit.ablation.summary import SEQUENCE_COLUMNS, SUMMARY_COLUMNS, summarize, summary_columns

__all__ = ["AblationSpec", "Grid", "Job", "SEQUENCE_COLUMNS", "SUMMARY_COLUMNS", "Variant", "expand",
           "load_spec", "plot_sensitivity", "run_ablation", "sensitivity", "summarize", "summary_columns",
           "variant_folders", "variant_names"]

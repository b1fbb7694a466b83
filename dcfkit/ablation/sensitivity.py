"""Fig. 6 of the paper: per grid parameter, precision and AUC against its value, as data
(:func:`sensitivity`, which the HTML page draws) and as PNG figures (:func:`plot_sensitivity`)."""
from __future__ import annotations

import math
from pathlib import Path
from typing import Any

from dcfkit.ablation.experiment import scope_title
from dcfkit.ablation.spec import AblationSpec, format_value
from dcfkit.analysis.plots import save_figure
from dcfkit.config.overrides import get_dotted
from dcfkit.protocols import DEFAULT

METRICS = (("precision", "precision@20", "C3", "o", "#d62728"), ("auc", "AUC", "C0", "s", "#1f77b4"))


def _is_number(value: Any) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)


def _stats(scores: list) -> tuple[float, float, float]:
    scores = [s for s in scores if s is not None and math.isfinite(s)]
    if not scores:
        return math.nan, math.nan, math.nan
    return sum(scores) / len(scores), min(scores), max(scores)


def sensitivity(spec: AblationSpec, overall: list[dict]) -> list[dict]:
    """Per grid parameter of ``spec``, the scores of the summary rows ``overall`` against its
    values: ``key``, ``label``, ``names`` (the values as written), ``x`` (the values, or their
    places when not all numeric), ``metrics`` (metric -> (mean, low, high) lists), ``band``
    (whether low-high is a range: product mode with several parameters), ``base_x`` and
    ``base_name`` (the base config's value, None off the axis) and ``title``.

    Sweep: the grid points of that parameter (the others at the base). Product: the mean
    over the other parameters' values, with their min-max as the band.
    """
    grid = spec.grid
    rows = {r["variant"]: r for r in overall}
    points = [v for v in spec.variants if v.values]
    band = grid.mode == "product" and len(grid.parameters) > 1
    what = "mean over the other parameters" if band else "others at the base"
    n_seq = overall[0]["sequences"] if overall else 0
    out = []
    for key, (label, values) in grid.parameters.items():
        numeric = all(_is_number(v) for v in values)
        names = [format_value(v) for v in values]
        metrics = {}
        for metric, *_ in METRICS:
            stats = [_stats([rows[p.name][metric] for p in points
                             if key in p.values and format_value(p.values[key]) == name]) for name in names]
            metrics[metric] = tuple(list(column) for column in zip(*stats))
        base = get_dotted(grid.base_config, key)
        base_x = (float(base) if numeric and _is_number(base) else
                  names.index(format_value(base)) if not numeric and format_value(base) in names else None)
        out.append({"key": key, "label": label, "names": names, "numeric": numeric,
                    "x": [float(v) for v in values] if numeric else list(range(len(values))),
                    "metrics": metrics, "band": band, "base_x": base_x, "base_name": format_value(base),
                    "axis": label if label == key else f"{label} ({key})",
                    "title": f"{label} on {spec.dataset} ({n_seq} sequences, "
                             f"{scope_title(spec.experiment, spec.max_frames)}), {what}"})
    return out


def plot_sensitivity(spec: AblationSpec, overall: list[dict], out, protocol: str = DEFAULT) -> list[Path]:
    """Fig. 6 of the paper from :func:`sensitivity`: one PNG per grid parameter, precision and
    AUC against its value, the base value a dotted vertical line (product mode: the min-max
    band). Writes ``OUT/sensitivity_<key>.png``; returns the paths."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg  # lazy: matplotlib is slow to import,
    from matplotlib.figure import Figure  # and only plots need it

    paths = []
    for param in sensitivity(spec, overall):
        fig = Figure(figsize=(4.6, 3.6))
        FigureCanvasAgg(fig)
        ax = fig.add_subplot(1, 1, 1)
        for metric, legend, colour, marker, _ in METRICS:
            mean, low, high = param["metrics"][metric]
            ax.plot(param["x"], mean, color=colour, marker=marker, linewidth=1.8, label=legend)
            if param["band"]:
                ax.fill_between(param["x"], low, high, color=colour, alpha=0.15, linewidth=0)
        if param["base_x"] is not None:
            ax.axvline(param["base_x"], color="0.5", linestyle=":", linewidth=1, label=f"base ({param['base_name']})")
        ax.set_xticks(param["x"])
        ax.set_xticklabels(param["names"])
        ax.set_xlabel(param["axis"])
        ax.set_ylabel("score")
        ax.set_title(f"{param['title']} [protocol {protocol}]", fontsize=9)
        ax.grid(True, linestyle=":", linewidth=0.6)
        ax.legend(fontsize=8)
        fig.tight_layout()
        path = Path(out) / sensitivity_file(param["key"])
        save_figure(fig, path)
        paths.append(path)
    return paths


def sensitivity_file(key: str) -> str:
    return "sensitivity_" + "".join(c if c.isalnum() or c in "._-" else "_" for c in key) + ".png"

"""The ablation's ``report.html``: the variants with what each changes from the base config,
the sensitivity plots of a grid, then the plots, tables and frames of any report."""
from __future__ import annotations

from pathlib import Path
from typing import Any, Mapping

from dcfkit.ablation.experiment import scope_title
from dcfkit.ablation.sensitivity import METRICS, sensitivity
from dcfkit.ablation.spec import AblationSpec, format_value
from dcfkit.ablation.spec_keys import data_text
from dcfkit.analysis.report_html import evaluation_sections, sections
from dcfkit.analysis.report_html.provenance import this_process
from dcfkit.store.provenance import LABEL_KEYS, shared_path


def flatten(config: Any, prefix: str = "") -> dict[str, Any]:
    """Dotted key -> value of every leaf of ``config``; lists of mappings (``features``) by index."""
    if isinstance(config, Mapping):
        items = config.items()
    elif isinstance(config, list) and config and all(isinstance(v, Mapping) for v in config):
        items = enumerate(config)
    else:
        return {prefix: config}
    out: dict[str, Any] = {}
    for key, value in items:
        out.update(flatten(value, f"{prefix}.{key}" if prefix else str(key)))
    return out


def config_changes(base: Mapping, config: Mapping) -> list[str]:
    """``key: base value -> value`` for each dotted key where ``config`` differs from ``base``
    (``name`` and ``description`` left out: they change no box), in config order. Where a
    component is replaced (its ``name`` changes), the old one's parameters are not listed."""
    old = flatten({k: v for k, v in base.items() if k not in LABEL_KEYS})
    new = flatten({k: v for k, v in config.items() if k not in LABEL_KEYS})
    missing = object()
    replaced = tuple(k.removesuffix("name") for k in old if k.endswith(".name") and k in new and old[k] != new[k])
    changes = []
    for key in dict.fromkeys([*old, *new]):
        a, b = old.get(key, missing), new.get(key, missing)
        if a != b and not (b is missing and key.startswith(replaced)):
            shown = ["(none)" if v is missing else format_value(v) for v in (a, b)]
            changes.append(f"{key}: {shown[0]} \u2192 {shown[1]}")
    return changes


def _base(spec: AblationSpec) -> tuple[str, dict]:
    """(name, config) the variants are compared with: the grid's base, else the first variant."""
    if spec.grid is not None:
        return f"the grid's base ({spec.grid.base})", spec.grid.base_config
    return spec.variants[0].name, spec.variants[0].config


def variants_table(spec: AblationSpec, overall: list[dict], columns: tuple[str, ...], trackers: list[str],
                   fps_note: str | None = None) -> dict:
    """The summary's rows (in ``columns``, the first the variant) with each variant's config
    changes from the base; ``fps_note`` (:func:`dcfkit.store.timing.fps_note`) ends its note."""
    base_name, base = _base(spec)
    configs = {v.name: v.config for v in spec.variants}
    published = dict(spec.published)
    rows = [{**r, "changes": [f"published results: {published[r['variant']]}"] if r["variant"] in published
             else config_changes(base, configs[r["variant"]]) or ["(same as the base)"]} for r in overall]
    table = sections.table("variants", "Variants", rows, ("variant", "changes", *columns[1:], "key"), trackers,
                           tracker_column="variant",
                           note=f"Changes from {base_name}, config key by config key. Click a column's name to "
                                f"sort by it.{' ' + fps_note if fps_note else ''}")
    for column in table["columns"]:
        if column["key"] == "changes":
            column.update(type="lines", label="changes from the base")
    return table


def sensitivity_charts(spec: AblationSpec, overall: list[dict]) -> dict:
    """One chart per grid parameter: precision and AUC against its values, the base marked."""
    charts = []
    for param in sensitivity(spec, overall):
        x = param["x"]
        base = param["base_x"]
        span = x + ([] if base is None else [base])  # a base off the swept values is still drawn
        pad = (max(span) - min(span)) * 0.06 or 0.5
        series = [{"key": metric, "label": legend, "color": colour, "marker": True,
                   "y": param["metrics"][metric][0],
                   **({"low": param["metrics"][metric][1], "high": param["metrics"][metric][2]}
                      if param["band"] else {})}
                  for metric, legend, _, _, colour in METRICS]
        vline = None if base is None else {"x": base, "label": f"dotted: base ({param['base_name']})"}
        charts.append({"title": param["title"], "xlabel": param["axis"], "ylabel": "score", "x": x,
                       "xlim": [min(span) - pad, max(span) + pad], "xticks": [list(t) for t in zip(x, param["names"])],
                       "series": series, "vline": vline})
    return {"kind": "charts", "id": "sensitivity", "title": "Sensitivity", "charts": charts}


def ablation_page(spec: AblationSpec, out: Path, info: Mapping, columns: tuple[str, ...], scores: Mapping,
                  sequences: list, results: Mapping[str, Mapping], keys: Mapping[str, str]) -> dict:
    """The page of an ablation: ``info`` is its ``summary.json`` (the summary table in
    ``columns``, each variant's ``folders``), ``scores`` what :func:`dcfkit.analysis.scoring.evaluate` returned for ``results``
    (variant -> sequence -> result), ``keys`` variant -> run key."""
    trackers = [*keys, *(name for name, _ in spec.published)]
    head = [variants_table(spec, info["overall"], columns, trackers, info.get("fps_note"))]
    statistics = sections.statistics_table(info["statistics"], trackers, tracker_label="variant")
    if statistics is not None:
        head.append(statistics)
    if spec.grid is not None:
        head.append(sensitivity_charts(spec, info["overall"]))
    folders = {**{v: out / info["folders"][v] for v in keys}, **dict(spec.published)}
    extra = [("spec", shared_path(spec.path, out)), ("dataset", data_text(spec, out))]
    return {"title": f"dcfkit ablation {spec.name}: {sections.count(len(trackers), 'variant')} on {spec.dataset}, "
                     f"{scope_title(spec.experiment, spec.max_frames)}",
            "protocol": scores.protocol.describe(),
            "subtitle": f"{spec.description + ' · ' if spec.description else ''}{info['scope']} · "
                        f"{sections.count(len(sequences), 'sequence')}, {sum(len(s) for s in sequences)} frames",
            "trackers": trackers,
            "sections": [*head, *evaluation_sections(scores, sequences, results, trackers),
                         sections.provenance(folders, [s.name for s in sequences], trackers, this_process(), extra,
                                             base=out)]}

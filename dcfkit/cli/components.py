"""``dcfkit components``: every registered component, its parameters with their defaults and
bounds, and what its ``Params.validate`` checks of them together, as a table, Markdown (also
used for docs/configs.md) or JSON."""
from __future__ import annotations

import argparse
import inspect
import json
import sys
import warnings
from typing import Any, Iterable

import yaml

from dcfkit.config.slots import KINDS
from dcfkit.opencv_check import contrib_problem
from dcfkit.params import Bounds, fields
from dcfkit.registry import PluginWarning, get_registry


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--kind", choices=KINDS)
    parser.add_argument("--format", choices=("table", "markdown", "json"), default="table")


def run(args: argparse.Namespace) -> int:
    """List the components; exit status 1 if a plugin could not be loaded. A cv2 without
    OpenCV's contrib modules is warned about (:mod:`dcfkit.opencv_check`)."""
    with warnings.catch_warnings():  # the skipped plugins are listed below, each once
        warnings.simplefilter("ignore", PluginWarning)
        registry = get_registry()
    rows = component_rows(registry, [args.kind] if args.kind else None)
    if args.format == "json":
        print(json.dumps(rows, indent=2, default=str))
    elif args.format == "markdown":
        print(components_markdown(rows), end="")
    else:
        for row in rows:
            print(f"{row['kind']:<12} {row['name']:<22} {row['doc']}  [{row['provider']}]")
            for f in row["params"]:
                bounds = f", {f['bounds']}" if f["bounds"] else ""
                print(f"{'':<14}{f['name']} ({f['type']}, default {f['default']}{bounds}): {f['help']}")
            if row["checks"]:
                print(f"{'':<14}also: {row['checks']}")
    for failure in registry.failures:
        print(f"warning: {failure}", file=sys.stderr)
    problem = contrib_problem()  # the colornames feature listed above needs OpenCV's contrib build
    if problem:
        print(f"warning: {problem}", file=sys.stderr)
    return 1 if registry.failures else 0


def summary(cls: Any) -> str:
    """First paragraph of a class's (or function's) docstring, on one line ('' without one)."""
    doc = inspect.cleandoc(cls.__doc__ or "")
    return " ".join(doc.split("\n\n")[0].split())


def checks(schema: type) -> str:
    """What ``schema.validate`` checks beyond each field's bounds: its docstring's first
    paragraph ('' without one)."""
    validate = getattr(schema, "validate", None)
    return summary(validate) if validate is not None else ""


def params_of(entry) -> list[dict]:
    """:func:`dcfkit.params.fields` of a registered component's ``Params``; a field the
    tracker reads (its kind's contract) and that declares no bounds shows the contract's."""
    params = fields(entry.cls.Params)
    for f in params:
        if f["bounds"] is None and f["name"] in entry.contract.params:
            _, low, high = entry.contract.params[f["name"]]
            f["bounds"] = str(Bounds(low, high))
    return params


def component_rows(registry, kinds: Iterable[str] | None = None) -> list[dict]:
    """One dict per registered component: kind, name, provider, doc, params, checks (what its
    ``Params.validate`` checks, from its docstring; '' without) and, for a regularizer, role."""
    rows = []
    for kind in kinds or KINDS:
        for name in registry.names(kind):
            entry = registry.entry(kind, name)
            row = {"kind": kind, "name": name, "provider": entry.provider, "doc": summary(entry.cls),
                   "params": params_of(entry), "checks": checks(entry.cls.Params)}
            if kind == "regularizer":
                row["role"] = getattr(entry.cls, "role", None)
            rows.append(row)
    return rows


def yaml_value(value: Any) -> str:
    """A default as it would be written in YAML: ``true``, ``null``, ``[1, 2]``, ``''``."""
    if isinstance(value, tuple):
        value = list(value)
    text = yaml.safe_dump(value, default_flow_style=True, allow_unicode=True, width=1000).strip()
    return text.removesuffix("\n...").removesuffix("...").strip()


def cell(text: Any) -> str:
    """``text`` for a Markdown table cell."""
    return str(text).replace("|", "\\|").replace("\n", " ")


def params_table(params: list[dict]) -> str:
    """Markdown table of :func:`dcfkit.params.fields` output."""
    if not params:
        return "No parameters.\n"
    lines = ["| parameter | type | default | range | description |", "|---|---|---|---|---|"]
    for f in params:
        help_ = f["help"] + (f" (one of: {', '.join(f'`{c}`' for c in f['choices'])})" if f["choices"] else "")
        bounds = f"`{cell(f['bounds'])}`" if f["bounds"] else ""
        lines.append(f"| `{f['name']}` | {cell(f['type'])} | `{cell(yaml_value(f['default']))}` | {bounds} "
                     f"| {cell(help_)} |")
    return "\n".join(lines) + "\n"


def components_markdown(rows: list[dict], level: int = 3) -> str:
    """Each component as a heading, its docstring summary, provider, role and parameter table."""
    out = []
    for row in rows:
        role = f" Role: `{row['role']}`." if row.get("role") else ""
        checks = f"\nAlso checked: {row['checks']}\n" if row["checks"] else ""
        out.append(f"{'#' * level} {row['kind']} `{row['name']}`\n\n{row['doc']} (from {row['provider']}){role}\n\n"
                   f"{params_table(row['params'])}{checks}")
    return "\n".join(out)



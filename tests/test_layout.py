"""The package's layout keeps showing its architecture: small functions, no import cycles, a
library without argparse, and a reason on every import deferred into a function."""
from __future__ import annotations

import ast
import subprocess
import sys
from pathlib import Path

import grimp
import mccabe
import pytest

import dcfkit

PACKAGE = Path(__file__).resolve().parents[1] / "dcfkit"
MAX_LINES = 60  # of a function's body, its docstring left out
MAX_COMPLEXITY = 15  # McCabe, as flake8 counts it
NOT_SPLIT = "Not split:"  # how a docstring gives the reason for a longer or more complex function


def sources() -> list[Path]:
    return sorted(PACKAGE.rglob("*.py"))


def functions(tree: ast.AST):
    for node in ast.walk(tree):
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
            yield node


def body_lines(node) -> int:
    body = node.body
    if body and isinstance(body[0], ast.Expr) and isinstance(body[0].value, ast.Constant) \
            and isinstance(body[0].value.value, str):
        body = body[1:]
    return (body[-1].end_lineno - body[0].lineno + 1) if body else 0


def complexities(tree: ast.AST) -> dict[int, int]:
    """First line of each function -> its McCabe complexity (nested functions counted apart)."""
    visitor = mccabe.PathGraphingAstVisitor()
    visitor.preorder(tree, visitor)
    return {graph.lineno: graph.complexity() for graph in visitor.graphs.values()}


def test_functions_are_small_or_say_why_not():
    offenders = []
    for path in sources():
        tree = ast.parse(path.read_text(encoding="utf-8"), str(path))
        cc = complexities(tree)
        for node in functions(tree):
            lines, complexity = body_lines(node), cc.get(node.lineno, 1)
            if (lines > MAX_LINES or complexity > MAX_COMPLEXITY) and NOT_SPLIT not in (ast.get_docstring(node) or ""):
                offenders.append(f"{path.relative_to(PACKAGE.parent)}:{node.lineno} {node.name}: "
                                 f"{lines} lines, complexity {complexity}")
    assert not offenders, "split these, or give the reason in a 'Not split:' paragraph:\n" + "\n".join(offenders)


def test_the_checker_sees_a_long_and_a_complex_function(tmp_path):
    branches = "\n".join(f"    if x == {i}:\n        return {i}" for i in range(20))
    tree = ast.parse(f"def f(x):\n    '''Doc.'''\n{branches}\n    return -1\n")
    (node,) = functions(tree)
    assert body_lines(node) == 41 and complexities(tree)[1] == 21


@pytest.fixture(scope="module")
def graph():
    return grimp.build_graph("dcfkit", include_external_packages=True, cache_dir=None)


def with_entry_points(graph):
    """``graph`` with an import from the registry of each module dcfkit's own entry points name:
    the registry loads them, so a cycle through one is a cycle."""
    from dcfkit.registry import plugin_entry_points  # deferred: the graph is built from files first

    for ep in plugin_entry_points(external=False)[0]:
        graph.add_import(importer="dcfkit.registry", imported=ep.module)
    return graph


def import_cycles(graph) -> list[tuple[str, str]]:
    return sorted({tuple(sorted((m, i))) for m in graph.modules if m.startswith("dcfkit")
                   for i in graph.find_modules_directly_imported_by(m)
                   if i.startswith("dcfkit") and i != m and not m.startswith(i + ".") and not i.startswith(m + ".")
                   and graph.chain_exists(importer=i, imported=m)})


def test_no_import_cycles_even_through_entry_points(graph):
    assert not import_cycles(with_entry_points(graph)), f"import cycles: {import_cycles(graph)}"


def test_the_cycle_check_sees_one_through_an_entry_point():
    graph = with_entry_points(grimp.build_graph("dcfkit", cache_dir=None))
    graph.add_import(importer="dcfkit.builtin", imported="dcfkit.registry")  # what the old built-ins did
    assert ("dcfkit.builtin", "dcfkit.registry") in import_cycles(graph)


def test_no_module_is_loaded_by_name():
    by_name = []
    for path in sources():
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            called = node.func if isinstance(node, ast.Call) else None
            name = getattr(called, "attr", None) or getattr(called, "id", None)
            if name in ("import_module", "__import__"):
                by_name.append(f"{path.relative_to(PACKAGE.parent)}:{node.lineno}")
    assert not by_name, f"modules loaded by name (import them, or name them by an entry point): {by_name}"


def test_the_top_level_shows_the_layers():
    modules = sorted(p.name for p in PACKAGE.glob("*.py"))
    assert len(modules) <= 12, modules
    families = ("features", "labels", "regularizers", "solvers", "search", "scale")
    assert all((PACKAGE / "components" / f / "__init__.py").is_file() for f in families)


#: The design card's top level, and what a repository needs beside it (CI, benchmarks).
TOP_LEVEL = {"pyproject.toml", "dcfkit", "plugins", "configs", "tests", "docs", "README.md",
             "benchmarks", ".ci", ".gitignore"}


def test_the_repository_tracks_only_the_design_cards_top_level():
    """Nothing else is committed beside them: a wheel or a stray script at the top was once."""
    root = PACKAGE.parent
    listed = subprocess.run(["git", "-C", str(root), "ls-files", "-z"], capture_output=True)
    if listed.returncode or not (root / ".git").exists():
        pytest.skip(f"{root} is not a git checkout: no tracked files to check")
    top = {path.split("/", 1)[0] for path in listed.stdout.decode().split("\0") if path}
    assert top <= TOP_LEVEL, f"tracked at the top level beyond the design card: {sorted(top - TOP_LEVEL)}"


def test_no_shim_of_the_moved_modules_is_left():
    """The 0.6 module paths that dcfkit/_moved kept went in 0.11 (docs/changes.md): no ``_moved``
    package or module, and no folder added to dcfkit's import path to find them."""
    left = [str(p.relative_to(PACKAGE.parent)) for p in PACKAGE.rglob("_moved*") if p.is_dir() or p.suffix == ".py"]
    assert not left, f"remove {left}"
    assert [Path(p).resolve() for p in dcfkit.__path__] == [PACKAGE]


def test_modules_stay_small():
    long = {str(p.relative_to(PACKAGE.parent)): n for p in sources()
            if (n := len(p.read_text(encoding="utf-8").splitlines())) > 400}
    assert not long, f"split these modules of over 400 lines: {long}"
    tracker = PACKAGE / "tracker" / "tracker.py"
    assert len(tracker.read_text(encoding="utf-8").splitlines()) <= 300, "the Tracker reads as Algorithm 1"


def test_only_the_cli_parses_arguments(graph):
    library = sorted(m for m in graph.find_modules_that_directly_import("argparse")
                     if m.startswith("dcfkit") and not m.startswith("dcfkit.cli"))
    assert not library, f"argparse outside dcfkit.cli: {library}"


# the dcfkit.cli modules and the statistics stack loaded by parsing a command, in a fresh process
LOADED_BY_TRAX = """import sys
import dcfkit.cli
try:
    dcfkit.cli.main(["trax", "--help"])
except SystemExit:
    print(" ".join(sorted(m for m in sys.modules if m.startswith("dcfkit.cli.") or m == "scipy.stats")))
"""


def test_a_command_imports_only_its_own_module():
    """``dcfkit trax`` (a process per sequence under the VOT toolkit) starts without the other
    commands' modules and the statistics that eval and ablate load."""
    run = subprocess.run([sys.executable, "-c", LOADED_BY_TRAX], capture_output=True, text=True, timeout=120)
    loaded = run.stdout.splitlines()[-1:]
    assert loaded == ["dcfkit.cli.parser dcfkit.cli.trax"], run.stdout[-2000:] + run.stderr[-2000:]


def test_imports_inside_functions_say_why():
    silent = []
    for path in sources():
        lines = path.read_text(encoding="utf-8").splitlines()
        for node in functions(ast.parse("\n".join(lines))):
            for inner in ast.walk(node):
                if isinstance(inner, (ast.Import, ast.ImportFrom)) and "#" not in lines[inner.lineno - 1]:
                    silent.append(f"{path.relative_to(PACKAGE.parent)}:{inner.lineno}: {lines[inner.lineno - 1].strip()}")
    assert not silent, "import at the top, or say on the line why it is deferred:\n" + "\n".join(silent)


def test_every_package_is_installed():
    """pyproject.toml lists the packages setuptools installs; a subpackage missing there is
    absent from an installed dcfkit (an editable install hides that)."""
    import tomllib  # deferred: only this test reads pyproject.toml

    listed = set(tomllib.loads((PACKAGE.parent / "pyproject.toml").read_text())["tool"]["setuptools"]["packages"])
    found = {".".join(p.parent.relative_to(PACKAGE.parent).parts) for p in PACKAGE.rglob("__init__.py")}
    assert found <= listed, f"add to pyproject.toml [tool.setuptools] packages: {sorted(found - listed)}"


def test_analysis_reads_results_without_the_runner(graph):
    """Scoring and reports reach results through dcfkit.store, never through dcfkit.running."""
    found = sorted((m, i) for m in graph.modules if m.startswith("dcfkit.analysis")
                   for i in graph.find_modules_directly_imported_by(m) if i.startswith("dcfkit.running"))
    assert not found, f"analysis imports the runner: {found}"


def experiment_names_compared(tree: ast.AST, names: set[str]) -> list[int]:
    """Lines that compare a value with an experiment's name (``x == "tre"``, ``x in ("ope", "sre")``)."""
    def named(node) -> bool:
        if isinstance(node, ast.Constant):
            return isinstance(node.value, str) and node.value.lower() in names
        return isinstance(node, (ast.Tuple, ast.List, ast.Set)) and any(named(e) for e in node.elts)
    return [node.lineno for node in ast.walk(tree) if isinstance(node, ast.Compare)
            and any(named(side) for side in (node.left, *node.comparators))]


def test_no_experiment_name_is_compared_outside_experiments():
    """The runner, scoring, reports and commands call the experiment's strategy
    (dcfkit.experiments.base.Experiment); only dcfkit/experiments/ knows an experiment by name."""
    from dcfkit.experiments import EXPERIMENTS  # deferred: the layout tests read files first

    names = set(EXPERIMENTS)
    found = [f"{path.relative_to(PACKAGE.parent)}:{line}" for path in sources()
             if "experiments" not in path.relative_to(PACKAGE).parts
             for line in experiment_names_compared(ast.parse(path.read_text(encoding="utf-8")), names)]
    assert not found, f"experiment names compared outside dcfkit/experiments/: {found}"


def test_the_name_check_sees_a_comparison():
    tree = ast.parse("if args.experiment == 'reset':\n    pass\nok = kind in ('ope', 'tre')\nfine = x == 'otb'\n")
    assert experiment_names_compared(tree, {"ope", "tre", "sre", "reset"}) == [1, 3]


# docs/architecture.md's layers, top to bottom; a package in one row imports none above it
LAYERS = (("cli", "ablation", "autosearch", "integrations"), ("analysis",), ("running",), ("store",),
          ("experiments",), ("tracker",), ("config",), ("components",), ("numerics",), ("datasets",))


def imports_climbing(graph) -> list[tuple[str, str]]:
    """(importer, imported) pairs where a package imports one of a layer above its own."""
    rank = {f"dcfkit.{package}": row for row, packages in enumerate(LAYERS) for package in packages}

    def row(module: str):
        return rank.get(".".join(module.split(".")[:2]))

    return sorted((m, i) for m in graph.modules if row(m) is not None
                  for i in graph.find_modules_directly_imported_by(m)
                  if row(i) is not None and row(i) < row(m))


def test_no_import_climbs_a_layer(graph):
    assert not imports_climbing(graph), f"imports of a layer above: {imports_climbing(graph)}"


def test_the_layer_check_sees_a_climbing_import():
    graph = grimp.build_graph("dcfkit", cache_dir=None)
    graph.add_import(importer="dcfkit.store.results", imported="dcfkit.running.runner")
    assert ("dcfkit.store.results", "dcfkit.running.runner") in imports_climbing(graph)

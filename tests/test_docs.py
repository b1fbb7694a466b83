"""Generated reference docs (dcfkit/cli/docs.py): the committed files are current, and the renderers."""
import dataclasses
import difflib
import json
import re
from pathlib import Path

import pytest

from dcfkit.cli import components, main
from dcfkit.cli import docs as docs_gen
from dcfkit.config.slots import KINDS
from dcfkit.params import fields, param
from dcfkit.registry import build_registry, get_registry

DOCS = Path(__file__).resolve().parents[1] / "docs"


@pytest.mark.parametrize("file_name", sorted(docs_gen.GENERATED))
def test_committed_reference_docs_are_current(file_name):
    committed = (DOCS / file_name).read_text(encoding="utf-8")
    generated = docs_gen.GENERATED[file_name]()
    diff = "".join(difflib.unified_diff(committed.splitlines(True), generated.splitlines(True),
                                        f"docs/{file_name} (committed)", "generated", n=1))
    assert committed == generated, f"docs/{file_name} is stale: run `python -m dcfkit.cli.docs docs/`\n{diff[:3000]}"


def test_config_reference_documents_every_key_and_every_parameter():
    text = docs_gen.config_reference()
    registry = build_registry(external=False)
    for kind in KINDS:
        for name in registry.names(kind):
            assert f"#### {kind} `{name}`" in text
            for f in fields(registry.entry(kind, name).cls.Params):
                assert f"| `{f['name']}` |" in text
    assert "| `output_sigma_factor` | float | `0.0625` | `> 0` |" in text  # the tracker section
    assert "Also checked: min_image_sample_size <= max_image_sample_size." in text
    assert "| `scale` | `pyramid` |" in text and "| `search` | `fixed` |" in text  # what resolve() fills in
    assert "| `variant` | str | `subtractive` |  | 'subtractive' g - μR̃, 'overwrite' -μR̃ (the authors' code) or " \
           "'multiplicative' (the paper's g⊙d) (one of: `subtractive`, `overwrite`, `multiplicative`) |" in text


def test_cli_reference_has_every_subcommand_and_option():
    text = docs_gen.cli_reference()
    for command in ("track", "demo", "components", "eval", "report"):
        assert f"## dcfkit {command}\n" in text and f"usage: dcfkit {command} [-h]" in text
    assert ("| `--box BOX` |  | initial box x,y,w,h (0-based pixels unless --one-based); write --box=-5,10,40,30 "
            "when x is negative |") in text and "(--box BOX | --select)" in text  # one of the two is required
    assert "| `--seed SEED` | `0` |" in text  # a default of 0 is shown


def test_defaults_are_written_as_yaml():
    assert [components.yaml_value(v) for v in (True, None, (1, 2), "", "fhog", 1e-3, 1e5)] == \
        ["true", "null", "[1, 2]", "''", "fhog", "0.001", "100000.0"]


def test_params_table_escapes_and_lists_choices():
    @dataclasses.dataclass(frozen=True)
    class Params:
        mode: str = param("a", "either a | b", choices=("a", "b"))

    assert components.params_table(fields(Params)).splitlines()[2] == \
        "| `mode` | str | `a` |  | either a \\| b (one of: `a`, `b`) |"
    assert components.params_table([]) == "No parameters.\n"


def test_components_markdown_command_uses_the_shared_renderer(capsys):
    assert main(["components", "--kind", "label", "--format", "markdown"]) == 0
    out = capsys.readouterr().out
    assert out == components.components_markdown(components.component_rows(get_registry(), ["label"]))
    assert "### label `gaussian`\n\nThe fixed Gaussian label of STRCF/BACF (Eq. 1). (from dcfkit)\n\nNo parameters.\n" in out
    assert "| `top_n` | int | `30` | `>= 0` | N: how many of the highest background local maxima are repressed |" in out
    assert "| `neighbourhood` | int | `3` | `[3, 101]` |" in out
    assert "\nAlso checked: neighbourhood an odd number.\n" in out


def test_summary_is_the_whole_first_paragraph():
    class Doc:
        """First line
        continues here.

        Details.
        """

    assert components.summary(Doc) == "First line continues here."


def test_check_mode_reports_stale_files(tmp_path, capsys):
    assert docs_gen.main([str(tmp_path), "--check"]) == 1
    assert "stale:" in capsys.readouterr().err and not list(tmp_path.iterdir())
    assert docs_gen.main([str(tmp_path)]) == 0
    assert sorted(p.name for p in tmp_path.iterdir()) == ["cli.md", "configs.md"]
    assert docs_gen.main([str(tmp_path), "--check"]) == 0


def test_components_lists_each_parameters_bounds_and_the_rules_between_them(capsys):
    """``solver.beta`` must be > 0, ``iterations`` in [1, 10000]...: the table said nothing of it."""
    assert main(["components", "--kind", "solver"]) == 0
    out = capsys.readouterr().out
    assert "iterations (int, default 4, [1, 10000]): E: ADMM iterations per frame" in out
    assert "beta (float, default 10.0, > 0): β: penalty growth per iteration" in out
    assert "learning_rate (float, default 0.013, (0, 1]): η:" in out  # admm_bacf's own field
    assert "h_step (str, default standard): " in out  # no bounds, none shown
    assert "also: every penalty γ of the schedule (γ⁰, then γ ← min(gamma_max, beta·γ)) in [1e-10, 1e10]" in out
    assert main(["components", "--kind", "scale", "--format", "json"]) == 0
    rows = {row["name"]: row for row in json.loads(capsys.readouterr().out)}
    dsst = {f["name"]: f["bounds"] for f in rows["dsst"]["params"]}
    assert dsst["n_scales"] == "[3, 101]" and dsst["step"] == "> 1" and dsst["model_update"] is None
    assert rows["pyramid"]["checks"].startswith("step ** ((n_scales - 1) / 2) <= 10")


def test_a_contract_range_is_listed_for_a_field_that_declares_none():
    """A plugin's temporal regularizer whose theta has no bounds of its own: the tracker's
    contract bounds it to [0, 1e10] all the same, and the listing says so."""
    from dcfkit.components.regularizers import TemporalRegularizer

    @dataclasses.dataclass(frozen=True)
    class Params:
        theta: float = param(1.0, "θ")

    registry = build_registry(external=False)
    registry.register(type("Plain", (TemporalRegularizer,), {"name": "plain_theta", "Params": Params}))
    (row,) = [r for r in components.component_rows(registry, ["regularizer"]) if r["name"] == "plain_theta"]
    assert row["params"][0]["bounds"] == "[0, 1e+10]" and row["checks"] == ""


def test_the_architecture_page_opens_with_every_layer_and_stays_short():
    text = (DOCS / "architecture.md").read_text(encoding="utf-8")
    picture = text.split("```")[1]
    package = DOCS.parent / "dcfkit"
    layers = {p.parent.name for p in package.glob("*/__init__.py")}
    modules = {p.name for p in package.glob("*.py")} - {"__init__.py"}
    assert all(f"{name}/" in picture for name in layers), sorted(n for n in layers if f"{n}/" not in picture)
    assert all(name in text[:text.index("## ")] for name in modules), modules
    assert len(text.encode()) <= 20_000


def test_the_readme_and_the_integrations_page_run_got10k_into_one_folder():
    readme = (DOCS.parent / "README.md").read_text(encoding="utf-8")
    page = (DOCS / "integrations.md").read_text(encoding="utf-8")
    for text in (readme, page):
        assert 'ExperimentDTB70("../shared/data/DTB70", result_dir="results/got10k", report_dir="results/got10k")' \
            in text


def test_ablate_help_names_every_shipped_spec():
    from dcfkit.cli.parser import build_parser  # deferred: the parser is only needed here

    specs = {p.stem for p in (DOCS.parent / "configs" / "ablations").glob("*.yaml")
             if "\nvariants:" in p.read_text(encoding="utf-8") or "\ngrid:" in p.read_text(encoding="utf-8")}
    helps = build_parser()._subparsers._group_actions[0].choices["ablate"].format_help()
    assert specs == {"departures", "family", "recovery", "sensitivity", "speed_departures", "table3",
                     "validation_departures"}
    assert all(name in " ".join(helps.split()) for name in specs), helps


def test_the_helpers_plugins_md_lists_are_where_it_says():
    import importlib  # deferred: only this test imports by name

    text = (DOCS / "plugins.md").read_text(encoding="utf-8")
    table = text.split("### Grids, helpers and bounds")[1].split("\n\n")[2]
    rows = [line.split("|")[1:3] for line in table.splitlines()[2:]]
    assert len(rows) >= 8
    for names, module in rows:
        loaded = importlib.import_module(module.strip().strip("`"))
        for name in re.findall(r"`(\w+)", names):  # `gaussian_label(shape, sigma)`: the name before '('
            assert hasattr(loaded, name), f"{module.strip()} has no {name}"


# a claim that a preset gives the authors' code's boxes, in any of its wordings
REPRODUCTION_CLAIM = re.compile(r"box for box|reproduc\w* (?:the )?authors'|authors' code reproduced|"
                                r"same as the authors'|identical to (?:their|the authors') code", re.IGNORECASE)
# what it was shown against: the authors' code under GNU Octave with the stand-ins, or the section listing them
SHOWN_AGAINST = re.compile(r"Octave|The authors' code under Octave")


def _sentences(text: str) -> list[str]:
    """The sentences of ``text``: a table row or a YAML line is one; a paragraph's lines are joined."""
    out = []
    for block in re.split(r"\n\s*\n", text):
        lines = block.splitlines()
        rows = [line for line in lines if line.lstrip().startswith(("|", "description:"))]
        prose = " ".join(line.strip().lstrip("#").strip() for line in lines if line not in rows)
        out += rows + re.split(r"(?<=[.;!?])\s+(?=[A-Z*(`\"-])", prose)
    return out


def test_every_reproduction_claim_says_it_was_shown_under_octave_with_the_stand_ins():
    """Issue 38: the presets were shown to give the authors' boxes with their MATLAB code run
    under GNU Octave with a stand-in mexResize, .m shims and portable estimates, never under
    MATLAB; each claim says so (or names the section of reference.md that lists them).
    changes.md is history and keeps its words."""
    root = DOCS.parent
    files = [root / "README.md", *sorted(DOCS.glob("*.md")), *sorted((root / "configs" / "reference").glob("*.yaml"))]
    unsaid = [f"{path.relative_to(root)}: {sentence}" for path in files if path.name != "changes.md"
              for sentence in _sentences(path.read_text(encoding="utf-8"))
              if REPRODUCTION_CLAIM.search(sentence) and not SHOWN_AGAINST.search(sentence)]
    assert [] == unsaid
    assert "The authors' code under Octave: what parity was shown against" in (DOCS / "reference.md").read_text()


def test_the_claim_check_finds_a_bare_claim():
    bare = "The preset reproduces the authors' code box for box. It was run\nunder GNU Octave."
    assert [s for s in _sentences(bare) if REPRODUCTION_CLAIM.search(s) and not SHOWN_AGAINST.search(s)] == [
        "The preset reproduces the authors' code box for box."]

"""Generated reference docs (dcfkit/cli/docs.py): the committed files are current, and the renderers."""
import dataclasses
import difflib
from pathlib import Path

import pytest

from dcfkit.cli import components, docs as docs_gen, main
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
    for kind in ("feature", "label", "regularizer", "solver", "search", "scale"):
        for name in registry.names(kind):
            assert f"#### {kind} `{name}`" in text
            for f in fields(registry.entry(kind, name).cls.Params):
                assert f"| `{f['name']}` |" in text
    assert "| `output_sigma_factor` | float | `0.0625` |" in text  # the tracker section
    assert "| `scale` | `pyramid` |" in text and "| `search` | `fixed` |" in text  # what resolve() fills in
    assert "| `variant` | str | `subtractive` | 'subtractive' g - μR̃, 'overwrite' -μR̃ (the authors' code) or " \
           "'multiplicative' (the paper's g⊙d) (one of: `subtractive`, `overwrite`, `multiplicative`) |" in text


def test_cli_reference_has_every_subcommand_and_option():
    text = docs_gen.cli_reference()
    for command in ("track", "demo", "components", "eval", "report"):
        assert f"## dcfkit {command}\n" in text and f"usage: dcfkit {command} [-h]" in text
    assert ("| `--box BOX` |  | initial box x,y,w,h (0-based pixels unless --one-based); write --box=-5,10,40,30 "
            "when x is negative **required** |") in text
    assert "| `--seed SEED` | `0` |" in text  # a default of 0 is shown


def test_defaults_are_written_as_yaml():
    assert [components.yaml_value(v) for v in (True, None, (1, 2), "", "fhog", 1e-3, 1e5)] == \
        ["true", "null", "[1, 2]", "''", "fhog", "0.001", "100000.0"]


def test_params_table_escapes_and_lists_choices():
    @dataclasses.dataclass(frozen=True)
    class Params:
        mode: str = param("a", "either a | b", choices=("a", "b"))

    assert components.params_table(fields(Params)).splitlines()[2] == \
        "| `mode` | str | `a` | either a \\| b (one of: `a`, `b`) |"
    assert components.params_table([]) == "No parameters.\n"


def test_components_markdown_command_uses_the_shared_renderer(capsys):
    assert main(["components", "--kind", "label", "--format", "markdown"]) == 0
    out = capsys.readouterr().out
    assert out == components.components_markdown(components.component_rows(get_registry(), ["label"]))
    assert "### label `gaussian`\n\nThe fixed Gaussian label of STRCF/BACF (Eq. 1). (from dcfkit)\n\nNo parameters.\n" in out
    assert "| `top_n` | int | `30` | N: how many of the highest background local maxima are repressed |" in out


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

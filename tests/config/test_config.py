"""Configs: inheritance, overrides, validation and clear errors."""
import re
from pathlib import Path

import pytest

from dcfkit.config import load_config, shipped_config_dir
from dcfkit.config.overrides import parse_overrides
from dcfkit.errors import ConfigError, DcfkitError, RegistryError

CONFIGS = Path(__file__).resolve().parents[2] / "configs"


@pytest.mark.parametrize("name", ["strcf", "bacf", "dr2track", "kcf", "dsst"])
def test_shipped_configs_resolve(name):
    cfg = load_config(CONFIGS / f"{name}.yaml")
    assert cfg["name"] == name
    assert load_config(name) == cfg  # a bare name finds the shipped file


def test_dr2track_has_the_papers_parameters():
    cfg = load_config("dr2track")
    assert cfg["label"] == {"name": "distractor_repressed", "top_n": 30, "mu": 0.25, "variant": "overwrite",
                            "neighbourhood": 3, "exclusion": 1.0, "selection": "authors", "mirrored": True}
    assert cfg["regularizers"]["temporal"]["theta"] == 12
    assert cfg["solver"]["iterations"] == 4 and cfg["solver"]["gamma0"] == 1
    assert cfg["solver"]["beta"] == 10 and cfg["solver"]["gamma_max"] == 10000
    assert cfg["search"]["name"] == "motion_aware"
    assert cfg["scale"]["name"] == "dsst" and cfg["scale"]["n_scales"] == 33 and cfg["scale"]["step"] == 1.03
    assert cfg["tracker"]["search_area_scale"] == 5 and cfg["tracker"]["cell_size"] == 4
    assert [f["name"] for f in cfg["features"]] == ["gray", "fhog", "colornames"]


def test_ablations_differ_from_dr2track_only_where_they_say():
    full = load_config("dr2track")
    no_dr = load_config(CONFIGS / "ablations" / "dr2track_no_dr.yaml")
    no_ma = load_config(CONFIGS / "ablations" / "dr2track_no_ma.yaml")
    assert {k for k in full if full[k] != no_dr[k]} == {"name", "label"}
    assert no_dr["label"]["name"] == "gaussian"
    assert {k for k in full if full[k] != no_ma[k]} == {"name", "search"}
    assert no_ma["search"]["name"] == "fixed"


def test_dr2track_paper_differs_only_in_dr2tracks_own_details():
    full = load_config("dr2track")
    paper = load_config(CONFIGS / "ablations" / "dr2track_paper.yaml")
    assert {k for k in full if full[k] != paper[k]} == {"name", "description", "tracker", "label", "solver", "scale"}
    changed = {(section, key) for section in ("tracker", "label", "solver", "scale")
               for key in full[section] if full[section][key] != paper[section][key]}
    assert changed == {("tracker", "training_sample"), ("label", "variant"), ("label", "selection"),
                       ("label", "mirrored"), ("solver", "h_step"), ("scale", "model_size"), ("scale", "sampling"),
                       ("scale", "window"), ("scale", "model_update")}


def test_dotted_overrides():
    renamed = load_config("dr2track", {"name": "dr2track_mu03", "label.mu": 0.3})
    assert renamed["name"] == "dr2track_mu03" and renamed["scale"]["name"] == "dsst"  # the rest is kept
    switched = load_config("dr2track", {"label.name": "gaussian"})
    assert switched["label"] == {"name": "gaussian"}  # another component: old parameters dropped
    cfg = load_config("dr2track", {"label.mu": 0.3, "features.0.name": "fhog", "regularizers.temporal": None})
    assert cfg["label"]["mu"] == 0.3
    assert cfg["features"][0]["name"] == "fhog"
    assert cfg["regularizers"]["temporal"] is None


def test_unknown_parameter_names_valid_ones_and_suggests(tmp_path):
    with pytest.raises(ConfigError, match=r"label.*unknown parameter 'mue'.*did you mean 'mu'.*top_n"):
        load_config("dr2track", {"label.mue": 0.3})


def test_unknown_component_lists_registered_ones():
    with pytest.raises(RegistryError, match=r"unknown label 'gausian'.*did you mean 'gaussian'"):
        load_config("strcf", {"label.name": "gausian"})


def test_wrong_type_is_reported_with_key():
    with pytest.raises(ConfigError, match=r"solver.*iterations: expected an integer"):
        load_config("strcf", {"solver.iterations": "four"})
    with pytest.raises(ConfigError, match=r"label .*: mu must be in \[0, 1e\+06\], got -1\.0"):
        load_config("dr2track", {"label.mu": -1})


@pytest.mark.parametrize("section,match", [
    ({"tracker": 5}, r"tracker: expected a mapping of parameters, got 5"),
    ({"label": {"name": ["a"]}}, r"label: expected a mapping with a 'name' key"),
    ({"solver": {"name": "admm_strcf", "iterations": [4]}}, r"iterations: expected an integer"),
    ({"name": [1]}, r"name: expected a string"),
])
def test_wrong_section_types_are_config_errors(section, match):
    with pytest.raises(DcfkitError, match=match):
        load_config({"base": "dr2track", **section})


@pytest.mark.parametrize("key,value", [("label.mu", float("nan")), ("search.gain", float("inf")),
                                       ("tracker.search_area_scale", "inf"), ("scale.step", "-inf")])
def test_non_finite_numbers_are_refused(key, value):
    with pytest.raises(ConfigError, match=rf"{key.split('.')[-1]}: expected a finite number"):
        load_config("dr2track", {key: value})


@pytest.mark.parametrize("config,key,value,match", [
    ("strcf", "scale.step", 1e6, r"scale.*step=1e\+06 with n_scales=5: the scales may span at most x10"),
    ("strcf", "scale.n_scales", 10**6, r"scale.*n_scales must be in \[1, 101\]"),
    ("dr2track", "scale.model_max_area", -5, r"scale.*model_max_area must be in"),
    ("dr2track", "scale.cell_size", 0, r"scale.*cell_size must be in"),
    ("dr2track", "scale.sigma_factor", 0, r"scale.*sigma_factor must be in \(0, 10\], got 0"),
    ("strcf", "tracker.search_area_scale", 1e6, r"tracker: search_area_scale must be in \[1, 50\]"),
    ("strcf", "tracker.cell_size", 10000, r"tracker: cell_size must be in \[1, 64\]"),
    ("strcf", "tracker.min_image_sample_size", 1e-300,
     r"tracker: min_image_sample_size must be in \[64, 4000000\], got 1e-300"),
    ("strcf", "tracker.min_image_sample_size", 300**2, r"tracker: need min_image_sample_size <= max_image_sample_size"),
    ("strcf", "solver.iterations", 10**9, r"solver.*iterations must be in \[1, 10000\]"),
    ("dr2track", "scale.n_scales", 200, r"scale.*n_scales must be in \[3, 101\]"),
])
def test_values_whose_patches_would_not_fit_in_memory_are_refused(config, key, value, match):
    # each used to pass validation and fail inside OpenCV (out of memory, int overflow) or never finish
    with pytest.raises(ConfigError, match=match):
        load_config(config, {key: value})


def test_what_is_not_a_config_is_a_config_error(tmp_path):
    latin = tmp_path / "latin.yaml"
    latin.write_bytes("name: caf\xe9\n".encode("latin-1"))
    with pytest.raises(ConfigError, match=r"latin.yaml: not a UTF-8 text file \(byte 9"):
        load_config(latin)
    for source in (None, 5):
        with pytest.raises(ConfigError, match=f"a file path, a shipped config name or a mapping, got "
                                              f"{type(source).__name__}"):
            load_config(source)
    with pytest.raises(ConfigError, match=r"override keys are dotted strings .* got 1"):
        load_config("strcf", {1: 2})


def test_error_in_an_inherited_file_lists_the_files_merged(tmp_path):
    (tmp_path / "parent.yaml").write_text("base: strcf\nlabel: {name: gaussian, sigma: 2}\n")
    (tmp_path / "child.yaml").write_text("base: parent.yaml\nname: child\n")
    with pytest.raises(ConfigError, match=r"unknown parameter 'sigma'.*merged from .*child.yaml <- "
                                          r".*parent.yaml <- .*strcf.yaml\)"):
        load_config(tmp_path / "child.yaml")


@pytest.mark.parametrize("text,match", [
    ("name: x\nlabel: {name: gaussian\nsolver: admm_strcf\n", r"bad.yaml:\d+:\d+: YAML error"),
    ("base: dr2track\nregularizers:\n  temporal: {theta: .inf}\n", r"bad.yaml.*theta: expected a finite number"),
    ("base: strcf\nsolver: {iterations: 3, iterations: 4}\n", r"bad.yaml:2:\d+: .*key 'iterations' is given twice"),
    ("base: strcf\nlabel: {name: gaussian}\nlabel: {name: gaussian}\n", r"bad.yaml:3:1: .*key 'label' is given twice"),
    ("base: strcf\n? [a, b]\n: 1\n", r"bad.yaml:\d+:\d+: YAML error: found unhashable key"),
    # values PyYAML cannot build: a ConfigError naming the line, not PyYAML's ValueError
    ("base: strcf\nname: 1" + "0" * 5000 + "\n",
     r"bad.yaml:2:7: YAML error: cannot read this value: Exceeds the limit"),
    ("base: strcf\nname: 2001-13-45\n", r"bad.yaml:2:7: YAML error: cannot read this value: month must be in 1..12"),
    ("base: strcf\nname: \x00\n", r"bad.yaml: YAML error: .*unacceptable character"),
])
def test_bad_yaml_files_name_file_line_and_key(tmp_path, text, match):
    bad = tmp_path / "bad.yaml"
    bad.write_text(text)
    with pytest.raises(ConfigError, match=match):
        load_config(bad)


def test_yaml_merge_keys_work(tmp_path):
    path = tmp_path / "merge.yaml"
    path.write_text("base: strcf\nregularizers:\n  temporal:\n    <<: {name: temporal, theta: 3}\n    theta: 12\n")
    assert load_config(path)["regularizers"]["temporal"] == {"name": "temporal", "theta": 12.0}


def test_unknown_top_level_key_and_wrong_regularizer_role(tmp_path):
    cfg = tmp_path / "c.yaml"
    cfg.write_text(f"base: {CONFIGS / 'strcf.yaml'}\nsolvr: {{name: admm_strcf}}\n")
    with pytest.raises(ConfigError, match=r"unknown key 'solvr'.*did you mean 'solver'"):
        load_config(cfg)
    with pytest.raises(ConfigError, match=r"regularizers.spatial: 'temporal' is a temporal regularizer"):
        load_config("strcf", {"regularizers.spatial": {"name": "temporal"}})


@pytest.mark.parametrize("override", ["base=bacf", "base=no_such_config", "base.x=1", " base =bacf"])
def test_base_cannot_be_overridden(override, tmp_path, capsys):
    """--set base=... set a key that nothing read any more: the config stayed on its own base,
    silently, even when the new base did not exist."""
    from dcfkit import cli

    child = tmp_path / "child.yaml"
    child.write_text("base: strcf\nname: child\n")
    for source in ("strcf", child, {"base": "strcf", "name": "child"}):
        with pytest.raises(ConfigError, match=r"override 'base(\.x)?': a config's base is read with its file, "
                                              r"before overrides apply; give that config instead"):
            load_config(source, parse_overrides([override]))
    assert cli.main(["track", "strcf", "--frames", str(tmp_path), "--box", "1,1,5,5", "--set", override]) == 2
    assert capsys.readouterr().err.startswith("dcfkit track: error: override 'base")


@pytest.mark.parametrize("value, roles", [("null", (None, None)), ("{}", (None, None)),
                                          ("{temporal: {name: temporal, theta: 3}}", (None, "temporal"))])
def test_regularizers_replaced_by_an_override(value, roles):
    cfg = load_config("strcf", parse_overrides([f"regularizers={value}"]))
    assert tuple(r and r["name"] for r in (cfg["regularizers"]["spatial"], cfg["regularizers"]["temporal"])) == roles


@pytest.mark.parametrize("value, shown", [("[]", "[]"), ("", "''"), ("false", "False"), ("0", "0"), ("[l2]", "['l2']")])
def test_regularizers_that_are_not_a_mapping_are_refused(value, shown):
    """[], '', false and 0 were read as "no regularizers" (anything falsy), a non-empty list was an error."""
    with pytest.raises(ConfigError, match=r"strcf.yaml: regularizers: expected a mapping of roles \(spatial, temporal\) "
                                          rf"to components, got {re.escape(shown)} \(null: none; "):
        load_config("strcf", parse_overrides([f"regularizers={value}"]))


def test_base_may_name_a_shipped_config(tmp_path):
    (tmp_path / "sub").mkdir()
    for base in ("dr2track", "dr2track.yaml"):
        path = tmp_path / "sub" / "mine.yaml"
        path.write_text(f"base: {base}\nname: mine\nlabel: {{mu: 0.3}}\n")
        config = load_config(path)
        assert config["name"] == "mine" and config["label"]["mu"] == 0.3
        assert {k: v for k, v in config.items() if k not in ("name", "label")} == \
            {k: v for k, v in load_config("dr2track").items() if k not in ("name", "label")}
    # a file next to the config comes first
    (tmp_path / "sub" / "dr2track.yaml").write_text("base: strcf\nname: local\n")
    path.write_text("base: dr2track.yaml\n")
    assert load_config(path)["name"] == "local"
    path.write_text("base: ../nowhere/dr2track.yaml\n")
    with pytest.raises(ConfigError, match=r"base config '../nowhere/dr2track.yaml' not found"):
        load_config(path)


def test_circular_base_is_an_error(tmp_path):
    (tmp_path / "a.yaml").write_text("base: b.yaml\n")
    (tmp_path / "b.yaml").write_text("base: a.yaml\n")
    with pytest.raises(ConfigError, match="circular"):
        load_config(tmp_path / "a.yaml")


def test_missing_config_lists_shipped_ones():
    with pytest.raises(ConfigError, match=r"config not found: nope.*dr2track"):
        load_config("nope")
    assert (shipped_config_dir() / "dr2track.yaml").is_file()


def test_an_override_value_is_not_written_into_by_a_later_key():
    """load_config(base, {"label": d, "label.mu": 0.5}) set mu inside the caller's own d."""
    label = {"name": "distractor_repressed", "mu": 0.25}
    config = load_config("dr2track", {"label": label, "label.mu": 0.5})
    assert config["label"]["mu"] == 0.5 and label == {"name": "distractor_repressed", "mu": 0.25}

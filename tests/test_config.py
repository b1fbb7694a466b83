"""Configs: inheritance, overrides, validation and clear errors."""
from pathlib import Path

import pytest

from dcfkit.config import load_config, shipped_config_dir
from dcfkit.errors import ConfigError, DcfkitError, RegistryError

CONFIGS = Path(__file__).resolve().parents[1] / "configs"


@pytest.mark.parametrize("name", ["strcf", "bacf", "dr2track"])
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

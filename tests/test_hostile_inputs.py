"""Hostile input (issue 15): extreme boxes, configs at the edges of their ranges, images that
declare billions of pixels, corrupt JPEGs, truncated videos. Each ends in dcfkit's own error
naming what was wrong, quickly and in bounded memory, or is tracked as before.

The property tests use the derandomized profile of conftest.py; their budgets are lowered
through the environment variables a user would set, so that each example stays small."""
from __future__ import annotations

import struct
import time
import tracemalloc
import zlib

import cv2
import numpy as np
import pytest
from PIL import Image
from hypothesis import event, example, given
from hypothesis import strategies as st

import dcfkit
from dcfkit import cli
from dcfkit.datasets import DatasetError, read_frame
from dcfkit.errors import ConfigError, InputError
from dcfkit.synthetic import make_sequence
from dcfkit.video import iter_frames

CONFIGS = ("strcf", "bacf", "dr2track")
SEQUENCE = make_sequence(n_frames=2, size=(72, 96), target=(10, 14), distractor=False)
_TRACKERS: dict[str, dcfkit.Tracker] = {}


def tracker(config: str) -> dcfkit.Tracker:
    """One tracker per shipped config for the whole module (init starts it over), run once
    before it is measured: the first run loads the compiled loops."""
    if config not in _TRACKERS:
        _TRACKERS[config] = dcfkit.load_tracker(config)
        _TRACKERS[config].init(SEQUENCE.frames[0], SEQUENCE.ground_truth[0])
    return _TRACKERS[config]


class Measured:
    """Wall time and the peak of traced allocations (numpy's and OpenCV's arrays) in the block."""

    def __enter__(self):
        tracemalloc.start()
        self.start = time.perf_counter()
        return self

    def __exit__(self, *exc):
        self.seconds = time.perf_counter() - self.start
        self.peak_mb = tracemalloc.get_traced_memory()[1] / 2**20
        tracemalloc.stop()


# --------------------------------------------------------------------------- initial boxes

coordinate = st.one_of(st.floats(allow_nan=True, allow_infinity=True),
                       st.sampled_from([-1e12, -20.0, 0.0, 0.5, 50.0, 95.0, 95.5, 1e12]))
side = st.one_of(st.floats(allow_nan=True, allow_infinity=True),
                 st.sampled_from([1e-300, 1e-5, 0.5, 1.0, 3.0, 14.0, 96.0, 960.0, 961.0, 1e6, 1e9, 2e12]))
plausible = st.tuples(st.floats(-60, 100), st.floats(-60, 75), st.floats(0.5, 1000), st.floats(0.5, 750))


@given(box=st.one_of(plausible, st.tuples(coordinate, coordinate, side, side)))
@example(box=(10, 10, 1e9, 1e9))  # the fault-injection pass: OpenCV out of memory
@example(box=(10, 10, 1e6, 1e6))
@example(box=(10, 10, 1e-300, 1e-300))  # cannot convert NaN
@example(box=(-1e12, -1e12, 2e12, 2e12))  # integer overflow
@example(box=(0, 0, 960, 720))  # ten times the image: the largest box kept
def test_any_initial_box_is_tracked_or_refused_quickly_in_bounded_memory(box):
    """Every shipped tracker either refuses the box with an InputError naming it, or tracks the
    next frame to a finite box of positive size; in under 2 s and 200 MB either way (a box of
    1e6 px used to ask OpenCV for 30 GB)."""
    for config in CONFIGS:
        t = tracker(config)
        with Measured() as used:
            try:
                t.init(SEQUENCE.frames[0], box)
            except InputError as exc:
                assert "initial box" in str(exc) or "frame 1" in str(exc)
                event(f"{config}: refused")
            else:
                event(f"{config}: tracked")
                out = np.asarray(t.update(SEQUENCE.frames[1]))
                assert np.all(np.isfinite(out)) and out[2] > 0 and out[3] > 0, (config, out)
        assert used.seconds < 2 and used.peak_mb < 200, (config, used.seconds, used.peak_mb)


@pytest.mark.parametrize("box,said", [
    ("10,10,1e9,1e9", "more than 10 times as wide or as tall as the 96x72 image"),
    ("10,10,1e6,1e6", "more than 10 times"),
    ("10,10,1e-300,1e-300", "under a pixel wide or tall"),
    ("-1e12,-1e12,2e12,2e12", "more than 10 times"),
    ("0.1,0.2,0.3,0.4", "boxes are in pixels, not fractions of the image"),
])
def test_extreme_boxes_on_the_command_line_are_one_line_errors(box, said, tmp_path, capsys):
    folder = tmp_path / "frames"
    folder.mkdir()
    for i, frame in enumerate(SEQUENCE.frames):
        cv2.imwrite(str(folder / f"{i:03d}.png"), frame)
    assert cli.main(["track", "strcf", "--frames", str(folder), f"--box={box}"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("dcfkit track: error: frame 1: init raised InputError: initial box") and said in err
    assert "Traceback" not in err and len(err.splitlines()) == 1


# --------------------------------------------------------------------------- configs

BUDGET = {"DCFKIT_MAX_SAMPLE_PIXELS": str(2**18), "DCFKIT_MAX_IMAGE_PIXELS": str(2**21)}


def pyramid_span(least: int):
    """(n_scales, step) inside the scale estimators' ranges: step ** ((n - 1) / 2) <= 10."""
    return st.one_of(st.integers(least, 7), st.integers(least, 101)).flatmap(
        lambda n: st.tuples(st.just(n), st.floats(1.0001, 10 ** (1.999 / max(n - 1, 1)))))


@st.composite
def tracker_configs(draw):
    """A shipped config with its tracker section and scale parameters anywhere in their ranges."""
    config = draw(st.sampled_from(CONFIGS))
    sides = st.one_of(st.integers(8, 250), st.integers(8, 2000))  # of the sample areas' squares
    low, high = sorted(float(v * v) for v in draw(st.lists(sides, min_size=2, max_size=2)))
    n, step = draw(pyramid_span(3 if config == "dr2track" else 1))
    overrides = {"tracker.search_area_scale": draw(st.floats(1, 50)),
                 "tracker.search_area_shape": draw(st.sampled_from(["square", "proportional"])),
                 "tracker.min_image_sample_size": low, "tracker.max_image_sample_size": high,
                 "tracker.cell_size": draw(st.one_of(st.integers(2, 8), st.integers(1, 64))),
                 "tracker.cell_selection_thresh": draw(st.sampled_from([0.0, 0.75**2, 1.0])),
                 "tracker.sampling": draw(st.sampled_from(["subpixel", "whole_pixel"])),
                 "scale.n_scales": n, "scale.step": step}
    if config == "dr2track":
        overrides.update({"scale.model_max_area": draw(st.integers(1, 10000)),
                          "scale.cell_size": draw(st.integers(1, 16)),
                          "scale.sampling": draw(st.sampled_from(["working_patch", "whole_pixel"]))})
    return config, overrides


@given(spec=tracker_configs())
@example(spec=("strcf", {"tracker.cell_size": 1, "tracker.min_image_sample_size": 2000.0**2,
                         "tracker.max_image_sample_size": 2000.0**2}))
@example(spec=("strcf", {"scale.n_scales": 101, "scale.step": 1.02, "tracker.min_image_sample_size": 2000.0**2,
                         "tracker.max_image_sample_size": 2000.0**2}))
@example(spec=("dr2track", {"scale.n_scales": 101, "scale.step": 1.046, "scale.model_max_area": 10000,
                            "scale.cell_size": 1}))
@example(spec=("strcf", {"tracker.search_area_scale": 50, "tracker.sampling": "whole_pixel"}))
def test_configs_in_range_are_tracked_within_the_budget_or_refused(spec, monkeypatch):
    """With the budgets lowered to 2^18 sample pixels and 2^21 image pixels, a config is
    refused with a ConfigError naming the variable (or its box with an InputError), or tracks a
    frame in under 100 MB of arrays: configs inside the allowed ranges used to need gigabytes
    (2000² samples at 1-px cells, 101 search scales of them, a 9000² DSST working patch)."""
    config, overrides = spec
    tracker(config)  # the compiled loops loaded before anything is measured
    for name, value in BUDGET.items():
        monkeypatch.setenv(name, value)
    try:
        built = dcfkit.load_tracker(config, overrides=overrides)
    except ConfigError as exc:
        assert "DCFKIT_MAX_SAMPLE_PIXELS" in str(exc)
        event("config refused")
        return
    with Measured() as used:
        try:
            built.init(SEQUENCE.frames[0], SEQUENCE.ground_truth[0])
            built.update(SEQUENCE.frames[1])
            event("tracked")
        except InputError as exc:
            assert str(exc).startswith("frame 1: initial box") and "$DCFKIT_MAX_" in str(exc)
            event("box refused")
    assert used.peak_mb < 100 and used.seconds < 3, (used.peak_mb, used.seconds)


def test_a_config_over_the_sample_budget_names_keys_and_variable_and_the_variable_raises_it(monkeypatch):
    big = {"tracker.cell_size": 1, "tracker.min_image_sample_size": 2000.0**2,
           "tracker.max_image_sample_size": 2000.0**2}
    with pytest.raises(ConfigError, match=r"strcf: 5 search scales \(scale.n_scales\) of "
                                          r"tracker.max_image_sample_size 4e\+06 px \(tracker.cell_size 1\) .*"
                                          r"\$DCFKIT_MAX_SAMPLE_PIXELS"):
        dcfkit.load_tracker("strcf", overrides=big)
    with pytest.raises(ConfigError, match=r"scale.n_scales 101 samples of scale.model_max_area 10000 px"):
        dcfkit.load_tracker("dr2track", overrides={"scale.n_scales": 101, "scale.step": 1.046,
                                                   "scale.model_max_area": 10000})
    monkeypatch.setenv("DCFKIT_MAX_SAMPLE_PIXELS", "4e8")
    assert dcfkit.load_tracker("strcf", overrides=big).params.cell_size == 1
    monkeypatch.setenv("DCFKIT_MAX_SAMPLE_PIXELS", "lots")
    with pytest.raises(ConfigError, match=r"\$DCFKIT_MAX_SAMPLE_PIXELS must be a number of pixels >= 1, got 'lots'"):
        dcfkit.load_tracker("strcf")


def test_a_region_that_grows_over_the_image_budget_names_the_frame(monkeypatch):
    """The copies are checked where they are built, whatever asks for them: on a later frame
    (a target grown large) the update is refused, the tracker left as it was."""
    t = dcfkit.load_tracker("strcf")
    t.init(SEQUENCE.frames[0], (0, 0, 20, 20))  # its search region reaches past the corner
    before = t.box
    monkeypatch.setenv("DCFKIT_MAX_IMAGE_PIXELS", "1000")
    with pytest.raises(InputError, match=r"frame 2: the search region at scale .*: the \d+x\d+ px region to copy "
                                         r"from the 96x72 image holds .* over the limit of 1e\+03 "
                                         r"\(\$DCFKIT_MAX_IMAGE_PIXELS\)"):
        t.update(SEQUENCE.frames[1])
    assert t.box == before

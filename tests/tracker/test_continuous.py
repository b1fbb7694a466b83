"""The continuous loop (ECO-HC) end to end, and the hooks that choose and feed it."""
import types

import numpy as np
import pytest

import dcfkit
from dcfkit.analysis.metrics import score_sequence
from dcfkit.config import load_config
from dcfkit.config.tracker_params import TrackerParams
from dcfkit.datasets.synthetic import make_sequence
from dcfkit.components.schedule.sparse import Sparse
from dcfkit.errors import ConfigError, TrackingError
from dcfkit.tracker.continuous import ContinuousLoop
from dcfkit.tracker.tracker import Tracker


@pytest.fixture(scope="module")
def sequence():
    return make_sequence(n_frames=40, seed=3)


def run(tracker, frames, box):
    tracker.init(frames[0], box)
    return [tuple(box)] + [tracker.update(f) for f in frames[1:]]


@pytest.mark.parametrize("config", ["configs/eco_hc.yaml", "configs/reference/eco_hc.yaml"])
def test_eco_hc_tracks_the_synthetic_moving_target(config, sequence, request):
    tracker = dcfkit.load_tracker(request.config.rootpath / config)
    assert isinstance(tracker.loop, ContinuousLoop)
    boxes = run(tracker, sequence.frames, sequence.ground_truth[0])
    scores = score_sequence(boxes, sequence.ground_truth)
    assert scores["precision"] >= 0.95
    assert scores["auc"] >= 0.6
    # two blocks: fHOG at cell 6 compressed to 10 channels, Color Names at cell 4 to 3; the
    # finer block is the output grid
    blocks = tracker.loop.layout.blocks
    assert [(b.cell, b.dim) for b in blocks] == [(4, 3), (6, 10)]
    assert tracker.loop.layout.output == blocks[0].filter_size
    assert all(n % 2 == 1 for b in blocks for n in b.filter_size)
    assert [p.shape for p in tracker.solver.projections] == [(10, 3), (31, 10)]
    assert tracker.memory.count == len(sequence.frames) - 1 or tracker.memory.count == 30


def test_eco_hc_is_deterministic(sequence, request):
    path = request.config.rootpath / "configs/eco_hc.yaml"
    frames = sequence.frames[:12]
    assert run(dcfkit.load_tracker(path), frames, sequence.ground_truth[0]) == \
        run(dcfkit.load_tracker(path), frames, sequence.ground_truth[0])


def test_a_gray_sequence_takes_the_intensity_table_in_place_of_colour_names(sequence, request, tmp_path):
    frames = [f.mean(axis=2).astype(np.uint8) for f in sequence.frames[:8]]
    path = request.config.rootpath / "configs/eco_hc.yaml"
    tracker = dcfkit.load_tracker(path)
    boxes = run(tracker, frames, sequence.ground_truth[0])
    assert [b.feature.name for b in tracker.loop.layout.blocks] == ["fhog"]
    assert score_sequence(boxes, sequence.ground_truth[:8])["precision"] >= 0.9
    # with a gray-level table (ECO's intensityChannelNorm6 is such a 256x5 one) as a third feature
    np.save(tmp_path / "table.npy", np.random.default_rng(0).random((256, 5)).astype(np.float32))
    three = {"features": [{"name": "fhog"}, {"name": "colornames"},
                          {"name": "intensity_table", "table_path": str(tmp_path / "table.npy")}],
             "solver.cell_sizes": [6, 4, 4], "solver.compressed_dims": [10, 3, 3]}
    tracker = dcfkit.load_tracker(path, overrides=three)
    boxes = run(tracker, frames, sequence.ground_truth[0])
    assert [(b.feature.name, b.dim) for b in tracker.loop.layout.blocks] == [("intensity_table", 3), ("fhog", 10)]
    assert score_sequence(boxes, sequence.ground_truth[:8])["precision"] >= 0.9
    tracker.init(sequence.frames[0], sequence.ground_truth[0])  # a colour sequence: Color Names, no table
    assert [b.feature.name for b in tracker.loop.layout.blocks] == ["colornames", "fhog"]


def test_configs_without_the_new_slots_resolve_as_before():
    config = load_config("strcf")
    assert "memory" not in config and "schedule" not in config
    assert Tracker(config).loop is None


def test_a_memory_is_refused_by_the_discrete_loop_and_required_by_eco():
    with pytest.raises(ConfigError, match="memory: solver 'admm_strcf' keeps its own model"):
        dcfkit.load_tracker("strcf", overrides={"memory": {"name": "gmm"}})
    with pytest.raises(ConfigError, match="learns from a memory"):
        dcfkit.load_tracker("eco_hc", overrides={"memory": None})
    with pytest.raises(ConfigError, match="spatial"):
        dcfkit.load_tracker("eco_hc", overrides={"regularizers.spatial": {"name": "box"}})
    with pytest.raises(ConfigError, match="label: the continuous loop's label is a Gaussian's"):
        dcfkit.load_tracker("eco_hc", overrides={"label": {"name": "distractor_repressed"}})
    with pytest.raises(ConfigError, match="tracker.sampling: solver 'eco' runs in the continuous loop"):
        dcfkit.load_tracker("eco_hc", overrides={"tracker.sampling": "whole_pixel"})


def test_the_eco_solver_refuses_the_discrete_training_call():
    tracker = dcfkit.load_tracker("eco_hc")
    with pytest.raises(TrackingError, match="continuous loop"):
        tracker.solver.train(None, None, None, 0.0, None)


def test_a_schedule_gates_the_discrete_loops_training(sequence):
    tracker = dcfkit.load_tracker("strcf", overrides={"schedule": {"name": "sparse", "gap": 2, "after_frame": 3}})
    trained = []
    original = tracker.solver.train

    def train(*args):
        trained.append(tracker.frame)
        return original(*args)

    tracker.solver.train = train
    run(tracker, sequence.frames[:12], sequence.ground_truth[0])
    assert trained == [1, 2, 5, 8, 11]


@pytest.mark.parametrize("key, value", [("output_sigma", 1.0), ("cell_area", 100), ("box_scale", "previous"),
                                        ("resize", "matlab_bicubic")])
def test_the_continuous_loop_refuses_the_discrete_loops_csr_keys(key, value):
    default = getattr(TrackerParams(), key)
    assert value != default
    with pytest.raises(ConfigError, match=f"tracker.{key}: solver 'eco' runs in the continuous loop"):
        dcfkit.load_tracker("eco_hc", overrides={f"tracker.{key}": value})


def test_the_continuous_loop_refuses_a_padded_square_search_area():
    with pytest.raises(ConfigError, match="tracker.search_area_shape: 'padded_square'"):
        dcfkit.load_tracker("eco_hc", overrides={"tracker.search_area_shape": "padded_square"})


@pytest.mark.parametrize("slot", ["channel_weights", "mask"])
def test_the_continuous_loop_refuses_channel_weights_and_masks(slot):
    name = load_config("csrdcf")[slot]["name"]
    with pytest.raises(ConfigError, match=f"{slot} '{name}': solver 'eco' runs in the continuous loop"):
        dcfkit.load_tracker("eco_hc", overrides={slot: {"name": name}})


@pytest.mark.parametrize("skip", ["gray_skip", "colour_skip"])
def test_skipped_feature_names_must_be_the_configs(skip):
    with pytest.raises(ConfigError, match=f"solver.{skip}: 'colournames' is not one of the config's features"):
        dcfkit.load_tracker("eco_hc", overrides={f"solver.{skip}": ["colournames"]})


def _skips_first(schedule, frame):
    """ECO's sparse schedule's due(), but not learning on frame 1."""
    return frame != 1 and Sparse.due(schedule, frame)


@pytest.mark.parametrize("config", ["eco_hc", "strcf"])
def test_a_schedule_refusing_frame_1_leaves_the_tracker_as_it_was(config, sequence):
    box = sequence.ground_truth[0]
    overrides = {"schedule": {"name": "sparse", "gap": 2, "after_frame": 2}}
    tracking, reference = (dcfkit.load_tracker(config, overrides=overrides) for _ in range(2))
    run(tracking, sequence.frames[:5], box)
    run(reference, sequence.frames[:5], box)
    due = tracking.schedule.due
    tracking.schedule.due = types.MethodType(_skips_first, tracking.schedule)
    with pytest.raises(TrackingError, match="skips the first frame"):
        tracking.init(sequence.frames[5], (box[0] + 3, box[1], box[2] * 1.5, box[3] * 1.5))
    tracking.schedule.due = due
    assert [tracking.update(f) for f in sequence.frames[5:9]] == [reference.update(f) for f in sequence.frames[5:9]]


def test_the_continuous_loop_gives_the_schedule_each_detection(sequence):
    tracker = dcfkit.load_tracker("eco_hc")
    seen = []
    tracker.schedule.observe = seen.append
    run(tracker, sequence.frames[:6], sequence.ground_truth[0])
    assert len(seen) == 5
    output = tracker.loop.layout.output
    for d in seen:
        assert d.response.shape == tuple(output) and d.response.dtype == np.float32
        assert d.response[d.peak] == d.response.max()
        assert d.target_cells == tracker.geometry.target_cells and len(d.offset) == 2


def test_the_position_is_0_based_under_both_loops():
    seq = make_sequence(n_frames=3, seed=1)
    for config in ("eco_hc", "strcf"):
        tracker = dcfkit.load_tracker(config)
        tracker.init(seq.frames[0], seq.ground_truth[0])
        x, y, w, h = seq.ground_truth[0]
        np.testing.assert_allclose(tracker.position, [y + (h - 1) / 2, x + (w - 1) / 2])

"""Knowing the target is lost and finding it again: the reliability score changes no box, the
``reliable`` gate holds the filter and the scale, and re-detection finds a target that jumped
out of the search region of a synthetic sequence."""
import cv2
import numpy as np
import pytest

from dcfkit import load_tracker
from dcfkit.datasets.synthetic import make_sequence
from dcfkit.errors import ConfigError
from dcfkit.experiments.loop import track

LMCF = {"reliability": {"name": "lmcf"}}
GATED = {**LMCF, "schedule": {"name": "reliable"}}
RECOVERING = {**GATED, "redetect": {"name": "grid", "whole_frame": True}}


def jumping_target(n=30, jump=15, size=(240, 320), before=(80, 90), after=(170, 250), side=24, seed=0):
    """A blocky sprite on a blurred-noise background, still at ``before`` until frame ``jump``
    (0-based), then at ``after``: 90 and 160 pixels away, beyond any search region of these
    configs (about 120 pixels across). Returns the frames and the true boxes."""
    rng = np.random.default_rng(seed)
    ground = cv2.GaussianBlur(rng.integers(60, 200, size + (3,), dtype=np.uint8), (0, 0), 3)
    blocks = rng.integers(0, 256, (6, 6, 3), dtype=np.uint8)
    sprite = cv2.resize(blocks, (side, side), interpolation=cv2.INTER_NEAREST)
    frames, boxes = [], []
    for k in range(n):
        image = ground.copy()
        cy, cx = before if k < jump else after
        image[cy - side // 2: cy + side // 2, cx - side // 2: cx + side // 2] = sprite
        frames.append(image)
        boxes.append((cx - side // 2, cy - side // 2, side, side))
    return frames, np.array(boxes, dtype=float)


def iou(a, b):
    x1, y1 = np.maximum(a[:2], b[:2])
    x2, y2 = np.minimum(a[:2] + a[2:], b[:2] + b[2:])
    inter = max(x2 - x1, 0) * max(y2 - y1, 0)
    return inter / (a[2] * a[3] + b[2] * b[3] - inter)


@pytest.mark.parametrize("config", ["strcf", "dr2track", "csrdcf"])
def test_a_reliability_score_alone_changes_no_box(config):
    seq = make_sequence(n_frames=12, seed=4)
    plain = track(load_tracker(config), seq.frames, seq.ground_truth[0])
    scored = track(load_tracker(config, overrides=LMCF), seq.frames, seq.ground_truth[0])
    np.testing.assert_array_equal(scored.boxes, plain.boxes)
    np.testing.assert_array_equal(scored.confidence[:, :2], plain.confidence[:, :2])
    np.testing.assert_array_equal(plain.confidence[1:, 2], plain.confidence[1:, 0])  # no component: the peak
    assert np.all(scored.confidence[1:, 2] != scored.confidence[1:, 0])  # the component's score


@pytest.mark.parametrize("config", ["strcf", "bacf"])
def test_the_reliable_gate_holds_the_filter_and_the_scale_on_a_lost_frame(config):
    frames, boxes = jumping_target()
    tracker = load_tracker(config, overrides=GATED)
    tracker.init(frames[0], boxes[0])
    for frame in frames[1:15]:
        tracker.update(frame)
    assert tracker.last_confidence.score >= 1  # the still target: reliable
    kept, scale = np.copy(tracker.hf), tracker.scale
    tracker.update(frames[15])  # the target jumped away: what the search sees is background
    assert tracker.last_confidence.score < 1
    np.testing.assert_array_equal(tracker.hf, kept)
    assert tracker.scale == scale
    ungated = load_tracker(config, overrides=LMCF)  # the same frames without the gate: it learns
    ungated.init(frames[0], boxes[0])
    for frame in frames[1:16]:
        ungated.update(frame)
    assert not np.array_equal(ungated.hf, kept)


@pytest.mark.parametrize("config", ["strcf", "dr2track"])
def test_redetection_finds_a_target_that_left_the_search_region(config):
    frames, boxes = jumping_target()
    lost = track(load_tracker(config), frames, boxes[0]).boxes
    found = track(load_tracker(config, overrides=RECOVERING), frames, boxes[0])
    assert iou(lost[-1], boxes[-1]) == 0  # without recovery the tracker stays where the target was
    assert iou(found.boxes[-1], boxes[-1]) > 0.8
    assert found.confidence[-1, 2] >= 1  # and says it is sure again
    np.testing.assert_array_equal(found.boxes[:15], lost[:15])  # nothing moves before the loss


def test_redetection_takes_nothing_while_the_target_is_kept():
    seq = make_sequence(n_frames=12, seed=4)
    plain = track(load_tracker("strcf", overrides=GATED), seq.frames, seq.ground_truth[0])
    redetecting = track(load_tracker("strcf", overrides={**GATED, "redetect": {"name": "grid"}}), seq.frames,
                        seq.ground_truth[0])
    assert (plain.confidence[1:, 2] >= 1).all()  # every frame reliable: no re-detection is tried
    np.testing.assert_array_equal(redetecting.boxes, plain.boxes)


def test_channel_weighted_trackers_probe_candidates_too():
    frames, boxes = jumping_target()
    run = track(load_tracker("csrdcf", overrides=RECOVERING), frames, boxes[0])
    assert np.isfinite(run.boxes).all() and np.isfinite(run.confidence[1:]).all()


@pytest.mark.parametrize("overrides, key", [({"schedule": {"name": "reliable"}}, "schedule 'reliable'"),
                                            ({"redetect": {"name": "grid"}}, "redetect 'grid'")])
def test_a_gate_or_redetection_without_reliability_is_refused(overrides, key):
    with pytest.raises(ConfigError, match=f"{key} acts on the reliability.*reliability: {{name: lmcf}}"):
        load_tracker("strcf", overrides=overrides)


@pytest.mark.parametrize("slot, spec", [("reliability", {"name": "lmcf"}), ("redetect", {"name": "grid"})])
def test_the_continuous_loop_refuses_recovery(slot, spec):
    with pytest.raises(ConfigError, match=f"{slot} '{spec['name']}': solver 'eco' runs in the continuous loop"):
        load_tracker("eco_hc", overrides={slot: spec})
    with pytest.raises(ConfigError, match="schedule 'reliable' gates on the reliability .* continuous loop"):
        load_tracker("eco_hc", overrides={"schedule": {"name": "reliable"}})

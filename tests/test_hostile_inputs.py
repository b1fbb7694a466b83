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
from dcfkit.config import load_config
from dcfkit.datasets import DatasetError, read_frame
from dcfkit.errors import ConfigError, InputError
from dcfkit.synthetic import make_sequence
from dcfkit.video import iter_frames

CONFIGS = ("strcf", "bacf", "dr2track", "kcf", "dsst")
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
    scale = load_config(config)["scale"]["name"]
    sides = st.one_of(st.integers(8, 250), st.integers(8, 2000))  # of the sample areas' squares
    low, high = sorted(float(v * v) for v in draw(st.lists(sides, min_size=2, max_size=2)))
    overrides = {"tracker.search_area_scale": draw(st.floats(1, 50)),
                 "tracker.search_area_shape": draw(st.sampled_from(["square", "proportional"])),
                 "tracker.min_image_sample_size": low, "tracker.max_image_sample_size": high,
                 "tracker.cell_size": draw(st.one_of(st.integers(2, 8), st.integers(1, 64))),
                 "tracker.cell_selection_thresh": draw(st.sampled_from([0.0, 0.75**2, 1.0])),
                 "tracker.sampling": draw(st.sampled_from(["subpixel", "whole_pixel"]))}
    if scale == "fixed":  # KCF: one scale, no parameters
        return config, overrides
    n, step = draw(pyramid_span(3 if scale == "dsst" else 1))
    overrides.update({"scale.n_scales": n, "scale.step": step})
    if scale == "dsst":
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
    refused with a ConfigError naming the variable (or the DSST's own working-patch bound, or
    its box with an InputError), or tracks a frame in under 100 MB of arrays: configs inside the
    allowed ranges used to need gigabytes (2000² samples at 1-px cells, 101 search scales of
    them, a 9000² DSST working patch)."""
    config, overrides = spec
    tracker(config)  # the compiled loops loaded before anything is measured
    for name, value in BUDGET.items():
        monkeypatch.setenv(name, value)
    try:
        built = dcfkit.load_tracker(config, overrides=overrides)
    except ConfigError as exc:  # over the budget, or over the DSST's own working-patch bound
        assert "$DCFKIT_MAX_SAMPLE_PIXELS" in str(exc) or "working patch would have" in str(exc)
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
    monkeypatch.setenv("DCFKIT_MAX_SAMPLE_PIXELS", "4e8")
    assert dcfkit.load_tracker("strcf", overrides=big).params.cell_size == 1
    monkeypatch.setenv("DCFKIT_MAX_SAMPLE_PIXELS", str(2**18))
    with pytest.raises(ConfigError, match=r"dr2track: scale.n_scales 101 samples of scale.model_max_area 5000 px, "
                                          r"and their working patch \(scale.step 1.01\), are 5.42e\+05 px a frame"):
        dcfkit.load_tracker("dr2track", overrides={"scale.n_scales": 101, "scale.step": 1.01,
                                                   "scale.model_max_area": 5000})
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


def test_a_dsst_copy_over_the_image_budget_refuses_init_before_any_state_changes(monkeypatch):
    """DR²Track's scale samples are whole-pixel crops of up to 1.6 times the target: for a box
    ten times the image they hold 1.6 million pixels, far more than its search sample copies.
    The refusal comes before anything changes: the tracker goes on as if init had not been
    called."""
    tracking, reference = dcfkit.load_tracker("dr2track"), dcfkit.load_tracker("dr2track")
    for t in (tracking, reference):
        t.init(SEQUENCE.frames[0], SEQUENCE.ground_truth[0])
    monkeypatch.setenv("DCFKIT_MAX_IMAGE_PIXELS", "1e6")
    with pytest.raises(InputError, match=r"frame 1: initial box \(0.0, 0.0, 900.0, 700.0\): the 1444x1123 px region "
                                         r"to copy from the 96x72 image holds 1.62e\+06 pixels, over the limit of 1e\+06"):
        tracking.init(SEQUENCE.frames[0], (0, 0, 900, 700))
    assert tracking.update(SEQUENCE.frames[1]) == reference.update(SEQUENCE.frames[1])


# --------------------------------------------------------------------------- image files

def png_declaring(width: int, height: int) -> bytes:
    """A valid 8x8 PNG whose IHDR chunk claims ``width`` x ``height`` (its CRC fixed)."""
    data = bytearray(cv2.imencode(".png", SEQUENCE.frames[0][:8, :8])[1].tobytes())
    data[16:24] = struct.pack(">II", width, height)
    data[29:33] = struct.pack(">I", zlib.crc32(bytes(data[12:29])))
    return bytes(data)


def jpeg_declaring(width: int, height: int) -> bytes:
    """A valid 8x8 baseline JPEG whose frame header (SOF0) claims ``width`` x ``height``."""
    data = bytearray(cv2.imencode(".jpg", SEQUENCE.frames[0][:8, :8])[1].tobytes())
    sof = data.index(b"\xff\xc0")
    data[sof + 5:sof + 9] = struct.pack(">HH", height, width)
    return bytes(data)


@pytest.fixture
def decodes(monkeypatch):
    """The calls made to cv2.imdecode (read_frame's decoder) while the test runs."""
    calls = []
    real = cv2.imdecode

    def counted(*args, **kwargs):
        calls.append(args)
        return real(*args, **kwargs)

    monkeypatch.setattr(cv2, "imdecode", counted)
    return calls


@given(kind=st.sampled_from(["png", "jpeg"]), width=st.integers(1, 65535), height=st.integers(1, 65535))
@example(kind="png", width=30000, height=30000)  # the 876 KB PNG that needed 5.3 GB
@example(kind="jpeg", width=2000, height=2000)
def test_an_image_larger_than_the_limit_is_refused_from_its_header(kind, width, height, tmp_path, monkeypatch,
                                                                   decodes):
    """With the limit lowered to a million pixels, a header over it is refused naming the file,
    its size and the variable, without decoding anything; one under it is decoded or refused
    as unreadable (its data is an 8x8 image's)."""
    monkeypatch.setenv("DCFKIT_MAX_IMAGE_PIXELS", "1e6")
    path = tmp_path / f"frame.{kind}"
    path.write_bytes((png_declaring if kind == "png" else jpeg_declaring)(width, height))
    decodes.clear()
    if width * height > 10**6:
        said = (rf"{width}x{height} = .* pixels, over the limit of 1e\+06: \$DCFKIT_MAX_IMAGE_PIXELS\)"
                if width * height <= 2 * Image.MAX_IMAGE_PIXELS else "more pixels than Pillow reads")
        with pytest.raises(DatasetError, match=rf"cannot read frame 4: .*frame\.{kind} \(its header declares {said}"):
            read_frame(path, "frame 4")
        assert not decodes
        return
    try:
        read_frame(path)
    except DatasetError:
        pass


def test_pillows_own_bomb_limit_is_a_dataset_error_too(tmp_path, monkeypatch, decodes):
    """Pillow refuses headers over twice PIL.Image.MAX_IMAGE_PIXELS (1.79e8) itself, even when
    dcfkit's limit is raised past it."""
    monkeypatch.setenv("DCFKIT_MAX_IMAGE_PIXELS", "1e12")
    path = tmp_path / "bomb.png"
    path.write_bytes(png_declaring(30000, 30000))
    with pytest.raises(DatasetError, match=r"bomb\.png \(its header declares more pixels than Pillow reads: "
                                           r"1\.79e\+08, twice PIL.Image.MAX_IMAGE_PIXELS\)"):
        read_frame(path)
    assert not decodes


def libjpeg_verdict(data: bytes, capfd) -> tuple[np.ndarray | None, str]:
    """OpenCV's decode of ``data`` and what its libjpeg printed (warnings of corrupt data)."""
    capfd.readouterr()
    image = cv2.imdecode(np.frombuffer(data, np.uint8), cv2.IMREAD_COLOR)
    return image, capfd.readouterr().err


TEXTURE = make_sequence(n_frames=1, size=(96, 128), target=(10, 14), distractor=False).frames[0]
JPEG = cv2.imencode(".jpg", TEXTURE, [cv2.IMWRITE_JPEG_QUALITY, 90])[1].tobytes()
SCAN = JPEG.index(b"\xff\xda") + 14  # the entropy-coded data (the scan header is 12 bytes + marker)


@given(flips=st.lists(st.tuples(st.integers(SCAN, len(JPEG) - 3), st.integers(1, 255)), min_size=1, max_size=200))
def test_a_jpeg_whose_data_libjpeg_reports_corrupt_is_refused(flips, tmp_path, capfd):
    """Bytes of the coded data changed, the end-of-image marker kept (as the fault-injection
    pass did): whenever OpenCV's libjpeg warns about the data, read_frame refuses the file,
    naming it; otherwise it returns OpenCV's decode unchanged. (A change libjpeg cannot see is
    indistinguishable from a different picture.)"""
    data = bytearray(JPEG)
    for position, xor in flips:
        data[position] ^= xor
    path = tmp_path / "frame.jpg"
    path.write_bytes(bytes(data))
    expected, warnings = libjpeg_verdict(bytes(data), capfd)
    event("libjpeg warns" if expected is None or warnings.strip() else "libjpeg silent")
    if expected is None or warnings.strip():
        with pytest.raises(DatasetError, match=r"cannot read frame 9: .*frame\.jpg \((corrupt JPEG data|truncated "
                                               r"JPEG|not a readable image)"):
            read_frame(path, "frame 9")
    else:
        np.testing.assert_array_equal(read_frame(path, "frame 9"), expected)


def test_valid_jpegs_decode_as_opencv_decodes_them(tmp_path):
    """The strict check changes no pixel: the same array as cv2.imdecode, for baseline,
    progressive, gray and 4:4:4 JPEGs."""
    variants = {"baseline": [], "progressive": [cv2.IMWRITE_JPEG_PROGRESSIVE, 1],
                "444": [cv2.IMWRITE_JPEG_SAMPLING_FACTOR, cv2.IMWRITE_JPEG_SAMPLING_FACTOR_444]}
    for name, params in variants.items():
        for image in (TEXTURE, cv2.cvtColor(TEXTURE, cv2.COLOR_BGR2GRAY)):
            data = cv2.imencode(".jpg", image, params)[1].tobytes()
            path = tmp_path / f"{name}.jpg"
            path.write_bytes(data)
            np.testing.assert_array_equal(read_frame(path), cv2.imdecode(np.frombuffer(data, np.uint8),
                                                                         cv2.IMREAD_COLOR))


def test_a_corrupt_frame_ends_the_run_naming_it_and_keeps_the_boxes_before(tmp_path, capsys):
    folder = tmp_path / "frames"
    folder.mkdir()
    frames = make_sequence(n_frames=4, size=(96, 128), target=(10, 14), distractor=False)
    for i, frame in enumerate(frames.frames, start=1):
        cv2.imwrite(str(folder / f"{i}.jpg"), frame)
    data = bytearray((folder / "3.jpg").read_bytes())
    scan = data.index(b"\xff\xda") + 14
    for position in np.random.default_rng(0).integers(scan, len(data) - 2, 200):  # the pass's 200 flipped bytes
        data[position] ^= 0xFF
    (folder / "3.jpg").write_bytes(bytes(data))
    out = tmp_path / "boxes.txt"
    box = ",".join(str(v) for v in frames.ground_truth[0])
    assert cli.main(["track", "strcf", "--frames", str(folder), f"--box={box}", "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert "error: cannot read frame 3: " in err and "3.jpg (corrupt JPEG data: " in err
    assert len(out.read_text().splitlines()) == 2  # frames 1 and 2


# --------------------------------------------------------------------------- videos

def write_video(path, frames) -> bytes:
    writer = cv2.VideoWriter(str(path), cv2.VideoWriter_fourcc(*"MJPG"), 10, frames[0].shape[1::-1])
    for frame in frames:
        writer.write(frame)
    writer.release()
    return path.read_bytes()


VIDEO_FRAMES = make_sequence(n_frames=8, size=(96, 128), target=(10, 14), distractor=False)


@pytest.mark.parametrize("kept", [0.3, 0.5, 0.8])
def test_a_truncated_video_ends_with_an_error_naming_the_frame_where_it_stops(kept, tmp_path, capsys):
    """An MJPG .avi cut short: the frames before the last one read are the complete video's,
    the last one (partly lost, filled in by FFmpeg) is not given, and the error names it and
    the count the header declares; `dcfkit track` exits 2 with the boxes of the frames before."""
    full = tmp_path / "full.avi"
    data = write_video(full, VIDEO_FRAMES.frames)
    cut = tmp_path / "cut.avi"
    cut.write_bytes(data[:int(len(data) * kept)])
    complete = list(iter_frames(video=str(full)))
    got = []
    with pytest.raises(InputError, match=r"--video: .*cut\.avi stops at frame (\d) of the 8 its header declares") as e:
        got.extend(iter_frames(video=str(cut)))
    stop = int(e.value.args[0].split("stops at frame ")[1].split()[0])
    assert len(got) == stop - 1 and all(np.array_equal(a, b) for a, b in zip(got, complete))
    out = tmp_path / "boxes.txt"
    box = ",".join(str(v) for v in VIDEO_FRAMES.ground_truth[0])
    assert cli.main(["track", "strcf", "--video", str(cut), f"--box={box}", "--out", str(out)]) == 2
    assert f"stops at frame {stop} of the 8" in capsys.readouterr().err
    assert len(out.read_text().splitlines() if out.exists() else []) == stop - 1  # none: no file


def test_video_frames_over_the_image_limit_are_refused_before_reading(tmp_path, monkeypatch):
    path = tmp_path / "v.avi"
    write_video(path, VIDEO_FRAMES.frames)
    monkeypatch.setenv("DCFKIT_MAX_IMAGE_PIXELS", "10000")
    with pytest.raises(InputError, match=r"v\.avi has 128x96 = 1\.23e\+04 pixel frames, over the limit of 1e\+04 "
                                         r"\(\$DCFKIT_MAX_IMAGE_PIXELS\)"):
        next(iter_frames(video=str(path)))


# --------------------------------------------------------------------------- the demo

@pytest.mark.parametrize("args,said", [
    (["--frames", "251"], "expected a whole number of frames from 2 to 250, got '251'"),
    (["--frames", "100000000"], "expected a whole number of frames from 2 to 250"),
    (["--seed", "-1"], "expected a whole number >= 0, got '-1'"),
    (["--seed", "1.5"], "expected a whole number >= 0, got '1.5'"),
])
def test_demo_arguments_out_of_range_are_usage_errors(args, said, capsys):
    """--frames beyond the generated world (the camera drifts off it near frame 265: frames
    shrank and tracking failed) and negative seeds (numpy raised) are refused by argparse."""
    with pytest.raises(SystemExit) as e:
        cli.main(["demo", "--save-video", "", *args])
    assert e.value.code == 2 and said in capsys.readouterr().err


def test_only_regular_frame_files_of_bounded_size_are_read(tmp_path, monkeypatch):
    import os

    """A FIFO would block, /dev/zero never end, a sparse 6 GB file fill memory: refused unread."""
    from dcfkit.datasets import DatasetError, read_frame

    fifo = tmp_path / "00001.jpg"
    os.mkfifo(fifo)
    with pytest.raises(DatasetError, match=r"00001\.jpg \(not a regular file\)"):
        read_frame(fifo)
    monkeypatch.setenv("DCFKIT_MAX_IMAGE_PIXELS", "1000")
    big = tmp_path / "00002.png"
    with open(big, "wb") as f:
        f.truncate(10**7)  # sparse
    with pytest.raises(DatasetError, match=r"00002\.png \(1e\+07 bytes, more than an image of the limit"):
        read_frame(big)


def test_many_feature_channels_are_refused_at_load():
    import dcfkit
    from dcfkit.errors import ConfigError

    features = [{"name": "fhog", "n_orients": 36}] * 10
    with pytest.raises(ConfigError, match=r"1120 channels together, over the limit of 256"):
        dcfkit.load_tracker("strcf", overrides={"features": features})


def test_a_short_video_is_an_error_only_where_the_frame_count_is_an_index():
    """MKV and WebM counts are duration x fps estimates: a complete file may fall short of them."""
    from dcfkit.errors import InputError
    from dcfkit.video import _stopped_short

    with pytest.raises(InputError, match=r"cut\.avi stops at frame 8 of the 10 .*not tracked"):
        _stopped_short("cut.avi", 8, 10)
    with pytest.warns(RuntimeWarning, match=r"long\.mkv stops at frame 8 of the 10 .*tracked as the last"):
        _stopped_short("long.mkv", 8, 10)

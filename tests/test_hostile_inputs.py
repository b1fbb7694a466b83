"""Hostile input (issue 15): extreme boxes, configs at the edges of their ranges, images that
declare billions of pixels, corrupt JPEGs, truncated videos. Each ends in dcfkit's own error
naming what was wrong, in bounded memory and work (elements computed on, not seconds: the
CPU is not the tests' to know), or is tracked as before.

The property tests use the derandomized profile of conftest.py; their budgets are lowered
through the environment variables a user would set, so that each example stays small."""
from __future__ import annotations

import io
import struct
import tracemalloc
import warnings
import zlib

import cv2
import numpy as np
import pytest
import scipy.fft
import simplejpeg
from hypothesis import event, example, given
from hypothesis import strategies as st
from PIL import Image

import dcfkit
from dcfkit import cli
from dcfkit.config import load_config
from dcfkit.datasets import DatasetError, images, read_frame
from dcfkit.datasets.synthetic import make_sequence
from dcfkit.datasets.video import open_source
from dcfkit.errors import ConfigError, DcfkitError, InputError

CONFIGS = ("strcf", "bacf", "dr2track", "kcf", "dsst", "csrdcf", "eco_hc")
SEQUENCE = make_sequence(n_frames=2, size=(72, 96), target=(10, 14), distractor=False)
_TRACKERS: dict[str, dcfkit.Tracker] = {}


def tracker(config: str) -> dcfkit.Tracker:
    """One tracker per shipped config for the whole module (init starts it over), run once
    before it is measured: the first run loads the compiled loops."""
    if config not in _TRACKERS:
        _TRACKERS[config] = dcfkit.load_tracker(config)
        _TRACKERS[config].init(SEQUENCE.frames[0], SEQUENCE.ground_truth[0])
    return _TRACKERS[config]


# What a tracker computes on: the arrays its FFTs transform and the images OpenCV resamples or
# pads (in elements), whatever the CPU. Counted where the library calls them, by module attribute.
WORKERS = [(scipy.fft, name) for name in ("rfft2", "irfft2", "fft2", "ifft2")] + \
          [(np.fft, name) for name in ("fft", "ifft")] + \
          [(cv2, name) for name in ("resize", "warpAffine", "copyMakeBorder")]


class Measured:
    """The elements worked on (:data:`WORKERS`' inputs and outputs) and the peak of traced
    allocations (numpy's and OpenCV's arrays) in the block: both independent of the machine."""

    def __enter__(self):
        self.elements = 0
        self._real = [(module, name, getattr(module, name)) for module, name in WORKERS]
        for module, name, real in self._real:
            setattr(module, name, self._counted(real))
        tracemalloc.start()
        return self

    def _counted(self, real):
        def counted(source, *args, **kwargs):
            out = real(source, *args, **kwargs)
            self.elements += np.size(source) + np.size(out)
            return out
        return counted

    def __exit__(self, *exc):
        self.peak_mb = tracemalloc.get_traced_memory()[1] / 2**20
        tracemalloc.stop()
        for module, name, real in self._real:
            setattr(module, name, real)


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
@example(box=(0, 0, 1, 2))  # BACF's floored size of a 1-px target shrinking: an empty box
def test_any_initial_box_is_tracked_or_refused_in_bounded_memory_and_work(box):
    """Every shipped tracker either refuses the box with an InputError naming it, or tracks the
    next frame to a finite box of positive size; in under 200 MB and 1.5e9 elements worked on
    either way (a box of 1e6 px used to ask OpenCV for 30 GB; the largest box kept, ten times
    the image, takes 7.3e8)."""
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
        assert used.elements < 1.5e9 and used.peak_mb < 200, (config, used.elements, used.peak_mb)


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
    shipped = load_config(config)
    scale = shipped["scale"]["name"]
    sides = st.one_of(st.integers(8, 250), st.integers(8, 2000))  # of the sample areas' squares
    low, high = sorted(float(v * v) for v in draw(st.lists(sides, min_size=2, max_size=2)))
    template = shipped["tracker"].get("search_area_shape") == "padded_square"  # CSR-DCF's, whole pixels only
    shape = draw(st.sampled_from(["square", "proportional"] + ["padded_square"] * template))
    sampling = "whole_pixel" if shape == "padded_square" else draw(st.sampled_from(["subpixel", "whole_pixel"]))
    overrides = {"tracker.search_area_scale": draw(st.floats(1, 50)), "tracker.search_area_shape": shape,
                 "tracker.min_image_sample_size": low, "tracker.max_image_sample_size": high,
                 "tracker.cell_size": draw(st.one_of(st.integers(2, 8), st.integers(1, 64))),
                 "tracker.cell_selection_thresh": draw(st.sampled_from([0.0, 0.75**2, 1.0])),
                 "tracker.sampling": sampling}
    if shape != "padded_square" and shipped["tracker"].get("resize", "auto") != "auto":  # the template's resize
        overrides["tracker.resize"] = "auto"
    if shipped["solver"]["name"] == "eco":  # the continuous loop refuses the keys it does not read
        del overrides["tracker.cell_selection_thresh"], overrides["tracker.sampling"]
    if scale == "fixed":  # KCF: one scale, no parameters
        return config, overrides
    n, step = draw(pyramid_span(3 if scale in ("dsst", "fdsst") else 1))
    if scale == "fdsst":  # ECO-HC's: the span is of the interpolated scales, sampled at fewer
        overrides.update({"scale.n_interp": n, "scale.step": step, "scale.n_scales": draw(st.integers(3, n)),
                          "scale.model_max_area": draw(st.integers(1, 10000)),
                          "scale.cell_size": draw(st.integers(1, 16))})
        return config, overrides
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
    its box with an InputError), or tracks a frame in under 100 MB of arrays and 1e8 elements
    worked on (the most any example takes is 4e7): configs inside the
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
    assert used.peak_mb < 100 and used.elements < 1e8, (used.peak_mb, used.elements)


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
    called. (Sub-pixel sampling: the whole-pixel search sample would copy its own region first.)"""
    tracking, reference = (dcfkit.load_tracker("dr2track", overrides={"tracker.sampling": "subpixel"}) for _ in "ab")
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
    """The calls made to read_frame's decoders while the test runs: ``("cv2", args)`` for
    cv2.imdecode, ``("simplejpeg", args)`` for a full-size simplejpeg.decode_jpeg (not its
    1/8-scale damage check, which passes ``min_width``)."""
    calls = []
    images.decoders_agree()  # its own decodes, once a process, before counting

    def counting(name, real):
        def counted(*args, **kwargs):
            if "min_width" not in kwargs:
                calls.append((name, args))
            return real(*args, **kwargs)
        return counted

    monkeypatch.setattr(cv2, "imdecode", counting("cv2", cv2.imdecode))
    monkeypatch.setattr(simplejpeg, "decode_jpeg", counting("simplejpeg", simplejpeg.decode_jpeg))
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


def png_chunk(kind: bytes, body: bytes, crc: int | None = None) -> bytes:
    """One PNG chunk; its CRC is ``crc`` if given, else the right one."""
    crc = zlib.crc32(kind + body) if crc is None else crc
    return struct.pack(">I", len(body)) + kind + body + struct.pack(">I", crc)


def with_bad_text_chunk(png: bytes) -> bytes:
    """``png`` with a tEXt chunk whose CRC is wrong, after its IHDR (8 + 25 bytes)."""
    return png[:33] + png_chunk(b"tEXt", b"Comment\0made by a camera", crc=0) + png[33:]


def test_a_bad_crc_in_an_ancillary_png_chunk_is_read_as_libpng_reads_it(tmp_path, monkeypatch, capfd, decodes):
    """A tEXt chunk with a bad CRC: libpng (OpenCV's decoder) warns and decodes the image, Pillow
    refused its header; read_frame returns OpenCV's pixels, and still refuses such a PNG whose
    IDAT data is damaged too (libpng's error: OpenCV returns nothing), naming the frame, and
    one whose IHDR declares over the limit, from the header, decoding nothing."""
    png = with_bad_text_chunk(cv2.imencode(".png", TEXTURE)[1].tobytes())
    capfd.readouterr()
    expected = cv2.imdecode(np.frombuffer(png, np.uint8), cv2.IMREAD_COLOR)
    assert "tEXt: CRC error" in capfd.readouterr().err
    np.testing.assert_array_equal(expected, TEXTURE)
    path = tmp_path / "frame.png"
    path.write_bytes(png)
    np.testing.assert_array_equal(read_frame(path, "frame 2"), expected)
    idat = png.index(b"IDAT") + 4
    damaged = bytearray(png)
    damaged[idat + 100] ^= 0x55
    path.write_bytes(bytes(damaged))
    with pytest.raises(DatasetError, match=r"cannot read frame 2: .*frame\.png \(not a readable image\)"):
        read_frame(path, "frame 2")
    monkeypatch.setenv("DCFKIT_MAX_IMAGE_PIXELS", "1e6")
    path.write_bytes(with_bad_text_chunk(png_declaring(2000, 2000)))
    decodes.clear()
    with pytest.raises(DatasetError, match=r"cannot read frame 2: .*frame\.png \(its header declares 2000x2000 = "):
        read_frame(path, "frame 2")
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


JPEG_VARIANTS = {"baseline": [], "quality 100": [cv2.IMWRITE_JPEG_QUALITY, 100],
                 "quality 20": [cv2.IMWRITE_JPEG_QUALITY, 20], "progressive": [cv2.IMWRITE_JPEG_PROGRESSIVE, 1],
                 "optimized": [cv2.IMWRITE_JPEG_OPTIMIZE, 1], "restarts": [cv2.IMWRITE_JPEG_RST_INTERVAL, 3],
                 **{f"{name[-3:]}": [cv2.IMWRITE_JPEG_SAMPLING_FACTOR, getattr(cv2, name)]
                    for name in ("IMWRITE_JPEG_SAMPLING_FACTOR_411", "IMWRITE_JPEG_SAMPLING_FACTOR_422",
                                 "IMWRITE_JPEG_SAMPLING_FACTOR_440", "IMWRITE_JPEG_SAMPLING_FACTOR_444")}}


@pytest.mark.parametrize("variant", JPEG_VARIANTS)
def test_valid_jpegs_decode_as_opencv_decodes_them(variant, tmp_path, decodes):
    """A JPEG libjpeg decodes cleanly is decoded once, not by OpenCV, to the same array as
    cv2.imdecode: colour and gray, each chroma subsampling, progressive, optimized and with
    restart markers, at sizes that leave partial blocks (1x1, 9x17, 33x65)."""
    for size in ((96, 128), (1, 1), (9, 17), (33, 65)):
        colour = cv2.resize(TEXTURE, size[::-1], interpolation=cv2.INTER_AREA)
        for image in (colour, cv2.cvtColor(colour, cv2.COLOR_BGR2GRAY)):
            data = cv2.imencode(".jpg", image, JPEG_VARIANTS[variant])[1].tobytes()
            expected = cv2.imdecode(np.frombuffer(data, np.uint8), cv2.IMREAD_COLOR)
            path = tmp_path / "frame.jpg"
            path.write_bytes(data)
            decodes.clear()
            np.testing.assert_array_equal(read_frame(path), expected, err_msg=f"{variant}, {image.shape}")
            assert [decoder for decoder, _ in decodes] == ["simplejpeg"], (variant, image.shape)


def test_where_simplejpeg_decodes_otherwise_opencv_decodes_every_frame(tmp_path, monkeypatch, decodes):
    """An OpenCV built on another libjpeg would decode some JPEG otherwise than simplejpeg: the
    check at the first read finds it (here simplejpeg's 4:2:0 pixels are made one level off),
    and every frame is OpenCV's."""
    real = simplejpeg.decode_jpeg

    def otherwise(data, *args, **kwargs):
        image = real(data, *args, **kwargs)
        header = simplejpeg.decode_jpeg_header(data)
        return image + 1 if header[3] == "420" else image

    images.decoders_agree.cache_clear()
    monkeypatch.setattr(simplejpeg, "decode_jpeg", otherwise)
    try:
        assert not images.decoders_agree()
        path = tmp_path / "frame.jpg"
        path.write_bytes(JPEG)
        expected = cv2.imdecode(np.frombuffer(JPEG, np.uint8), cv2.IMREAD_COLOR)
        decodes.clear()
        np.testing.assert_array_equal(read_frame(path), expected)
        assert [decoder for decoder, _ in decodes] == ["cv2"]
    finally:
        images.decoders_agree.cache_clear()


@pytest.mark.parametrize("orientation", [1, 3, 6, 8])
def test_a_jpeg_with_exif_is_turned_as_opencv_turns_it(orientation, tmp_path, decodes):
    """OpenCV turns an image as its EXIF orientation tag says (6: 90 degrees clockwise), which
    libjpeg alone does not: read_frame leaves a JPEG with EXIF data to OpenCV."""
    exif = Image.Exif()
    exif[0x0112] = orientation
    buffer = io.BytesIO()
    Image.fromarray(TEXTURE[..., ::-1]).save(buffer, "JPEG", quality=90, exif=exif.tobytes())
    path = tmp_path / "frame.jpg"
    path.write_bytes(buffer.getvalue())
    expected = cv2.imdecode(np.frombuffer(buffer.getvalue(), np.uint8), cv2.IMREAD_COLOR)
    assert expected.shape[:2] == (TEXTURE.shape[:2] if orientation in (1, 3) else TEXTURE.shape[1::-1])
    decodes.clear()
    np.testing.assert_array_equal(read_frame(path), expected)
    assert "cv2" in [decoder for decoder, _ in decodes]


def segment(marker: int, payload: bytes) -> bytes:
    """A JPEG header segment: its marker, its length (which counts itself) and ``payload``."""
    return bytes([0xFF, marker]) + struct.pack(">H", len(payload) + 2) + payload


@pytest.mark.parametrize("before", ["an ICC profile holding the bytes of a scan marker", "a JFXX thumbnail"])
def test_exif_after_a_segment_holding_marker_bytes_is_still_seen(before, tmp_path, decodes):
    """EXIF data after a segment whose payload holds FF DA (the start-of-scan marker's bytes) is
    still EXIF data: OpenCV's turn, not libjpeg's unturned picture."""
    exif = Image.Exif()
    exif[0x0112] = 6
    buffer = io.BytesIO()
    Image.fromarray(TEXTURE[..., ::-1]).save(buffer, "JPEG", quality=90, exif=exif.tobytes())
    start = buffer.getvalue().index(b"\xff\xe1")  # Pillow's EXIF segment
    exif_segment = buffer.getvalue()[start:start + 2 + struct.unpack(">H", buffer.getvalue()[start + 2:start + 4])[0]]
    rest = buffer.getvalue().replace(exif_segment, b"")
    first = (segment(0xE2, b"ICC_PROFILE\0\x01\x01" + b"\x00\x10\xff\xda\x00\x00" * 4)
             if before.startswith("an ICC") else segment(0xE0, b"JFXX\0\x10" + JPEG))
    data = rest[:2] + first + exif_segment + rest[2:]
    path = tmp_path / "frame.jpg"
    path.write_bytes(data)
    expected = cv2.imdecode(np.frombuffer(data, np.uint8), cv2.IMREAD_COLOR)
    assert expected.shape[:2] == TEXTURE.shape[1::-1]  # turned
    decodes.clear()
    np.testing.assert_array_equal(read_frame(path), expected)
    assert "cv2" in [decoder for decoder, _ in decodes]


def with_padding(data: bytes, padding: bytes) -> bytes:
    """``data`` with ``padding`` between its last scan and its end-of-image marker."""
    assert data.endswith(b"\xff\xd9")
    return data[:-2] + padding + data[-2:]


def early_finish(capfd) -> bytes:
    """JPEG with one byte changed so that the decoder finishes early, leaving coded data before
    the end-of-image marker: libjpeg warns as it does for padding there."""
    for offset in range(SCAN, len(JPEG) - 2):
        damaged = bytearray(JPEG)
        damaged[offset] ^= 0xFF
        image, warned = libjpeg_verdict(bytes(damaged), capfd)
        if image is not None and "extraneous bytes before marker 0xd9" in warned:
            return bytes(damaged)
    pytest.fail("no changed byte makes the decoder finish early")


def test_zero_padding_before_the_end_marker_is_read_and_damage_warned_alike_is_not(tmp_path, capfd):
    """Zero bytes some writers put before the end-of-image marker: libjpeg warns ("extraneous
    bytes before marker 0xd9") and OpenCV decodes the same pixels; read_frame returns them,
    baseline and progressive. The same warning for a damaged JPEG (the decoder finished early),
    zero padding added to it, or nonzero bytes there, is still a refusal naming the frame."""
    path = tmp_path / "frame.jpg"
    for params in ([], [cv2.IMWRITE_JPEG_PROGRESSIVE, 1]):
        plain = cv2.imencode(".jpg", TEXTURE, params)[1].tobytes()
        for count in (16, 1000):  # the few bytes libjpeg-turbo has read ahead go unreported
            data = with_padding(plain, bytes(count))
            image, warned = libjpeg_verdict(data, capfd)
            assert "extraneous bytes before marker 0xd9" in warned
            path.write_bytes(data)
            np.testing.assert_array_equal(read_frame(path), image)
            np.testing.assert_array_equal(image, cv2.imdecode(np.frombuffer(plain, np.uint8), cv2.IMREAD_COLOR))
    damaged = early_finish(capfd)
    for data in (damaged, with_padding(damaged, bytes(8)), with_padding(JPEG, b"\x12\x34"),
                 with_padding(JPEG, b"\0\0\x01\0\0")):
        path.write_bytes(data)
        with pytest.raises(DatasetError, match=r"cannot read frame 5: .*frame\.jpg \(corrupt JPEG data: Corrupt JPEG "
                                               r"data: \d+ extraneous bytes before marker 0xd9\)"):
            read_frame(path, "frame 5")


@pytest.mark.parametrize("compression,name", [(5, "tiff_lzw"), (8, "tiff_adobe_deflate")])
def test_a_tiff_whose_data_libtiff_cannot_decode_is_refused(compression, name, tmp_path, capfd):
    """LZW and Deflate TIFFs with bytes of their strip overwritten: OpenCV's libtiff prints an
    error and returns the image, a fifth of it wrong; read_frame refuses the file naming the
    frame. Intact, they are read as OpenCV reads them."""
    data = cv2.imencode(".tiff", TEXTURE, [cv2.IMWRITE_TIFF_COMPRESSION, compression])[1].tobytes()
    path = tmp_path / "frame.tif"
    path.write_bytes(data)
    np.testing.assert_array_equal(read_frame(path, "frame 6"), TEXTURE)
    damaged = bytearray(data)
    damaged[200:240] = b"\xff" * 40  # the strip starts at byte 8
    capfd.readouterr()
    image = cv2.imdecode(np.frombuffer(bytes(damaged), np.uint8), cv2.IMREAD_COLOR)
    assert image.shape == TEXTURE.shape and "TIFF_Error" in capfd.readouterr().err
    assert (image != TEXTURE).any()
    path.write_bytes(bytes(damaged))
    with pytest.raises(DatasetError, match=rf"cannot read frame 6: .*frame\.tif \(corrupt TIFF data: libtiff cannot "
                                           rf"decode its {name} data\)"):
        read_frame(path, "frame 6")


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
    complete = list(open_source(video=str(full)).frames)
    got = []
    with pytest.raises(InputError, match=r"--video: .*cut\.avi stops at frame (\d) of the 8 its header declares") as e:
        got.extend(open_source(video=str(cut)).frames)
    stop = int(e.value.args[0].split("stops at frame ")[1].split()[0])
    assert len(got) == stop - 1 and all(np.array_equal(a, b) for a, b in zip(got, complete))
    out = tmp_path / "boxes.txt"
    box = ",".join(str(v) for v in VIDEO_FRAMES.ground_truth[0])
    assert cli.main(["track", "strcf", "--video", str(cut), f"--box={box}", "--out", str(out)]) == 2
    assert f"stops at frame {stop} of the 8" in capsys.readouterr().err
    assert len(out.read_text().splitlines() if out.exists() else []) == stop - 1  # none: no file


def damage_frame(data: bytes, frame: int) -> bytes:
    """The MJPG video ``data`` with bytes of frame ``frame``'s (1-based) coded data inverted."""
    start = -1
    for _ in range(frame):
        start = data.index(b"\xff\xd8", start + 1)  # each frame's start-of-image marker
    scan = data.index(b"\xff\xda", start) + 14
    damaged = bytearray(data)
    for position in np.random.default_rng(0).integers(scan, scan + 600, 50):
        damaged[position] ^= 0xFF
    return bytes(damaged)


def test_a_damaged_frame_of_a_motion_jpeg_video_ends_the_run_naming_it(tmp_path, capsys):
    """Frame 3 of an MJPG .avi damaged: FFmpeg decodes all 8 frames, patching over the damage,
    so it was tracked. Now the frames before it are given as before and the error names it;
    `dcfkit track` exits 2 with the boxes of frames 1 and 2."""
    full = tmp_path / "full.avi"
    data = write_video(full, VIDEO_FRAMES.frames)
    damaged = tmp_path / "damaged.avi"
    damaged.write_bytes(damage_frame(data, 3))
    complete = list(open_source(video=str(full)).frames)
    cap = cv2.VideoCapture(str(damaged))
    concealed = [cap.read()[1] for _ in range(8)]
    assert all(image is not None for image in concealed) and not np.array_equal(concealed[2], complete[2])
    got = []
    with pytest.raises(InputError, match=r"--video: .*damaged\.avi: frame 3 is damaged \(corrupt JPEG data: "):
        got.extend(open_source(video=str(damaged)).frames)
    assert len(got) == 2 and all(np.array_equal(a, b) for a, b in zip(got, complete))
    out = tmp_path / "boxes.txt"
    box = ",".join(str(v) for v in VIDEO_FRAMES.ground_truth[0])
    assert cli.main(["track", "strcf", "--video", str(damaged), f"--box={box}", "--out", str(out)]) == 2
    assert "damaged.avi: frame 3 is damaged" in capsys.readouterr().err
    assert len(out.read_text().splitlines()) == 2


def test_a_motion_jpeg_video_cut_inside_its_last_frame_is_refused_there(tmp_path):
    """A cut inside the last frame's data leaves the count the header declares: FFmpeg fills
    the rest of the frame in, and it was tracked. Now the first 7 frames are given and the
    error names frame 8."""
    full = tmp_path / "full.avi"
    data = write_video(full, VIDEO_FRAMES.frames)
    cut = tmp_path / "cut.avi"
    cut.write_bytes(data[:data.rindex(b"\xff\xd8") + 600])
    cap = cv2.VideoCapture(str(cut))
    assert cap.get(cv2.CAP_PROP_FRAME_COUNT) == 8 and all(cap.read()[0] for _ in range(8))
    got = []
    with pytest.raises(InputError, match=r"cut\.avi: frame 8 is damaged \(corrupt JPEG data: Premature end of JPEG"):
        got.extend(open_source(video=str(cut)).frames)
    assert len(got) == 7 and all(np.array_equal(a, b) for a, b in zip(got, open_source(video=str(full)).frames))


def test_video_frames_over_the_image_limit_are_refused_before_reading(tmp_path, monkeypatch):
    path = tmp_path / "v.avi"
    write_video(path, VIDEO_FRAMES.frames)
    monkeypatch.setenv("DCFKIT_MAX_IMAGE_PIXELS", "10000")
    with pytest.raises(InputError, match=r"v\.avi has 128x96 = 1\.23e\+04 pixel frames, over the limit of 1e\+04 "
                                         r"\(\$DCFKIT_MAX_IMAGE_PIXELS\)"):
        next(open_source(video=str(path)).frames)


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
    """MKV and WebM counts are duration x fps estimates: a complete file may fall short of them;
    a URL that stops short lost its stream, whatever its name says."""
    from dcfkit.datasets.video import _stopped_short
    from dcfkit.errors import InputError, InputWarning

    with pytest.raises(InputError, match=r"cut\.avi stops at frame 8 of the 10 .*not tracked"):
        _stopped_short("cut.avi", 8, 10)
    with pytest.warns(InputWarning, match=r"long\.mkv stops at frame 8 of the 10 .*tracked as the last"):
        _stopped_short("long.mkv", 8, 10)
    for url in ("http://cam.local/live", "http://cam.local/clip.mkv", "rtsp://cam.local/1?token=x"):
        with pytest.raises(InputError, match=r"stops at frame 8 of the 10 .*not tracked"):
            _stopped_short(url, 8, 10)


# --------------------------------------------------------------------------- long values in messages

LONG = "q" * 100_000  # an argument this long fits in argv (131072 bytes each on Linux)
MESSAGE_CHARS = 1000  # one error line, whatever the size of the value it is about


@pytest.fixture(scope="module")
def otb_root(tmp_path_factory):
    """ROOT/seqA/img/0001.jpg, 0002.jpg and ROOT/seqA/groundtruth_rect.txt: a 2-frame OTB sequence."""
    root = tmp_path_factory.mktemp("otb")
    (root / "seqA" / "img").mkdir(parents=True)
    for i in (1, 2):
        cv2.imwrite(str(root / "seqA" / "img" / f"{i:04d}.jpg"), SEQUENCE.frames[i - 1])
    (root / "seqA" / "groundtruth_rect.txt").write_text("11,11,14,10\n11,11,14,10\n")
    return root


@pytest.mark.parametrize("args,said", [
    (["eval", "strcf", "--dataset", LONG, "--root", "{root}", "--out", "{out}"], "error: unknown dataset 'qqq"),
    (["eval", "strcf", "--dataset", "otb", "--root", "{root}", "--sequences", LONG, "--out", "{out}"],
     "error: sequence 'qqq"),
    (["eval", "strcf", "--dataset", "otb", "--root", "{root}", "--set", "name=/" + LONG, "--out", "{out}"],
     "error: config 'name' '/qqq"),
    (["eval", "opencv:" + LONG, "--dataset", "otb", "--root", "{root}", "--out", "{out}"],
     "error: unknown OpenCV tracker 'qqq"),
    (["report", "{out}", "--dataset", "otb", "--root", "{root}", "--trackers", LONG],
     "error: no results for tracker 'qqq"),
    (["ablate", "{spec}", "--out", "{out}", "--dry-run"], "spec.yaml: dataset.name: unknown dataset 'qqq"),
    (["ablate", "{otb_spec}", "--out", "{out}", "--root", "{root}", "--sequences", LONG, "--dry-run"],
     "error: sequence 'qqq"),
    (["track", "strcf", "--frames", "{root}/seqA/img", "--box", LONG], "error: --box expects x,y,w,h"),
    (["track", "strcf", "--frames", "{root}/seqA/img", "--box", "10,10,14,10", "--save-video", LONG],
     "error: --save-video: cannot write a video named 'qqq"),
    (["compare", "{out}", "{out}", "--root", "{root}", "--divergence-px", LONG],
     "error: argument --divergence-px: expected a distance in pixels >= 0, got 'qqq"),
    (["ablate", "{spec}", "--out", "{out}", "--executor", LONG], "error: argument --executor: invalid choice"),
])
def test_long_arguments_are_shown_short_in_messages(args, said, otb_root, tmp_path, capsys):
    """A value of 100,000 characters in a command-line argument, a config name or a spec's
    dataset name: the error names it with its start only (it used to be echoed whole)."""
    (tmp_path / "spec.yaml").write_text(f"dataset: {{name: {LONG}}}\nvariants: {{a: strcf}}\n")
    (tmp_path / "otb_spec.yaml").write_text("dataset: otb\nvariants: {a: strcf}\n")
    paths = {"root": otb_root, "out": tmp_path / "out", "spec": tmp_path / "spec.yaml",
             "otb_spec": tmp_path / "otb_spec.yaml"}
    (tmp_path / "out").mkdir()
    try:
        status = cli.main([a.format(**paths) if "{" in a else a for a in args])
    except SystemExit as usage:  # argparse's usage errors
        status = usage.code
    err = capsys.readouterr().err
    assert status == 2 and said in err, err[:2000]
    line = next(x for x in err.splitlines() if "error:" in x)
    assert len(line) < MESSAGE_CHARS and len(err) < 3 * MESSAGE_CHARS, err[:2000]


def test_long_values_in_files_and_variables_are_shown_short(tmp_path, monkeypatch):
    from dcfkit.datasets import read_boxes
    from dcfkit.datasets.annotations import read_flags
    from dcfkit.limits import max_image_pixels
    from dcfkit.running.evaluation import tracker_name

    (tmp_path / "gt.txt").write_text("1,1,2,2\n" + "9," * 2000 + "\n")  # a longer line is refused unsplit
    (tmp_path / "att.txt").write_text("1 " * 2000)
    monkeypatch.setenv("DCFKIT_MAX_IMAGE_PIXELS", LONG)
    for call, said in [(lambda: read_boxes(tmp_path / "gt.txt"), "gt.txt, line 2: expected 4 numbers"),
                       (lambda: read_flags(tmp_path / "att.txt", ("SV", "ARC")), "att.txt, line 1: expected 2"),
                       (lambda: tracker_name({"name": "a/" + LONG}), "config 'name' 'a/qqq"),
                       (max_image_pixels, "$DCFKIT_MAX_IMAGE_PIXELS must be a number of pixels >= 1, got 'qqq")]:
        with pytest.raises(DcfkitError) as info:
            call()
        assert said in str(info.value) and len(str(info.value)) < MESSAGE_CHARS, str(info.value)[:2000]


LONG_NAME = "q" * 5000  # over any file system's 255 bytes a name: pathlib's is_file() raised OSError


@pytest.mark.parametrize("args,said", [
    (["track", LONG_NAME, "--frames", "{root}/seqA/img", "--box", "10,10,14,10"], "error: config not found: qqq"),
    (["track", "{long_base}", "--frames", "{root}/seqA/img", "--box", "10,10,14,10"],
     "long_base.yaml: base config 'qqq"),
    (["ablate", LONG_NAME, "--out", "{out}"], "error: ablation spec not found: qqq"),
    (["ablate", "{long_config_spec}", "--out", "{out}"], "long_config_spec.yaml: variants.a: config 'qqq"),
    (["ablate", "{long_root_spec}", "--out", "{out}", "--dry-run"], "long_root_spec.yaml: dataset root "),
    (["eval", "strcf", "--root", LONG_NAME, "--out", "{out}"], "error: a name too long for the file system: qqq"),
    (["eval", "strcf", "--dataset", "otb", "--root", "{root}", "--out", LONG_NAME], "error: cannot create the folder qqq"),
    (["track", "strcf", "--frames", LONG_NAME, "--box", "10,10,14,10"], "error: a name too long for the file system"),
    (["track", "strcf", "--frames", "{root}/seqA/img", "--box", "10,10,14,10", "--out", LONG_NAME],
     "error: a name too long for the file system"),
    (["report", LONG_NAME, "--dataset", "otb", "--root", "{root}"], "error: a name too long for the file system"),
])
def test_names_too_long_for_the_file_system_are_one_line_errors(args, said, otb_root, tmp_path, capsys):
    """A path argument, a config's base: or a spec's config or root of 5000 characters: each
    command ended in a traceback of pathlib's OSError (File name too long)."""
    (tmp_path / "long_base.yaml").write_text(f"base: {LONG_NAME}\n")
    (tmp_path / "long_config_spec.yaml").write_text(f"dataset: otb\nvariants: {{a: {LONG_NAME}}}\n")
    (tmp_path / "long_root_spec.yaml").write_text(f"dataset: {{name: otb, root: {LONG_NAME}}}\nvariants: {{a: strcf}}\n")
    paths = {"root": otb_root, "out": tmp_path / "out", **{name: tmp_path / f"{name}.yaml" for name in
                                                           ("long_base", "long_config_spec", "long_root_spec")}}
    status = cli.main([a.format(**paths) if "{" in a else a for a in args])
    err = capsys.readouterr().err
    assert status == 2 and said in err, err[:2000]
    assert len(err) < MESSAGE_CHARS, err[:2000]


def test_the_raw_capture_of_a_motion_jpeg_check_is_released_when_reading_it_fails(monkeypatch):
    """_JpegPackets.of opens a second capture; an error while it reads the first packet must
    not leave that capture to the garbage collector."""
    from dcfkit.datasets import video

    released = []

    class Raw:
        def __init__(self, *args):
            pass

        def isOpened(self):
            return True

        def get(self, prop):
            return -1

        def read(self):
            raise OSError("device gone")

        def release(self):
            released.append(True)

    class Decoding:
        def get(self, prop):
            return float(int.from_bytes(b"MJPG", "little"))

        def getBackendName(self):
            return "FFMPEG"

    monkeypatch.setattr(video.cv2, "VideoCapture", Raw)
    with pytest.raises(OSError, match="device gone"):
        video._JpegPackets.of("clip.avi", Decoding())
    assert released == [True]


# --------------------------------------------------------------------------- round 3: the low items


def test_a_config_name_with_a_control_character_is_a_config_error(tmp_path, otb_root, capsys):
    from dcfkit import cli

    config = tmp_path / "nul.yaml"
    config.write_text('base: kcf\nname: "a\\0b"\n')
    assert cli.main(["eval", str(config), "--dataset", "otb", "--root", str(otb_root), "--out",
                     str(tmp_path / "out"), "--no-progress"]) == 2
    err = capsys.readouterr().err
    assert err == ("dcfkit eval: error: config 'name' 'a\\x00b' must be usable as a folder name that report lists "
                   "(no / \\ : or comma, no leading dot, no leading or trailing space, no control character such as a "
                   "null byte or a line break)\n")
    from dcfkit.running.evaluation import tracker_name

    # a comma or a trailing space too: report --trackers could not name the folder (as eval's
    # folders for ablation variants are checked)
    for name in (".mine", ".locks", "..", "a\nb", "a,b", "a "):
        with pytest.raises(ConfigError, match="must be usable as a folder name"):
            tracker_name({"name": name})
    with pytest.raises(ConfigError, match="too long for a folder name"):
        tracker_name({"name": "x" * 300})


def test_a_name_cannot_add_rows_to_a_markdown_or_text_table():
    from dcfkit.analysis.tables import format_rows

    rows = [{"sequence": "car\n| fake | 1.000 |", "auc": 0.5}, {"sequence": "a|b", "auc": 0.25}]
    markdown = format_rows(rows, "markdown").splitlines()
    assert len(markdown) == 4 and markdown[2] == "| car\\n\\| fake \\| 1.000 \\| | 0.500 |"
    assert markdown[3] == "| a\\|b | 0.250 |"
    assert len(format_rows(rows, "table").splitlines()) == 4


def test_twelve_bit_data_in_sixteen_bit_pngs_is_warned_of(tmp_path):
    from dcfkit.datasets import DatasetWarning, read_frame

    rng = np.random.default_rng(0)
    twelve = tmp_path / "12" / "0001.png"
    full = tmp_path / "16" / "0001.png"
    for path, top in ((twelve, 4096), (full, 65536)):
        path.parent.mkdir()
        assert cv2.imwrite(str(path), rng.integers(0, top, (12, 16, 3)).astype(np.uint16))
    with pytest.warns(DatasetWarning, match=r"12: 16-bit frames whose values stay below 16384 keep fewer than 64"):
        image = read_frame(twelve)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        read_frame(twelve)  # once a folder
    assert image.dtype == np.uint8 and image.max() <= 15  # OpenCV's conversion, unchanged
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert np.array_equal(read_frame(full), cv2.imread(str(full)))


def test_boxes_of_absurd_size_score_without_a_numpy_warning():
    from dcfkit.analysis.metrics import score_sequence

    gt = np.array([[10, 10, 20, 20], [10, 10, -20, -20], [1e300, 10, 1e300, 20]], float)
    pred = np.array([[10, 10, 20, 20]] * 3, float)  # 1e300 away from the last box: an infinite error
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        for protocol in ("otb", "pysot", "got10k", "lasot"):
            scores = score_sequence(pred, gt, protocol=protocol)
            assert 0 <= scores["auc"] < 1 and 0 <= scores["precision"] < 1, (protocol, scores)

"""``dcfkit trax``: the TraX server driven by vot-trax's own client (``trax.client.Client``, as
vot-toolkit drives a tracker: the server's stdin and stdout), on a synthetic sequence."""
from __future__ import annotations

import contextlib
import math
import os
import re
import subprocess
import sys
import tempfile
import threading
from pathlib import Path

import cv2
import numpy as np
import pytest

import dcfkit
from dcfkit.cli import main
from dcfkit.config import load_config
from dcfkit.datasets import read_frame
from dcfkit.datasets.synthetic import make_sequence

NEEDS_TRAX = "vot-trax is not installed (pip install \"dcfkit[trax]\"; the test extra has it)"


@pytest.fixture(scope="module")
def trax():
    return pytest.importorskip("trax", reason=NEEDS_TRAX)


@pytest.fixture(scope="module")
def frames(tmp_path_factory):
    """Six frames of a synthetic sequence as PNG files (lossless), and its first box."""
    seq = make_sequence(n_frames=6, seed=3)
    folder = tmp_path_factory.mktemp("trax_frames")
    paths = []
    for i, image in enumerate(seq.frames):
        paths.append(folder / f"{i + 1:08d}.png")
        assert cv2.imwrite(str(paths[-1]), image)
    return paths, tuple(float(v) for v in seq.ground_truth[0])


def direct_run(images, box, config="strcf"):
    """Boxes and confidences of ``dcfkit.load_tracker(config)`` on ``images``: the reference."""
    tracker = dcfkit.load_tracker(config)
    tracker.init(images[0], box)
    boxes, confidence = [box], [None]
    for image in images[1:]:
        boxes.append(tracker.update(image))
        confidence.append(tracker.last_confidence)
    return np.array(boxes), confidence


SERVER = [sys.executable, "-m", "dcfkit.cli", "trax"]


def server_env() -> dict:
    """The environment of a server process: it imports the dcfkit under test, installed or not."""
    root = str(Path(dcfkit.__file__).resolve().parents[1])
    return {**os.environ, "PYTHONPATH": os.pathsep.join(filter(None, [root, os.environ.get("PYTHONPATH")]))}


@contextlib.contextmanager
def served(trax, *args):
    """``dcfkit trax ARGS`` in a process, connected to a ``trax.client.Client`` on its stdin and
    stdout; yields (client, process, log, stderr file). The client's log holds every line it
    read. A watchdog kills a server that hangs, so that the client's read returns."""
    from trax.client import Client

    with tempfile.TemporaryFile("w+") as stderr:
        process = subprocess.Popen(SERVER + list(args), stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=stderr,
                                   bufsize=0, env=server_env())
        watchdog = threading.Timer(120, process.kill)
        watchdog.start()
        log = []
        try:
            client = Client(stream=(process.stdin.fileno(), process.stdout.fileno()), log=log.append)
            yield client, process, log, stderr
        finally:
            watchdog.cancel()
            if process.poll() is None:
                process.kill()
            process.wait()
            process.stdin.close()
            process.stdout.close()


def stray_lines(log) -> list[str]:
    """What the server wrote on stdout besides TraX messages."""
    return [line for line in "".join(log).splitlines() if line.strip() and not line.startswith("@@TRAX:")]


def error_text(stderr) -> str:
    stderr.seek(0)
    return stderr.read()


def test_handshake_then_frames_give_the_boxes_of_the_tracker_run_directly(trax, frames):
    paths, box = frames
    images = [read_frame(p) for p in paths]
    expected, confidence = direct_run(images, box)
    config = dcfkit.load_config("strcf")
    with served(trax, "strcf") as (client, process, log, stderr):
        assert (client.tracker_name, client.tracker_family) == ("strcf", "dcfkit")
        assert client.tracker_description == config["description"].replace("—", "-").replace("θ", "theta")
        assert client.region_formats == ["rectangle", "polygon", "mask"] and client.image_formats == ["path", "memory"]
        assert client.channels == ["color"] and client.get("dcfkit.version") == dcfkit.__version__
        assert client.get("multiobject") is False

        objects, _ = client.initialize({"color": trax.FileImage.create(str(paths[0]))},
                                       [(trax.Rectangle.create(*box), {})], {})
        replies = [objects]
        for path in paths[1:]:
            objects, _ = client.frame({"color": trax.FileImage.create(str(path))}, {}, [])
            replies.append(objects)
        client.quit()
        assert process.wait(timeout=60) == 0
        assert error_text(stderr) == "" and stray_lines(log) == []
    assert all(len(objects) == 1 for objects in replies)
    boxes = np.array([region.bounds() for ((region, _),) in replies])
    np.testing.assert_allclose(boxes, expected, atol=1e-3)  # the protocol writes 4 decimals
    assert replies[0][0][1] == {}  # frame 1 has no response, so no confidence
    for ((_, properties),), c in zip(replies[1:], confidence[1:]):
        assert math.isclose(float(properties["confidence"]), c.score, rel_tol=1e-12)
        assert math.isclose(float(properties["peak"]), c.peak, rel_tol=1e-12)
        assert math.isclose(float(properties["apce"]), c.apce, rel_tol=1e-12)


def test_polygon_memory_images_and_a_second_initialize(trax, frames):
    """A polygon initialises with its bounding box, memory images are RGB, and a new
    ``initialize`` starts a new tracker (as if the process had been restarted)."""
    paths, (x, y, w, h) = frames
    images = [read_frame(p) for p in paths]
    diamond = [(x + w / 2, y - 1.0), (x + w + 2.0, y + h / 2), (x + w / 2, y + h), (x, y + h / 2)]
    bounding = (x, y - 1.0, w + 2.0, h + 1.0)
    second = (x + 2.0, y + 1.0, w - 4.0, h - 2.0)
    first_run, _ = direct_run(images[:3], bounding)
    second_run, _ = direct_run(images[3:], second)

    def memory(image):
        return {"color": trax.MemoryImage.create(np.ascontiguousarray(image[:, :, ::-1]))}

    with served(trax, "strcf") as (client, process, log, stderr):
        boxes = [client.initialize(memory(images[0]), [(trax.Polygon.create(diamond), {})], {})[0]]
        boxes += [client.frame(memory(image), {}, [])[0] for image in images[1:3]]
        boxes += [client.initialize(memory(images[3]), [(trax.Rectangle.create(*second), {})], {})[0]]
        boxes += [client.frame(memory(image), {}, [])[0] for image in images[4:]]
        client.quit()
        assert process.wait(timeout=60) == 0 and error_text(stderr) == ""
    got = np.array([region.bounds() for ((region, _),) in boxes])
    np.testing.assert_allclose(got, np.vstack([first_run, second_run]), atol=1e-3)


def test_an_unreadable_frame_ends_the_session_with_the_error_as_its_reason(trax, frames):
    paths, box = frames
    missing = paths[0].parent / "missing.png"
    said = f"cannot read frame 2: {missing} (file does not exist)"
    with served(trax, "strcf") as (client, process, log, stderr):
        client.initialize({"color": trax.FileImage.create(str(paths[0]))}, [(trax.Rectangle.create(*box), {})], {})
        with pytest.raises(trax.TraxException, match=f"^Server terminated the session: {re.escape(said)}$"):
            client.frame({"color": trax.FileImage.create(str(missing))}, {}, [])
        assert process.wait(timeout=60) == 2
        assert error_text(stderr) == f"dcfkit trax: error: {said}\n" and stray_lines(log) == []


def test_a_box_the_tracker_refuses_ends_the_session_naming_frame_1(trax, frames):
    paths, _ = frames
    with served(trax, "strcf") as (client, process, log, stderr):
        with pytest.raises(trax.TraxException, match="terminated the session: frame 1: init raised InputError: "
                                                     "initial box .* lies outside the 480x360 image"):
            client.initialize({"color": trax.FileImage.create(str(paths[0]))},
                              [(trax.Rectangle.create(900, 10, 20, 20), {})], {})
        assert process.wait(timeout=60) == 2
        assert "lies outside" in error_text(stderr) and "Traceback" not in error_text(stderr)


def test_a_config_error_is_said_before_any_handshake(trax, capsys):
    assert main(["trax", "strcf", "--set", "label.mu=x"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("dcfkit trax: error: ") and "label" in err


def test_without_vot_trax_the_error_names_the_extra(monkeypatch, capsys):
    monkeypatch.setitem(sys.modules, "trax", None)  # import trax raises ImportError
    monkeypatch.delitem(sys.modules, "dcfkit.integrations.trax", raising=False)
    assert main(["trax", "strcf"]) == 2
    assert capsys.readouterr().err == ('dcfkit trax: error: the TraX server needs the vot-trax package: '
                                       'pip install "dcfkit[trax]"\n')


def test_region_box_reads_rectangles_and_bounds_polygons(trax):
    from dcfkit.integrations.trax import region_box

    assert region_box(trax.Rectangle.create(1.5, 2.0, 3.0, 4.0)) == (1.5, 2.0, 3.0, 4.0)
    rotated = trax.Polygon.create([(10.0, 0.0), (20.0, 10.0), (10.0, 20.0), (0.0, 10.0)])  # a diamond
    assert region_box(rotated) == (0.0, 0.0, 20.0, 20.0)


def test_memory_images_become_bgr_or_gray_and_16_bits_are_refused(trax):
    from dcfkit.errors import InputError
    from dcfkit.integrations.trax import memory_image

    rgb = np.array([[[1, 2, 3], [4, 5, 6]]], np.uint8)
    assert memory_image(rgb, "frame 1").tolist() == [[[3, 2, 1], [6, 5, 4]]]
    assert memory_image(np.array([[[7], [8]]], np.uint8), "frame 1").tolist() == [[7, 8]]
    with pytest.raises(InputError, match="frame 4: a uint16 memory image"):
        memory_image(np.zeros((2, 2, 1), np.uint16), "frame 4")


def test_handshake_text_is_ascii(trax):
    from dcfkit.integrations.trax import ascii_text

    assert ascii_text("STRCF — θ=15, café") == "STRCF - theta=15, cafe"
    assert ascii_text("DR²Track μ, Δ, 中") == "DR2Track mu, Delta, ?"
    assert all(ascii_text(load_config(name)["description"]).isascii() and "?" not in ascii_text(
        load_config(name)["description"]) for name in ("kcf", "dsst", "strcf", "bacf", "arcf", "autotrack", "dr2track"))


def test_a_clobbered_opencv_is_warned_of_at_start_up(trax, clobbered_opencv, monkeypatch, capsys):
    import dcfkit.integrations.trax as server

    served_configs = []
    monkeypatch.setattr(server, "serve", served_configs.append)  # no session: pytest's stdin is no client
    assert main(["trax", "strcf"]) == 0
    assert [c["name"] for c in served_configs] == ["strcf"]
    err = capsys.readouterr().err
    assert err.startswith("dcfkit trax: warning: OpenCV's contrib modules are missing") and f"Repair with: {sys.executable} -m pip" in err


def test_a_client_that_ends_without_quit_ends_the_server_with_a_message(trax):
    run = subprocess.run(SERVER + ["strcf"], stdin=subprocess.DEVNULL, capture_output=True, text=True,
                         env=server_env(), timeout=120)
    assert run.returncode == 2 and run.stdout.startswith('@@TRAX:hello "dcfkit.version=')
    assert run.stderr.startswith("dcfkit trax: error: TraX: no request from the client: it closed the connection "
                                 "without sending quit") and "Traceback" not in run.stderr

"""`dcfkit track --select`: the box drawn in a window (dcfkit.cli.selection), and its errors where no
window can be shown."""
import os
import shutil
import subprocess
import sys
import time
from pathlib import Path

import cv2
import numpy as np
import pytest

from dcfkit import cli
from dcfkit.cli.selection import BoxDrawing, select_box
from dcfkit.datasets.synthetic import make_sequence
from dcfkit.errors import InputError

SEQ = make_sequence(n_frames=6, seed=4)  # 360x480 frames, the target at 148,179 36x22
ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture
def frames(tmp_path):
    folder = tmp_path / "frames"
    folder.mkdir()
    for i, frame in enumerate(SEQ.frames):
        cv2.imwrite(str(folder / f"{i}.png"), frame)
    return folder


@pytest.fixture
def agg():
    """pyplot on Agg (no windows), as on a machine without a display."""
    import matplotlib.pyplot as plt

    backend = plt.get_backend()
    plt.switch_backend("agg")
    yield plt
    plt.close("all")
    plt.switch_backend(backend)


def drawing(plt, image=SEQ.frames[0]):
    calls = []
    fig = plt.figure(figsize=(4.8, 3.6), dpi=100)
    fig.canvas.draw()
    return BoxDrawing(fig, image, done=lambda: calls.append("done")), fig, calls


def press(fig, key):
    from matplotlib.backend_bases import KeyEvent

    KeyEvent("key_press_event", fig.canvas, key)._process()


def test_a_box_dragged_and_accepted_is_in_whole_pixels(agg):
    from matplotlib.testing.widgets import click_and_drag

    box_drawing, fig, calls = drawing(agg)
    click_and_drag(box_drawing.selector, start=(148.3, 179.2), end=(184.4, 200.6))
    press(fig, "enter")
    assert calls == ["done"] and box_drawing.box == (148.0, 179.0, 36.0, 22.0)


def test_a_box_dragged_past_the_image_is_cut_at_its_edges(agg):
    from matplotlib.testing.widgets import click_and_drag

    box_drawing, fig, _ = drawing(agg)
    click_and_drag(box_drawing.selector, start=(450.0, 300.0), end=(520.0, 400.0))
    assert box_drawing.box == (450.0, 300.0, 30.0, 60.0)  # closing the window with a box accepts it


def test_escape_or_no_box_gives_none(agg):
    from matplotlib.testing.widgets import click_and_drag

    box_drawing, fig, calls = drawing(agg)
    assert box_drawing.box is None  # nothing drawn
    click_and_drag(box_drawing.selector, start=(10.0, 10.0), end=(40.0, 30.0))
    press(fig, "escape")
    assert calls == ["done"] and box_drawing.cancelled and box_drawing.box is None


def test_select_without_a_display_says_to_pass_box(frames, monkeypatch, capsys):
    if not sys.platform.startswith("linux"):
        pytest.skip("$DISPLAY decides only on Linux")
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    assert cli.main(["track", "strcf", "--frames", str(frames), "--select"]) == 2
    err = capsys.readouterr().err
    assert err == ("dcfkit track: error: --select needs a display to draw the box on, and there is none ($DISPLAY "
                   "and $WAYLAND_DISPLAY are not set): pass the first box as --box x,y,w,h instead\n")


def test_select_without_a_window_backend_says_to_pass_box(agg, monkeypatch):
    monkeypatch.setenv("DISPLAY", ":0")
    with pytest.raises(InputError, match=r"--select: matplotlib has no backend that opens windows here \(it has "
                                         r"'agg'; .*pass the first box as --box x,y,w,h instead"):
        select_box(SEQ.frames[0])


def test_box_or_select_is_required(frames, capsys):
    with pytest.raises(SystemExit) as exit_:
        cli.main(["track", "strcf", "--frames", str(frames)])
    assert exit_.value.code == 2
    assert "error: one of the arguments --box --select is required" in capsys.readouterr().err


# --------------------------------------------------------------------------- a real window


def _window_tools() -> str | None:
    """Why a real window cannot be driven here, or None."""
    missing = [tool for tool in ("Xvfb", "xdotool") if shutil.which(tool) is None]
    if missing:
        return f"{' and '.join(missing)} not installed (Debian: apt-get install xvfb xdotool)"
    try:
        import tkinter  # noqa: F401
    except ImportError:
        return "no tkinter for matplotlib's TkAgg window"
    return None


@pytest.fixture
def xvfb():
    """A virtual X display, its name."""
    why = _window_tools()
    if why:
        pytest.skip(why)
    read, write = os.pipe()
    server = subprocess.Popen(["Xvfb", "-displayfd", str(write), "-screen", "0", "1024x768x24", "-nolisten", "tcp"],
                              pass_fds=(write,), stderr=subprocess.DEVNULL)
    os.close(write)
    with os.fdopen(read) as displayfd:
        number = displayfd.readline().strip()
    yield f":{number}"
    server.terminate()
    server.wait(10)


def xdotool(display: str, *args: str) -> str:
    return subprocess.run(["xdotool", *args], env={**os.environ, "DISPLAY": display}, capture_output=True, text=True,
                          timeout=30, check=True).stdout


def test_a_box_drawn_with_the_mouse_in_a_real_window_starts_the_track(xvfb, frames, tmp_path):
    """Xvfb and xdotool: the window opens on the first frame, a drag with the mouse and Enter
    give the first box. The image fills the window's width (the toolbar below may widen it),
    so window coordinates are the image's times the window's width / 480."""
    env = {k: v for k, v in os.environ.items() if k != "MPLBACKEND"}
    env.update(DISPLAY=xvfb, PYTHONPATH=os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")]))
    out = tmp_path / "boxes.txt"
    run = subprocess.Popen([sys.executable, "-m", "dcfkit.cli", "track", "strcf", "--frames", str(frames), "--select",
                            "--out", str(out)], env=env, stderr=subprocess.PIPE, text=True)
    try:
        window = xdotool(xvfb, "search", "--sync", "--name", "^dcfkit: drag a box").split()[0]
        time.sleep(0.5)  # drawn
        width = int(xdotool(xvfb, "getwindowgeometry", window).split("Geometry: ")[1].split("x")[0])
        x0, y0, x1, y1 = (str(round(v * width / 480)) for v in (148, 179, 148 + 36, 179 + 22))
        xdotool(xvfb, "mousemove", "--window", window, x0, y0, "sleep", "0.1", "mousedown", "1", "sleep", "0.1",
                "mousemove", "--window", window, x1, y0, "sleep", "0.1", "mousemove", "--window", window, x1, y1,
                "sleep", "0.1", "mouseup", "1", "sleep", "0.2", "key", "Return")
        err = run.communicate(timeout=60)[1]
    finally:
        run.kill()
    assert run.returncode == 0, err
    said = next(line for line in err.splitlines() if line.startswith("--select: --box "))
    box = [float(v) for v in said.removeprefix("--select: --box ").split(",")]
    assert np.allclose(box, SEQ.ground_truth[0], atol=1), said
    boxes = np.loadtxt(out, delimiter=",")
    assert boxes.shape == (6, 4) and np.array_equal(boxes[0], box)

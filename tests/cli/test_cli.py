"""The command line: track (frames and video), errors, demo."""
import cv2
import numpy as np
import pytest

from dcfkit import cli
from dcfkit.datasets.synthetic import make_sequence


@pytest.fixture(scope="module")
def clip(tmp_path_factory):
    seq = make_sequence(n_frames=12, seed=4)
    folder = tmp_path_factory.mktemp("clip")
    frames = folder / "frames"
    frames.mkdir()
    for i, f in enumerate(seq.frames):
        cv2.imwrite(str(frames / f"{i:05d}.png"), f)
    return seq, frames


def box_arg(box, offset=0.0):
    return ",".join(f"{v + (offset if i < 2 else 0)}" for i, v in enumerate(box))


def test_track_frames_writes_one_box_per_frame(clip, tmp_path, capsys):
    seq, frames = clip
    out = tmp_path / "boxes.txt"
    assert cli.main(["track", "dr2track", "--frames", str(frames), "--box", box_arg(seq.ground_truth[0]),
                     "--out", str(out), "--set", "label.mu=0.3"]) == 0
    boxes = np.loadtxt(out, delimiter=",")
    assert boxes.shape == (12, 4)
    np.testing.assert_allclose(boxes[0], seq.ground_truth[0])
    centre = lambda b: b[:, :2] + b[:, 2:] / 2  # noqa: E731
    assert np.hypot(*(centre(boxes) - centre(seq.ground_truth)).T).max() < 10
    assert "12 frames" in capsys.readouterr().err
    confidence = np.loadtxt(tmp_path / "boxes.txt.confidence", delimiter=",")  # peak,apce,score beside the boxes
    assert confidence.shape == (12, 3) and np.isnan(confidence[0]).all() and (confidence[1:, 1] > 1).all()
    times = np.loadtxt(tmp_path / "boxes.txt.time")
    assert times.shape == (12,) and (times > 0).all()


def test_track_prints_boxes_and_confidence_on_stdout(clip, capsys):
    seq, frames = clip
    assert cli.main(["track", "strcf", "--frames", str(frames), "--box", box_arg(seq.ground_truth[0])]) == 0
    out = capsys.readouterr().out
    assert out.splitlines()[0].endswith(",nan,nan,nan")  # frame 1: no response
    rows = np.loadtxt(out.splitlines(), delimiter=",")  # x,y,w,h,peak,apce,score
    assert rows.shape == (12, 7)
    np.testing.assert_allclose(rows[0, :4], seq.ground_truth[0])
    assert np.isfinite(rows[1:, 4:]).all() and (rows[1:, 5] > 1).all()


def test_one_based_boxes_round_trip(clip, tmp_path):
    seq, frames = clip
    out = tmp_path / "boxes.txt"
    assert cli.main(["track", "strcf", "--frames", str(frames), "--box", box_arg(seq.ground_truth[0], 1.0),
                     "--one-based", "--out", str(out)]) == 0
    np.testing.assert_allclose(np.loadtxt(out, delimiter=",")[0], seq.ground_truth[0] + [1, 1, 0, 0])


def test_track_video_and_annotated_output(clip, tmp_path):
    seq, _ = clip
    video = tmp_path / "in.avi"
    writer = cv2.VideoWriter(str(video), cv2.VideoWriter_fourcc(*"MJPG"), 10, seq.frames[0].shape[1::-1])
    for f in seq.frames:
        writer.write(f)
    writer.release()
    out, annotated = tmp_path / "b.txt", tmp_path / "out.avi"
    assert cli.main(["track", "bacf", "--video", str(video), "--box", box_arg(seq.ground_truth[0]),
                     "--out", str(out), "--save-video", str(annotated)]) == 0
    assert np.loadtxt(out, delimiter=",").shape == (12, 4)
    cap = cv2.VideoCapture(str(annotated))
    assert int(cap.get(cv2.CAP_PROP_FRAME_COUNT)) == 12


@pytest.mark.parametrize("args,message", [
    (["--box", "1,2,3"], "--box expects x,y,w,h"),
    (["--box", "10,10,0,5"], "non-positive size"),
    (["--box", "10,10,20,20", "--set", "label.mue=1"], "unknown parameter 'mue'"),
    (["--box", "10,10,20,20", "--set", "labelmu"], "--set expects KEY=VALUE"),
    (["--box", "10,10,20,20", "--save-video", "out.gif"], "cannot write a video named 'out.gif'"),
    (["--box", "10,10,20,20", "--out", ""], "--out: an empty file name"),
])
def test_track_errors_are_one_line_messages(clip, args, message, capsys):
    _, frames = clip
    assert cli.main(["track", "dr2track", "--frames", str(frames), *args]) == 2
    err = capsys.readouterr().err
    assert message in err and "Traceback" not in err
    assert "frames," not in err  # no "dr2track: 0 frames, 0.0 fps" summary: nothing was tracked


def test_out_files_of_two_names_never_collide_and_odd_ones_are_refused_unwritten(clip, tmp_path, capsys):
    """``--out a.txt`` and ``--out a.csv`` once shared ``a.time``; a dangling link or a FIFO
    among the three files failed after the others were emptied; /dev/full gave a traceback."""
    import os

    seq, frames = clip
    run = lambda out: cli.main(["track", "kcf", "--frames", str(frames), "--box", box_arg(seq.ground_truth[0]),  # noqa: E731
                                "--out", str(out)])
    assert run(tmp_path / "a.txt") == 0 and run(tmp_path / "a.csv") == 0
    assert sorted(p.name for p in tmp_path.glob("a.*")) == ["a.csv", "a.csv.confidence", "a.csv.time", "a.txt",
                                                              "a.txt.confidence", "a.txt.time"]
    before = {p.name: p.read_bytes() for p in tmp_path.glob("a.txt*")}
    (tmp_path / "a.txt.time").unlink()
    os.symlink(tmp_path / "nowhere" / "x", tmp_path / "a.txt.time")
    capsys.readouterr()
    assert run(tmp_path / "a.txt") == 2
    assert "a.txt.time is a link to nothing" in capsys.readouterr().err
    assert (tmp_path / "a.txt").read_bytes() == before["a.txt"]  # untouched
    os.mkfifo(tmp_path / "b.txt.confidence")
    assert run(tmp_path / "b.txt") == 2 and "b.txt.confidence is not a regular file" in capsys.readouterr().err
    if os.path.exists("/dev/full"):  # the boxes may go to a device; its companions in /dev may not be made
        os.symlink("/dev/full", tmp_path / "full.txt")
        for name in ("full.txt.confidence", "full.txt.time"):
            (tmp_path / name).touch()
        assert run(tmp_path / "full.txt") == 2
        assert "--out: cannot write " in capsys.readouterr().err


def test_unreadable_frame_names_the_frame(clip, tmp_path, capsys):
    seq, frames = clip
    bad = tmp_path / "bad"
    bad.mkdir()
    for i in range(3):
        cv2.imwrite(str(bad / f"{i}.png"), seq.frames[i])
    (bad / "3.png").write_bytes(b"broken")
    out = tmp_path / "partial.txt"
    assert cli.main(["track", "strcf", "--frames", str(bad), "--box", box_arg(seq.ground_truth[0]),
                     "--out", str(out)]) == 2
    assert "cannot read frame 4" in capsys.readouterr().err
    assert np.loadtxt(out, delimiter=",").shape == (3, 4)  # the frames before the error are kept


def test_missing_inputs(tmp_path, capsys):
    assert cli.main(["track", "strcf", "--frames", str(tmp_path), "--box", "1,1,5,5"]) == 2
    assert "no images" in capsys.readouterr().err
    assert cli.main(["track", "strcf", "--video", str(tmp_path / "none.mp4"), "--box", "1,1,5,5"]) == 2
    assert "file not found" in capsys.readouterr().err


def test_demo_prints_scores(tmp_path, capsys):
    assert cli.main(["demo", "--frames", "10", "--save-video", str(tmp_path / "demo.avi")]) == 0
    out = capsys.readouterr().out
    rows = {line.split()[0]: line.split()[1:] for line in out.splitlines()
            if line.split()[:1] in (["strcf"], ["dr2track"])}
    assert set(rows) == {"strcf", "dr2track"} and (tmp_path / "demo.avi").stat().st_size > 0
    assert all(float(precision) >= 0.9 for precision, *_ in rows.values())  # 10 easy frames: both keep the target


def test_unwritable_outputs_fail_before_tracking(clip, tmp_path, capsys):
    seq, frames = clip
    blocker = tmp_path / "file"
    blocker.write_text("")
    for flag, target in (("--out", blocker / "boxes.txt"), ("--save-video", blocker / "v.avi"),
                         ("--out", tmp_path)):
        assert cli.main(["track", "strcf", "--frames", str(frames), "--box", box_arg(seq.ground_truth[0]),
                         flag, str(target)]) == 2
        err = capsys.readouterr().err
        assert err.startswith(f"dcfkit track: error: {flag}: cannot") and "Traceback" not in err
        assert "frames," not in err  # nothing was tracked
    assert cli.main(["demo", "--frames", "10", "--save-video", str(blocker / "demo.avi")]) == 2
    assert "--save-video: cannot create the folder" in capsys.readouterr().err
    assert cli.main(["demo", "--frames", "10", "--save-video", str(tmp_path / "demo.gif")]) == 2
    captured = capsys.readouterr()
    assert "the name must end in .mp4, .m4v, .mov, .mkv, .avi" in captured.err
    assert "synthetic sequence" not in captured.out  # refused before the demo ran


@pytest.mark.parametrize("frames", ["0", "1", "-5", "ten"])
def test_demo_needs_two_frames_or_more(frames, capsys):
    with pytest.raises(SystemExit):
        cli.main(["demo", "--frames", frames])
    assert "expected a whole number of frames from 2 to 250" in capsys.readouterr().err


def test_frames_are_tracked_in_natural_name_order(tmp_path):
    from dcfkit.datasets.video import frame_files

    for name in ("frame10.png", "frame2.png", "frame1.png", "notes.txt"):
        (tmp_path / name).write_bytes(b"")
    assert [p.name for p in frame_files(tmp_path)] == ["frame1.png", "frame2.png", "frame10.png"]


def test_video_writer_draws_points_in_the_colour_of_their_tracker(tmp_path):
    from dcfkit.datasets.video_writer import COLOURS, VideoWriter

    drawn = []
    writer = VideoWriter(tmp_path / "v.avi")
    writer._writer = type("Capture", (), {"write": lambda self, f: drawn.append(f), "release": lambda self: None})()
    frame = np.zeros((60, 80, 3), np.uint8)
    writer.write(frame, {"a": (1, 40, 5, 5), "b": (60, 40, 5, 5)}, points={"b": np.array([[40.0, 30.0], [np.nan, 1]])})
    (out,) = drawn
    ring = out[27:34, 37:44].reshape(-1, 3)  # a circle of radius 3 around x=40, y=30
    assert any((px == COLOURS[1]).all() for px in ring) and not any((px == COLOURS[0]).all() for px in ring)
    assert not frame.any()  # the caller's frame is not drawn on


TERMINATED_AT_FRAME_4 = """
import os, signal, sys
signal.signal(getattr(signal, sys.argv[1]), signal.SIG_DFL)  # as a terminal starts it, whoever started the suite
import dcfkit.cli.track as track_command
real = track_command.open_source

def frames(images):  # the signal arrives while frame 4 is being read, as from `timeout`
    for i, image in enumerate(images):
        if i == 3:
            os.kill(os.getpid(), getattr(signal, sys.argv[1]))
        yield image

def source(video, folder):
    opened = real(video, folder)
    opened.frames = frames(opened.frames)
    return opened

track_command.open_source = source
from dcfkit.cli import main
sys.exit(main(sys.argv[2:]))
"""


@pytest.mark.parametrize("signame", ["SIGTERM", "SIGHUP"])
def test_track_keeps_its_boxes_when_terminated(clip, tmp_path, signame):
    import signal
    import subprocess
    import sys

    seq, frames = clip
    out = tmp_path / "partial.txt"
    run = subprocess.run([sys.executable, "-c", TERMINATED_AT_FRAME_4, signame, "track", "strcf", "--frames",
                          str(frames), "--box", box_arg(seq.ground_truth[0]), "--out", str(out)],
                         capture_output=True, text=True, timeout=300)
    assert run.returncode == 128 + getattr(signal, signame), run.stderr
    assert f"dcfkit track: interrupted ({signame})" in run.stderr and "Traceback" not in run.stderr
    boxes = np.loadtxt(out, delimiter=",")
    assert boxes.shape == (3, 4)  # frames 1-3, tracked before the signal
    assert np.loadtxt(tmp_path / "partial.txt.confidence", delimiter=",").shape == (3, 3)
    assert np.loadtxt(tmp_path / "partial.txt.time").shape == (3,)
    np.testing.assert_allclose(boxes[0], seq.ground_truth[0], atol=1e-3)

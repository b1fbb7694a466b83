"""Live and streamed input of `dcfkit track`: streams, URLs, cameras and pipes read a frame at
a time, boxes out as each frame is tracked, the saved video's rate, interruptions, progress."""
import contextlib
import functools
import http.server
import io
import os
import queue
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import cv2
import numpy as np
import pytest

from dcfkit import cli
from dcfkit.datasets import video, video_writer
from dcfkit.datasets.synthetic import make_sequence
from dcfkit.datasets.video import open_source
from dcfkit.errors import InputError

SEQ = make_sequence(n_frames=20, size=(120, 160), target=(16, 20), distractor=False, seed=3)
BOX = ",".join(str(v) for v in SEQ.ground_truth[0])
ROOT = Path(__file__).resolve().parents[2]


def write_video(path: Path, fps: float = 10.0, frames=SEQ.frames) -> Path:
    writer = cv2.VideoWriter(str(path), cv2.VideoWriter_fourcc(*"MJPG"), fps, frames[0].shape[1::-1])
    for frame in frames:
        writer.write(frame)
    writer.release()
    return path


class MjpegStream:
    """An HTTP server sending SEQ's frames as a multipart JPEG stream, as IP cameras do (no
    frame count, no end but the connection's): ``hold_after`` frames, then nothing until
    :meth:`release` (or the server closes), then the rest."""

    def __init__(self, hold_after: int | None = None):
        self.released, self.sent = threading.Event(), 0
        jpegs = [cv2.imencode(".jpg", frame)[1].tobytes() for frame in SEQ.frames]
        stream = self

        class Handler(http.server.BaseHTTPRequestHandler):
            def log_message(self, *args):
                pass

            def do_GET(self):
                self.send_response(200)
                self.send_header("Content-Type", "multipart/x-mixed-replace;boundary=frame")
                self.end_headers()
                for i, jpeg in enumerate(jpegs):
                    if i == hold_after and not stream.released.wait(60):
                        return
                    self.wfile.write(b"--frame\r\nContent-Type: image/jpeg\r\nContent-Length: %d\r\n\r\n%s\r\n"
                                     % (len(jpeg), jpeg))
                    self.wfile.flush()
                    stream.sent = i + 1

        self.server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), Handler)
        self.url = f"http://127.0.0.1:{self.server.server_address[1]}/stream.mjpg"
        threading.Thread(target=self.server.serve_forever, daemon=True).start()

    def release(self):
        self.released.set()

    def close(self):
        self.release()
        self.server.shutdown()
        self.server.server_close()


@pytest.fixture
def serve_folder(tmp_path):
    """URLs of files in tmp_path, served by http.server (FFmpeg reads them as it reads any stream)."""
    handler = functools.partial(type("Quiet", (http.server.SimpleHTTPRequestHandler,),
                                     {"log_message": lambda self, *args: None}), directory=str(tmp_path))
    server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), handler)
    threading.Thread(target=server.serve_forever, daemon=True).start()
    yield lambda name: f"http://127.0.0.1:{server.server_address[1]}/{name}"
    server.shutdown()
    server.server_close()


def _ctrl_c_as_in_a_terminal() -> None:
    """SIGINT's default action in the child: a background job of a non-interactive shell (CI
    started with ``&``, nohup) ignores SIGINT, and a Python started so keeps ignoring it, where
    a command run from a terminal gets Ctrl-C as KeyboardInterrupt."""
    signal.signal(signal.SIGINT, signal.SIG_DFL)


def dcfkit_track(*args: str, **popen) -> subprocess.Popen:
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")])}
    return subprocess.Popen([sys.executable, "-m", "dcfkit.cli", "track", *args], env=env, text=True,
                            preexec_fn=_ctrl_c_as_in_a_terminal, **popen)


def lines_of(stream) -> queue.Queue:
    """The lines of ``stream`` as they come (read by a thread; None at the end)."""
    lines = queue.Queue()

    def read():
        for line in stream:
            lines.put(line)
        lines.put(None)

    threading.Thread(target=read, daemon=True).start()
    return lines


def test_boxes_are_printed_as_the_frames_of_a_stream_come(tmp_path):
    """The stream holds back after 6 of its 20 frames: the first boxes are on stdout while the
    process still waits for the rest (they were printed at the end of the run)."""
    stream = MjpegStream(hold_after=6)
    run = dcfkit_track("kcf", "--video", stream.url, f"--box={BOX}", stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    try:
        out = lines_of(run.stdout)
        first = [out.get(timeout=120) for _ in range(3)]
        assert stream.sent == 6 and run.poll() is None  # the rest of the stream is still to come
        stream.release()
        rest = iter(lambda: out.get(timeout=120), None)
        rows = np.loadtxt([*first, *rest], delimiter=",")
        err = run.stderr.read()
        assert run.wait(timeout=60) == 0, err
    finally:
        run.kill()
        stream.close()
    assert rows.shape == (20, 7)
    np.testing.assert_allclose(rows[0, :4], SEQ.ground_truth[0], atol=1e-3)
    assert "the stream ended after frame 20" in err


def test_a_url_gives_the_boxes_of_the_same_file(tmp_path, serve_folder, capsys):
    write_video(tmp_path / "clip.avi")
    assert cli.main(["track", "strcf", "--video", str(tmp_path / "clip.avi"), f"--box={BOX}"]) == 0
    from_file = capsys.readouterr().out
    assert cli.main(["track", "strcf", "--video", serve_folder("clip.avi"), f"--box={BOX}"]) == 0
    captured = capsys.readouterr()
    assert captured.out == from_file and len(from_file.splitlines()) == 20
    assert "stream ended" not in captured.err  # the file's header declares 20 frames, and 20 came


def test_a_named_pipe_gives_the_frames_of_the_file(tmp_path):
    write_video(tmp_path / "clip.avi")
    pipe = tmp_path / "pipe"
    os.mkfifo(pipe)
    writer = threading.Thread(target=lambda: pipe.write_bytes((tmp_path / "clip.avi").read_bytes()), daemon=True)
    writer.start()
    source = open_source(str(pipe))
    frames = list(source.frames)
    writer.join(10)
    assert source.live and source.total == 20 and source.fps == 10
    assert all(np.array_equal(a, b) for a, b in zip(frames, open_source(str(tmp_path / "clip.avi")).frames))
    assert len(frames) == 20


def test_a_named_pipe_nobody_writes_to_is_an_error_and_sigterm_ends_the_wait(tmp_path, monkeypatch):
    pipe = tmp_path / "pipe"
    os.mkfifo(pipe)
    monkeypatch.setattr(video, "OPEN_TIMEOUT", 0.5)
    monkeypatch.setattr(video, "WATCHDOG_MARGIN", 0.5)
    with pytest.raises(InputError, match=r"--video: .*pipe did not open within 1 s \(a named pipe opens when"):
        open_source(str(pipe))
    os.close(os.open(pipe, os.O_WRONLY))  # the open left waiting gets its writer, then the end: OpenCV is free
    run = subprocess.Popen([sys.executable, "-m", "dcfkit.cli", "track", "kcf", "--video", str(pipe),
                            "--box", "1,1,9,9"], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    waiting_for_a_writer(run.pid)
    run.send_signal(signal.SIGTERM)
    try:
        _, err = run.communicate(timeout=20)
    finally:
        run.kill()
    assert run.returncode == 128 + signal.SIGTERM and err.endswith("dcfkit track: interrupted (SIGTERM)\n")


def test_sigterm_ends_the_wait_for_a_url_that_does_not_answer():
    """A server that accepts the connection and says nothing: FFmpeg's open waits for its 30 s
    timeout, through SIGTERM, unless it runs in a thread."""
    import socket

    with socket.create_server(("127.0.0.1", 0)) as server:
        server.settimeout(60)
        url = f"http://127.0.0.1:{server.getsockname()[1]}/clip.avi"
        run = subprocess.Popen([sys.executable, "-m", "dcfkit.cli", "track", "kcf", "--video", url, "--box", "1,1,9,9"],
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        try:
            connection, _ = server.accept()  # the command is in FFmpeg's open, waiting for an answer
            with connection:
                run.send_signal(signal.SIGTERM)
                _, err = run.communicate(timeout=20)
        finally:
            run.kill()
    assert run.returncode == 128 + signal.SIGTERM and err.endswith("dcfkit track: interrupted (SIGTERM)\n"), err


def waiting_for_a_writer(pid: int, seconds: float = 60) -> None:
    """Return once a thread of process ``pid`` waits in the open of a named pipe (Linux's
    ``wait_for_partner``), where the command used to hang through SIGTERM."""
    tasks = Path(f"/proc/{pid}/task")
    if not tasks.is_dir():
        pytest.skip("needs Linux's /proc to see where the process waits")
    deadline = time.monotonic() + seconds
    while time.monotonic() < deadline:
        with contextlib.suppress(OSError):
            if any((task / "wchan").read_text() == "wait_for_partner" for task in tasks.iterdir()):
                return
        time.sleep(0.1)
    pytest.fail("the command never waited in the open of the named pipe")


def test_a_named_pipe_whose_writer_stalls_mid_clip_ends_the_run(tmp_path, monkeypatch):
    clip = write_video(tmp_path / "clip.avi").read_bytes()
    pipe = tmp_path / "pipe"
    os.mkfifo(pipe)
    release = threading.Event()

    def write_half():
        with open(pipe, "wb") as f:
            f.write(clip[:len(clip) // 2])
            f.flush()
            release.wait(30)  # the pipe stays open, nothing more comes

    threading.Thread(target=write_half, daemon=True).start()
    monkeypatch.setattr(video, "READ_TIMEOUT", 0.5)
    monkeypatch.setattr(video, "WATCHDOG_MARGIN", 0.5)
    got = []
    try:
        with pytest.raises(InputError, match=r"pipe gave no frame for 1 s after frame \d+: the stream stalled"):
            got.extend(open_source(str(pipe)).frames)
    finally:
        release.set()
    assert 0 < len(got) < 20


def test_a_stalled_stream_ends_the_run_naming_the_last_frame(monkeypatch):
    """No frame for READ_TIMEOUT: OpenCV's read gives up and reports an end, which is told
    from the end of a stream by the time it waited."""
    monkeypatch.setattr(video, "READ_TIMEOUT", 1.0)
    stream = MjpegStream(hold_after=4)
    try:
        got = []
        with pytest.raises(InputError, match=r"stream\.mjpg gave no frame for 1 s after frame [34]: the stream "
                                             r"stalled"):
            got.extend(open_source(stream.url).frames)
    finally:
        stream.close()
    assert 3 <= len(got) <= 4 and [nearest(frame) for frame in got] == list(range(len(got)))


def nearest(frame: np.ndarray) -> int:
    """The index of the frame of SEQ that ``frame`` (through JPEG) is closest to."""
    return int(np.argmin([np.abs(frame.astype(int) - f).mean() for f in SEQ.frames]))


def test_camera_numbers_and_a_camera_that_is_not_there(tmp_path, monkeypatch, capsys):
    if Path("/dev/video7").exists():
        pytest.skip("this machine has a camera 7")
    assert cli.main(["track", "strcf", "--video", "7", "--box", "1,1,5,5"]) == 2
    err = capsys.readouterr().err
    assert err == "dcfkit track: error: --video: cannot open camera 7 (there is no /dev/video7)\n"
    monkeypatch.chdir(tmp_path)
    write_video(tmp_path / "7.avi").rename(tmp_path / "7")  # a file named 7 is ./7
    assert open_source("./7").total == 20 and not open_source("./7").live
    with pytest.raises(InputError, match="cannot open camera 7"):
        open_source("7")


def test_a_url_that_does_not_open_is_named_without_its_password(capsys):
    with socket_closed() as port:
        assert cli.main(["track", "strcf", "--video", f"rtsp://user:secret@127.0.0.1:{port}/live",
                         "--box", "1,1,5,5"]) == 2
    err = capsys.readouterr().err
    assert f"error: --video: OpenCV cannot open rtsp://***@127.0.0.1:{port}/live" in err and "secret" not in err


def test_a_password_with_an_at_sign_is_hidden_whole():
    # FFmpeg (av_url_split) takes the user info up to the last '@' before the path
    assert video._name("rtsp://user:p@ss@cam.local:554/live?x=a@b") == "rtsp://***@cam.local:554/live?x=***"
    assert video._name("http://cam.local/a@b") == "http://cam.local/a@b"  # an '@' in the path is no user info


class socket_closed:
    """A local port nothing listens on."""

    def __enter__(self):
        import socket

        with socket.socket() as s:
            s.bind(("127.0.0.1", 0))
            return s.getsockname()[1]

    def __exit__(self, *exc):
        return False


@pytest.mark.parametrize("fps", [10.0, 25.0])
def test_the_saved_video_keeps_the_source_rate(fps, tmp_path):
    source = write_video(tmp_path / "in.avi", fps)
    saved = tmp_path / "out.avi"
    assert cli.main(["track", "kcf", "--video", str(source), f"--box={BOX}", "--out", str(tmp_path / "b.txt"),
                     "--save-video", str(saved)]) == 0
    cap = cv2.VideoCapture(str(saved))
    assert cap.get(cv2.CAP_PROP_FPS) == fps and cap.get(cv2.CAP_PROP_FRAME_COUNT) == 20


def test_the_saved_video_of_a_folder_has_the_default_rate(tmp_path):
    folder = tmp_path / "frames"
    folder.mkdir()
    for i, frame in enumerate(SEQ.frames[:5]):
        cv2.imwrite(str(folder / f"{i}.png"), frame)
    assert cli.main(["track", "kcf", "--frames", str(folder), f"--box={BOX}", "--out", str(tmp_path / "b.txt"),
                     "--save-video", str(tmp_path / "out.avi")]) == 0
    assert cv2.VideoCapture(str(tmp_path / "out.avi")).get(cv2.CAP_PROP_FPS) == video_writer.DEFAULT_FPS


@pytest.mark.parametrize("signame", ["SIGINT", "SIGTERM"])
def test_a_run_stopped_while_it_waits_for_frames_keeps_whole_lines(signame, tmp_path):
    """The stream stalls after 6 frames (for a minute); the signal ends the run at once (the
    frames are read in a thread) and --out holds the same whole lines in its three files."""
    stream = MjpegStream(hold_after=6)
    out = tmp_path / "boxes.txt"
    run = dcfkit_track("kcf", "--video", stream.url, f"--box={BOX}", "--out", str(out), stderr=subprocess.PIPE)
    try:
        deadline = time.monotonic() + 120
        while (not out.exists() or len(out.read_text().splitlines()) < 6) and time.monotonic() < deadline:
            time.sleep(0.05)
        run.send_signal(getattr(signal, signame))
        status = run.wait(timeout=20)
        err = run.stderr.read()
    finally:
        run.kill()
        stream.close()
    assert status == 128 + getattr(signal, signame), err
    said = f"dcfkit track: interrupted{' (SIGTERM)' if signame == 'SIGTERM' else ''}"
    assert err.splitlines()[-1] == said and "Traceback" not in err
    assert "kcf: 6 frames" in err  # the frames tracked, said before
    texts = [path.read_text() for path in (out, tmp_path / "boxes.txt.confidence", tmp_path / "boxes.txt.time")]
    assert all(text.endswith("\n") and len(text.splitlines()) == 6 for text in texts)
    assert np.loadtxt(out, delimiter=",").shape == (6, 4)


class Terminal(io.StringIO):
    def isatty(self):
        return True


@pytest.mark.parametrize("stdout_terminal", [False, True])
def test_progress_is_shown_on_a_terminal_and_stdout_holds_only_boxes(stdout_terminal, tmp_path, monkeypatch):
    path = str(write_video(tmp_path / "clip.avi"))
    stderr, stdout = Terminal(), (Terminal() if stdout_terminal else io.StringIO())
    monkeypatch.setattr(sys, "stderr", stderr)
    monkeypatch.setattr(sys, "stdout", stdout)
    assert cli.main(["track", "kcf", "--video", path, f"--box={BOX}"]) == 0
    assert "20/20" in stderr.getvalue() and "frame/s" in stderr.getvalue()
    assert np.loadtxt(stdout.getvalue().splitlines(), delimiter=",").shape == (20, 7)
    monkeypatch.setattr(sys, "stderr", Terminal())
    assert cli.main(["track", "kcf", "--video", path, f"--box={BOX}", "--no-progress"]) == 0
    assert sys.stderr.getvalue().startswith("kcf: 20 frames, ")  # no bar


def test_no_progress_bar_where_stderr_is_not_a_terminal(tmp_path, capsys):
    assert cli.main(["track", "kcf", "--video", str(write_video(tmp_path / "clip.avi")), f"--box={BOX}"]) == 0
    assert capsys.readouterr().err.startswith("kcf: 20 frames, ")


def test_frames_read_in_a_thread_come_in_order_with_the_error_in_its_place():
    def items():
        yield from (1, 2)
        raise InputError("frame 3 is damaged")

    got = []
    with pytest.raises(InputError, match="frame 3 is damaged"):
        got.extend(video._read_in_thread(items(), "clip"))
    assert got == [1, 2]


def test_a_caller_that_stops_stops_the_thread_which_closes_the_frames():
    closed = threading.Event()

    def items():
        try:
            yield from range(1000)
        finally:
            closed.set()

    frames = video._read_in_thread(items(), "clip")
    assert next(frames) == 0
    frames.close()
    assert closed.wait(10)

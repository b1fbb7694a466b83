"""The TraX server's framing of the client's stream (dcfkit.integrations.trax_stream): what
libtrax would misread ends the session in one line, within seconds and bounded memory."""
from __future__ import annotations

import os
import resource
import subprocess
import sys
from pathlib import Path

import cv2
import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

import dcfkit
from dcfkit.integrations.trax_stream import FramingError, check_message

trax = pytest.importorskip("trax", reason='vot-trax is not installed (pip install "dcfkit[trax]"; the test extra has it)')

SERVER = [sys.executable, "-m", "dcfkit.cli", "trax", "kcf"]
MEMORY_LIMIT = 3 * 2**30


def server_env() -> dict:
    """A server process's environment: it imports the dcfkit under test, on stdin and stdout."""
    root = str(Path(dcfkit.__file__).resolve().parents[1])
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(filter(None, [root, os.environ.get("PYTHONPATH")]))}
    env.pop("TRAX_SOCKET", None)
    return env


def served_stream(stream: bytes, tmp_path: Path, **variables: str) -> subprocess.CompletedProcess:
    """``dcfkit trax kcf`` reading ``stream`` then the end of its stdin, under a memory limit
    (libtrax's misreads grew to gigabytes) and a time limit, with environment ``variables``."""
    env = {**server_env(), **variables}

    def limited():
        resource.setrlimit(resource.RLIMIT_AS, (MEMORY_LIMIT, MEMORY_LIMIT))

    source = tmp_path / "stream"
    source.write_bytes(stream)
    with source.open("rb") as stdin:
        return subprocess.run(SERVER, stdin=stdin, capture_output=True, env=env, timeout=60, preexec_fn=limited)


@pytest.mark.parametrize("stream, says", [
    (b'@@TRAX:initialize "61.5,52.3,24,16"', "the stream ended inside it"),
    (b'@@TRAX:initialize 61.5,52.3,24,16', "the stream ended inside it"),
    (b'@@TRAX:initialize "61.5,52.3,24,16\n@@TRAX:frame "x"\n', "a quoted argument is not closed on its line"),
    (b'@@TRAX:initialize "1,2,3,4"\n@@TRAX:frame "file:///caf\xc3\xa9.png"\n', "byte 0xc3 at character 26"),
    (b'@@TRAX:initialize "1,2,3,4\\\n', "a backslash ends the line"),
    (b'@@TRAX:initialize "m50,50,10,10,5,73"\n', "VOT's mask files write m; TraX writes mask:"),
    (b'@@TRAX:initialize "mask:0,0,50000,50000,1"\n', "dcfkit takes masks of at most"),
    (b'@@TRAX:initialize "rect:1,2,3"\n', "has 3 numbers"),
    (b'@@TRAX:initialize "1,1,2,2"\n@@TRAX:frame "image:1;1431655766;rgb;AAA="\n', "a 1x1431655766 memory image: over"),
    (b'@@TRAX:initialize "1,1,2,2"\n@@TRAX:frame "image:2;2;rgb;AAAA"\n', "of 12 bytes whose data holds 3"),
    (b'@@TRAX:initialize "1,1,2,2"\n@@TRAX:frame\n', "a frame message with 0 images; the server reads 1"),
    # libtrax passes over a line of an unknown type and over the line after it: a frame lost, exit 0
    (b'@@TRAX:bogus\n@@TRAX:initialize "1,1,2,2"\n', "an unknown message type 'bogus'"),
    (b'@@TRAX:\n@@TRAX:quit\n', "an unknown message type ''"),
    (b'@@TRAX:dcfkitend\n@@TRAX:quit\n', "an unknown message type 'dcfkitend'"),  # the framing's own end
    (b'@@TRAX:initialize "1,1,2,2"\n@@TRAX:FRAME "image:2;2;rgb;AAAA"\n', "of 12 bytes whose data holds 3"),
])
def test_a_stream_libtrax_would_misread_ends_in_one_protocol_error(stream, says, tmp_path):
    run = served_stream(stream, tmp_path)
    err = run.stderr.decode()
    assert run.returncode == 2, err
    assert err.startswith("dcfkit trax: error: TraX: message ") and says in err, err
    assert err.count("\n") == 1 and "Traceback" not in err


@pytest.mark.parametrize("stream", [
    b'@@TRAX:initialize "1,1,2,2"\n', b"@@TRAX:initialize\n", b"@@TRAX:hello\n", b'@@TRAX:state "1,1,2,2"\n',
    b'@@TRAX:initialize "1,1,2,2" "a=b"\nnot a message\n',
])
def test_a_stream_that_ends_after_a_whole_message_ends_the_session(stream, tmp_path):
    """libtrax read the end as more of the last message's type: it grew (initialize) or spun
    (hello) for ever."""
    run = served_stream(stream, tmp_path)
    err = run.stderr.decode()
    assert run.returncode == 2 and err.startswith("dcfkit trax: error: TraX: no request from the client: it closed "
                                                  "the connection without sending quit"), err


@pytest.mark.parametrize("stream, variables, said", [
    (b'@@TRAX:initialize "1,1,2,2"\n@@TRAX:initialize "1,1,2,2"\n@@TRAX:frame "x"\n', {},
     "TraX: the client initialised 2 objects at once; the server tracks one"),  # was a traceback
    (b"@@TRAX:quit\n", {"TRAX_IN": "3"}, "TraX: $TRAX_IN is '3', not an open file descriptor"),  # was a hang
    (b"@@TRAX:quit\n", {"TRAX_OUT": "abc"}, "TraX: $TRAX_OUT is 'abc', not an open file descriptor"),
    (b"@@TRAX:quit\n", {"DCFKIT_MAX_IMAGE_PIXELS": "abc"}, "$DCFKIT_MAX_IMAGE_PIXELS must be a number"),
])
def test_what_the_client_or_the_environment_gets_wrong_is_said(stream, variables, said, tmp_path):
    run = served_stream(stream, tmp_path, **variables)
    err = run.stderr.decode()
    assert run.returncode == 2 and err.startswith(f"dcfkit trax: error: {said}") and err.count("\n") == 1, err


def test_the_messages_before_a_refused_one_are_served_however_the_stream_was_read(tmp_path):
    image = tmp_path / "frame.png"
    assert cv2.imwrite(str(image), np.random.default_rng(0).integers(0, 256, (100, 100, 3), np.uint8))
    stream = b'@@TRAX:initialize "10,10,20,20"\n@@TRAX:frame "file://%s"\n@@TRAX:bogus\n' % bytes(image)
    run = served_stream(stream, tmp_path)  # one read holds all three lines
    assert run.returncode == 2 and "message 3 from the client: an unknown message type" in run.stderr.decode()
    assert run.stdout.decode().count("@@TRAX:state ") == 1  # the frame before it was answered


def test_trax_socket_must_be_a_port_in_ascii_digits(monkeypatch):
    from dcfkit.integrations.trax_stream import ProtocolError, framed_connection

    for port in ("٣٣", "0", "70000", "x"):
        monkeypatch.setenv("TRAX_SOCKET", port)
        with pytest.raises(ProtocolError, match=r"\$TRAX_SOCKET is .*, not a port number"):
            with framed_connection():
                pass


def test_whole_messages_pass_and_the_session_ends_cleanly(tmp_path):
    run = served_stream(b"not a message: passed over\n@@TRAX:quit\n", tmp_path)
    assert run.returncode == 0 and not run.stderr, run.stderr.decode()
    assert run.stdout.decode().startswith("@@TRAX:hello ")


@pytest.mark.parametrize("line", [
    b'@@TRAX:frame "file:///a b.png" "key=va\\"lue"',
    b'@@TRAX:initialize "1,2,3,4" "name=car"',
    b'@@TRAX:initialize "mask:1,2,3,4,5,6"',
    b'@@TRAX:initialize "10.5,-3,1e2,.5,7,8"',
    b"@@TRAX:frame data:aGVsbG8= \r",
    b"@@TRAX:quit",
    b'any other "line\\',
])
def test_messages_libtrax_reads_as_written_pass(line):
    check_message(line)


@pytest.mark.parametrize("line, says", [
    (b'@@TRAX:frame"x"', "type is followed by '\"'"),
    (b'@@TRAX:frame "x"y', "closing quote is followed by 'y'"),
    (b'@@TRAX:frame "x', "not closed on its line"),
    (b"@@TRAX:frame x\\", "a backslash ends the line"),
    (b'@@TRAX:initialize "1,2,three,4"', "not numbers separated by commas"),
    (b'@@TRAX:initialize "1_0,2,3,4"', "not numbers separated by commas"),
    (b'@@TRAX:initialize "mask:0,0,-5,5,1"', "-5x5 pixels"),
])
def test_messages_libtrax_would_misread_are_refused(line, says):
    with pytest.raises(FramingError) as caught:
        check_message(line)
    assert says in str(caught.value)


def test_a_mask_initialises_on_the_box_of_its_pixels(tmp_path):
    from trax.client import Client

    image = tmp_path / "frame.png"
    assert cv2.imwrite(str(image), np.random.default_rng(0).integers(0, 256, (100, 100, 3), np.uint8))
    mask = np.zeros((60, 60), np.uint8)
    mask[30:40, 20:40] = 1
    process = subprocess.Popen(SERVER, stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL,
                               bufsize=0, env=server_env())
    try:
        client = Client(stream=(process.stdin.fileno(), process.stdout.fileno()), log=lambda line: None)
        assert "mask" in client.region_formats
        (region, _), = client.initialize({"color": trax.FileImage.create(str(image))},
                                         [(trax.Mask.create(mask, 10, 5), {})], {})[0]
        assert region.bounds() == (30.0, 35.0, 20.0, 10.0)  # pixels 30..49 x 35..44
        client.quit()
        assert process.wait(timeout=60) == 0
    finally:
        process.kill()
        process.wait()
        process.stdin.close()
        process.stdout.close()


TOKENS = [b"@@TRAX:", b"initialize", b"frame", b"quit", b" ", b'"', b"\\", b"\n", b"\r", b"1,2,3,4", b"mask:",
          b"0,0,4,4,3,2", b"m", b"1e30", b"nan", b",", b"=", b"key=", b"file:///nowhere.png", b"\xc3", b"x"]


@settings(max_examples=60, deadline=None)
@given(st.lists(st.sampled_from(TOKENS), max_size=40))
@example([b"@@TRAX:", b"initialize", b" ", b'"', b"1,2,3,4", b'"', b"\n"])  # whole, then the end: libtrax grew
@example([b"@@TRAX:", b"quit", b" ", b"x", b"\n", b"@@TRAX:", b"frame", b"\n"])
def test_fuzzed_streams_through_libtrax_end_without_hanging(monkeypatch, pieces):
    """Any stream of protocol fragments, framed then read by libtrax in this process: every
    wait returns (a request or libtrax's error) and the session ends within a bounded number
    of requests; a stream that ends inside a message or holds a byte over 127 is refused."""
    from dcfkit.integrations.trax import CHANNEL, IMAGE_FORMATS, REGION_FORMATS
    from dcfkit.integrations.trax_stream import framed_connection

    stream = b"".join(pieces)
    source_read, source_write = os.pipe()
    os.write(source_write, stream)  # small: fits in the pipe's buffer
    os.close(source_write)
    sink = os.open(os.devnull, os.O_WRONLY)
    monkeypatch.setenv("TRAX_IN", str(source_read))
    monkeypatch.setenv("TRAX_OUT", str(sink))
    monkeypatch.delenv("TRAX_SOCKET", raising=False)
    try:
        with framed_connection() as framing:
            server = trax.Server(REGION_FORMATS, IMAGE_FORMATS, [CHANNEL], tracker_name="fuzz")
            for _ in range(stream.count(b"\n") + 2):
                try:
                    if server.wait().type == trax.TraxStatus.QUIT:
                        break
                except trax.TraxException:
                    break
            else:
                pytest.fail("the session outlasted the stream's messages")
            framing._thread.join(timeout=10)
            assert not framing._thread.is_alive()
    finally:
        os.close(source_read)
        os.close(sink)
    tail = stream[stream.rfind(b"\n") + 1:]
    refused = not stream.isascii() or bool(tail.strip())
    if refused and b"@@TRAX:quit\n" not in stream:
        assert framing.error is not None

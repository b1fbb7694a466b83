"""``--scheduler ADDR``: a malformed address, a closed port, a peer that is not a Dask scheduler
(an HTTP server, one that says nothing) are each one line in bounded time and memory. Every
peer is a server on 127.0.0.1 started here."""
from __future__ import annotations

import contextlib
import re
import socket
import struct
import sys
import threading
from pathlib import Path

import numpy as np
import pytest

from dcfkit import cli
from dcfkit.datasets import Sequence
from dcfkit.errors import DcfkitError
from dcfkit.running.execute import execute
from dcfkit.running.runner import RunTask

distributed = pytest.importorskip("distributed", reason="dask.distributed not installed (pip install 'dcfkit[dask]')")
dask = pytest.importorskip("dask")

HOLD_SECONDS = 10  # a silent peer closes after this: without a bound of dcfkit's own, connecting ends anyway


@pytest.fixture
def short_timeout():
    with dask.config.set({"distributed.comm.timeouts.connect": "1s"}):
        yield


@contextlib.contextmanager
def peer(reply: bytes | None):
    """A 127.0.0.1 server that sends ``reply`` (None: nothing) to whoever connects, holds the
    connection for :data:`HOLD_SECONDS`, then closes it; yields its tcp:// address."""
    server = socket.create_server(("127.0.0.1", 0))
    stop = threading.Event()

    def serve(conn):
        with conn:
            if reply is not None:
                conn.sendall(reply)
            stop.wait(HOLD_SECONDS)

    def accept():
        with contextlib.suppress(OSError):  # the listening socket closed
            while True:
                threading.Thread(target=serve, args=(server.accept()[0],), daemon=True).start()

    threading.Thread(target=accept, daemon=True).start()
    try:
        yield f"tcp://127.0.0.1:{server.getsockname()[1]}"
    finally:
        stop.set()
        server.close()


def closed_port() -> str:
    with socket.create_server(("127.0.0.1", 0)) as s:
        return f"tcp://127.0.0.1:{s.getsockname()[1]}"


def run_on(address: str, tmp_path: Path) -> None:
    seq = Sequence("s", (tmp_path / "0001.png",), np.array([[1.0, 1.0, 4.0, 4.0]]), {}, "synthetic")
    execute([RunTask({"name": "kcf"}, seq, tmp_path / "out", "k")], lambda *_: None, executor="dask",
            scheduler=address)


@pytest.mark.parametrize("address, said", [
    ("garbage://x", r"unknown scheme 'garbage': distributed knows .*tcp"),
    ("tcp://127.0.0.1", "expected HOST:PORT"),  # nothing is sent: the form is checked first
    ("tcp://127.0.0.1:99999", "a port from 1 to 65535"),
    ("tcp://:1", "expected HOST:PORT"),
    ("tcp://a..b:1", "'a..b' is not a host name"),  # IDNA refuses an empty label: a UnicodeError
])
def test_a_malformed_address_is_refused_before_connecting(tmp_path, address, said):
    with pytest.raises(DcfkitError, match=said):
        run_on(address, tmp_path)


@pytest.mark.parametrize("scheme", ["tcp", "ws"])
def test_a_closed_port_fails_at_once(tmp_path, scheme):
    """distributed retried it for its whole connect timeout, 30 s."""
    address = closed_port().replace("tcp://", f"{scheme}://")
    with pytest.raises(DcfkitError, match=re.escape(f"dask scheduler '{address}': connection refused")):
        run_on(address, tmp_path)


@pytest.mark.parametrize("reply, said", [
    (b"HTTP/1.1 400 Bad Request\r\n\r\n", r"the peer is not a Dask scheduler \(its first message announces "
                                           + str(int.from_bytes(b"HTTP/1.1", sys.byteorder))),  # 3 EiB
    (struct.pack("Q", 16) + b"\xff" * 16, "the peer is not a Dask scheduler .*not a dask handshake"),
    (None, r"no answer within 1 s \(distributed.comm.timeouts.connect\)"),
    (struct.pack("Q", 100), r"no answer within 1 s"),  # a size, then nothing
])
def test_a_peer_that_is_not_a_dask_scheduler_is_one_line(tmp_path, short_timeout, reply, said):
    """distributed allocated the 3 EiB that "HTTP/1.1" read as a size announces, and waited
    without end for a peer that accepts and says nothing."""
    with peer(reply) as address:
        with pytest.raises(DcfkitError, match=re.escape(f"dask scheduler '{address}': ") + said):
            run_on(address, tmp_path)


def test_a_dask_scheduler_passes_the_check(short_timeout):
    from dcfkit.running.scheduler import connect  # deferred: the module is new; the tests above use execute

    with distributed.LocalCluster(n_workers=0, processes=False, protocol="tcp://", host="127.0.0.1",
                                  scheduler_port=0, dashboard_address=None) as cluster:
        with connect(cluster.scheduler_address) as client:
            assert client.scheduler.address == cluster.scheduler_address


def test_the_command_says_it_in_one_line_before_running(tmp_path, capsys):
    assert cli.main(["ablate", "missing.yaml", "--out", str(tmp_path / "out"), "--scheduler", "garbage://x"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("dcfkit ablate: error: dask scheduler 'garbage://x': unknown scheme") and err.count("\n") == 1

"""Connecting to a dask scheduler (``--scheduler ADDR``) in bounded time and memory, or one
line saying why not.

distributed's own connect reads a length prefix and allocates that many bytes before reading
them (an HTTP server's ``HTTP/1.1`` reply asks for 3 EiB), and waits without end for a peer
that accepts and says nothing. So the address's form is checked first, and a ``tcp://`` peer
is probed here: the handshake a Dask scheduler sends on connect is read with a size cap and a
deadline (``tls``, ``ws`` and ``wss`` peers are only checked to accept a connection). Each step
is bounded by distributed's connect timeout (``distributed.comm.timeouts.connect``, 30 s by
default; ``DASK_DISTRIBUTED__COMM__TIMEOUTS__CONNECT=5s`` shortens it); a refused connection
fails at once.
"""
from __future__ import annotations

import pickle
import socket
import struct
import sys
import time

from dcfkit.errors import DcfkitError, MissingDependency, clip, shown

GREETING_BYTES = 64 * 1024  # a scheduler's handshake is some 60 bytes; its size prefix must not be trusted
_PREFIX = struct.Struct("Q")  # distributed's frame lengths: native uint64
_SOCKET_SCHEMES = ("tcp", "tls", "ws", "wss")  # reached over a TCP socket (a tcp:// peer's handshake is read too)


class SchedulerError(DcfkitError):
    """A dask scheduler address is malformed, unreachable or not a Dask scheduler."""


def import_distributed():
    """The ``distributed`` package, or :class:`MissingDependency` saying how to install it."""
    try:
        import distributed  # optional: dcfkit[dask]
    except ImportError:
        raise MissingDependency("--executor dask needs dask.distributed: pip install 'dcfkit[dask]'") from None
    return distributed


def connect_timeout() -> float:
    """Seconds allowed to reach a scheduler: distributed's ``distributed.comm.timeouts.connect``."""
    import_distributed()
    import dask  # installed with distributed
    from dask.utils import parse_timedelta  # optional, as above

    return float(parse_timedelta(dask.config.get("distributed.comm.timeouts.connect"), default="seconds"))


def check_address(address: str) -> tuple[str, str, int | None]:
    """``(scheme, host, port)`` of a scheduler address (no scheme: ``tcp``); host and port are
    ``None`` for schemes without them (``inproc``). Raises :class:`SchedulerError` for a scheme
    distributed does not know or a host:port that is not one."""
    import_distributed()
    from distributed.comm import registry  # importing distributed.comm registers the built-in schemes
    from distributed.comm.addressing import parse_address, parse_host_port  # optional, as above

    def fail(why: str) -> SchedulerError:
        return SchedulerError(f"dask scheduler {shown(address)}: {why}")

    if not isinstance(address, str) or not address.isprintable() or not address.strip():
        raise fail("expected an address such as tcp://10.0.0.5:8786")
    scheme, location = parse_address(address, strict=False)
    try:
        registry.get_backend(scheme)
    except ValueError:
        raise fail(f"unknown scheme {scheme!r}: distributed knows {', '.join(sorted(registry.backends))}") from None
    if scheme == "inproc":
        return scheme, None, None
    try:
        host, port = parse_host_port(location)
    except ValueError:
        raise fail("expected HOST:PORT after the scheme, e.g. tcp://10.0.0.5:8786") from None
    if not host or any(c.isspace() for c in host) or not 0 < port < 65536:
        raise fail("expected HOST:PORT with a port from 1 to 65535, e.g. tcp://10.0.0.5:8786")
    return scheme, host, port


def connect(address: str):
    """A ``distributed.Client`` of the scheduler at ``address``, or :class:`SchedulerError`
    naming the address and what went wrong; the probe and the client's connect are each
    bounded by :func:`connect_timeout`."""
    distributed = import_distributed()
    scheme, host, port = check_address(address)
    timeout = connect_timeout()
    if scheme in _SOCKET_SCHEMES:
        probe(address, host, port, timeout, handshake=scheme == "tcp")
    try:
        return distributed.Client(address, timeout=timeout)
    except Exception as exc:  # OSError, TimeoutError, and whatever a peer's garbage raises in distributed
        raise SchedulerError(f"dask scheduler {shown(address)}: cannot connect: {type(exc).__name__}: "
                             f"{clip(str(exc))}") from None


def probe(address: str, host: str, port: int, timeout: float, handshake: bool = True) -> None:
    """Check that something listens at ``host:port`` and, with ``handshake``, that it is a Dask
    scheduler: send the handshake a client sends, read the scheduler's (at most
    :data:`GREETING_BYTES`, within ``timeout`` seconds)."""
    deadline = time.monotonic() + timeout
    where = f"dask scheduler {shown(address)}"
    try:
        with socket.create_connection((host, port), timeout=timeout) as sock:
            if handshake:
                _check_greeting(sock, where, deadline)
    except ConnectionRefusedError:
        raise SchedulerError(f"{where}: connection refused: no scheduler listens at that port") from None
    except (TimeoutError, socket.timeout):
        raise SchedulerError(f"{where}: no answer within {timeout:g} s (distributed.comm.timeouts.connect)") from None
    except OSError as exc:
        raise SchedulerError(f"{where}: cannot connect: {exc.strerror or exc}") from None
    except UnicodeError:  # the IDNA encoding of a host name: an empty or over-long label
        raise SchedulerError(f"{where}: {shown(host)} is not a host name") from None


def _check_greeting(sock: socket.socket, where: str, deadline: float) -> None:
    """Send a client's handshake and read the peer's, with a size cap; a :class:`SchedulerError`
    unless it is a Dask scheduler's."""
    sock.sendall(_hello())
    (size,) = _PREFIX.unpack(_read(sock, _PREFIX.size, deadline))
    if size > GREETING_BYTES:
        raise SchedulerError(f"{where}: the peer is not a Dask scheduler (its first message announces "
                             f"{size} bytes, a scheduler's handshake is under {GREETING_BYTES})")
    greeting = _decode(_read(sock, size, deadline))
    if not isinstance(greeting, dict) or "python" not in greeting:
        raise SchedulerError(f"{where}: the peer is not a Dask scheduler (its first message is not a dask handshake)")


def _hello() -> bytes:
    """A client's handshake as distributed frames it: a uint64 size, then the packed frames."""
    import msgpack  # installed with distributed
    from distributed.protocol.utils import pack_frames  # optional, as above

    body = pack_frames([msgpack.dumps({"compression": None, "python": list(sys.version_info[:3]),
                                       "pickle-protocol": pickle.HIGHEST_PROTOCOL})])
    return _PREFIX.pack(len(body)) + body


def _read(sock: socket.socket, size: int, deadline: float) -> bytes:
    """Exactly ``size`` bytes from ``sock`` before ``deadline``; a peer that closes early raises OSError."""
    data = bytearray()
    while len(data) < size:
        sock.settimeout(max(deadline - time.monotonic(), 1e-3))
        chunk = sock.recv(size - len(data))
        if not chunk:
            raise OSError(f"the peer closed the connection after {len(data)} of {size} bytes")
        data += chunk
    return bytes(data)


def _decode(packed: bytes):
    """The handshake dict in a scheduler's packed frames (msgpack, never pickle), or None."""
    import msgpack  # installed with distributed
    from distributed.protocol.utils import unpack_frames  # optional, as above

    try:
        frames = unpack_frames(packed)
        return msgpack.loads(frames[0]) if frames else None
    except Exception:  # any garbage: struct.error, msgpack's errors, an index past the end
        return None

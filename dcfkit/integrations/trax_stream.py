"""The client's byte stream, framed into whole TraX messages before libtrax reads it.

libtrax's parser (vot-trax 4.0) misreads a stream that ends inside a message: it feeds itself
line breaks for ever and grows until the machine runs out of memory. It also reads a byte
over 127 as the end of the stream, and a raw line break inside a quoted argument as part of
it. So the server's libtrax never sees the client directly: a thread reads the client's
stream (stdin, ``$TRAX_IN`` or the ``$TRAX_SOCKET`` port), checks each message and passes
on whole messages only, through a pipe libtrax takes as its input (``$TRAX_IN``). A stream
that breaks these rules is closed at the last whole message, and :attr:`Framing.error` says
what was wrong and where; libtrax then sees a clean end of stream.

The rules, from the protocol (a message is one line, ``@@TRAX:`` then its type, then
space-separated arguments, quoted ones with ``\\"``, ``\\\\`` and ``\\n`` escaped) and
libtrax's parser (``message.c``, ``read_message``):

- a message ends at its line break, within :data:`MAX_MESSAGE_BYTES`;
- every byte is ASCII;
- after the type comes a space or the line break; a quoted argument closes on its own line
  and is followed by a space or the line break; no backslash ends a line;
- the type is one libtrax knows (it passes over a line of another type, and the next line);
- an ``initialize`` region is numbers libtrax parses as they are written (``atof`` reads
  ``m50`` as 0), and a mask (``mask:x,y,w,h,runs...``) has at most :data:`MAX_MASK_PIXELS`
  pixels (libtrax allocates them in an ``int``-sized buffer);
- a ``frame`` carries one image, and a memory image (``image:W;H;FORMAT;BASE64``) holds at
  most ``$DCFKIT_MAX_IMAGE_PIXELS`` pixels and exactly the bytes its header says (libtrax
  compares them in an ``int``; vot-trax then allocates what the header says).

After the client's last message, :data:`END_OF_STREAM` makes the end of the stream an end.
"""
from __future__ import annotations

import contextlib
import os
import re
import socket
import threading
import time
from typing import Iterator

from dcfkit.datasets.annotations import NUMBER
from dcfkit.errors import DcfkitError, describe_error
from dcfkit.limits import IMAGE_PIXELS_VARIABLE, max_image_pixels

PREFIX = b"@@TRAX:"
MAX_MESSAGE_BYTES = 256 * 2**20  # an 8K RGB frame as a base64 memory image is 133 MB
MAX_MASK_PIXELS = 2**28
CHUNK_BYTES = 2**20
CONNECT_SECONDS = 30.0  # libtrax retries a refused $TRAX_SOCKET connection for ever
# written after the client's last message: libtrax reads the end of its input as the end of a
# message of the last type it read (after a whole "initialize" or "hello" it loops for ever,
# growing); a line of a type it does not know resets that, so the end is an end
END_OF_STREAM = PREFIX + b"dcfkitend\n"  # letters alone: another character ends the type, not the message

_TYPE = re.compile(rb"[A-Za-z0-9]*")
_UNQUOTED_SPECIAL = re.compile(rb"[ \\]")
_QUOTED_SPECIAL = re.compile(rb'["\\]')
_REGION = re.compile(rf"(?:(rect|rectangle|poly|polygon|mask|special):)?((?:{NUMBER})(?:,(?:{NUMBER}))*)",
                     re.IGNORECASE | re.ASCII)
_KEYWORD = re.compile(rb"[A-Za-z0-9_.]{1,64}=")  # libtrax's keys: 64 characters at most (else an argument)
TYPES = (b"hello", b"initialize", b"state", b"status", b"frame", b"quit")  # libtrax's, in any case
_MEMORY_IMAGE = re.compile(rb"image:([0-9]{1,10});([0-9]{1,10});(rgb|gray8|gray16);")
_BYTES_PER_PIXEL = {b"rgb": 3, b"gray8": 1, b"gray16": 2}
CHANNELS = 1  # images a frame message carries: the server asks for the color channel alone
_COUNTS = {"rect": lambda n: n == 4, "poly": lambda n: n >= 6 and n % 2 == 0, "mask": lambda n: n > 4,
           "spec": lambda n: n == 1}  # libtrax's assertions, per region type


class ProtocolError(DcfkitError):
    """The TraX connection failed (the client went away, or sent what libtrax cannot read)."""


class FramingError(ValueError):
    """A message libtrax would misread (the text says what is wrong with it)."""


def check_message(line: bytes, image_pixels: int | None = None) -> None:
    """Raise :class:`FramingError` if ``line`` (one line without its line break) is a TraX
    message that libtrax would read past its line break or not at all, or would misread
    (``image_pixels``: the most pixels of a memory image, :func:`max_image_pixels` if None)."""
    if not line.startswith(PREFIX):
        return  # not a message: libtrax passes over the line
    i = _TYPE.match(line, len(PREFIX)).end()
    if i < len(line) and line[i:i + 1] != b" ":
        raise FramingError(f"the message type is followed by {_char(line, i)}, not a space")
    kind, positional = line[len(PREFIX):i].lower(), 0
    if kind not in TYPES:  # libtrax would pass over it, and over the line after it too
        raise FramingError(f"an unknown message type {_start(line[len(PREFIX):i])}; TraX's are "
                           f"{', '.join(t.decode() for t in TYPES)}")
    while i < len(line):
        c = line[i:i + 1]
        if c in (b" ", b"\r"):
            i += 1
            continue
        start, i = i, _quoted_end(line, i + 1) if c == b'"' else _unquoted_end(line, i + 1)
        text = line[start + 1:i - 1] if c == b'"' else line[start:i]
        if _KEYWORD.match(text):
            continue  # a property
        positional += 1
        if kind == b"initialize":
            _check_region(text)
        elif kind == b"frame":
            _check_image(text, max_image_pixels() if image_pixels is None else image_pixels)
    # falling off the end of the line: the message ends at its line break
    if kind == b"frame" and positional != CHANNELS:
        raise FramingError(f"a frame message with {positional} images; the server reads {CHANNELS} (color)")


def _check_image(text: bytes, limit: int) -> None:
    """Raise :class:`FramingError` if a ``frame``'s memory image (``image:W;H;FORMAT;BASE64``)
    is larger than dcfkit takes, or its data is not of its size (libtrax compares the two in an
    ``int``, and vot-trax then allocates what the header says)."""
    if not text.startswith(b"image:"):
        return
    header = _MEMORY_IMAGE.match(text)
    if header is None:
        raise FramingError(f"the memory image {_start(text)}... is not image:WIDTH;HEIGHT;rgb|gray8|gray16;BASE64")
    width, height, fmt = int(header.group(1)), int(header.group(2)), header.group(3)
    data = len(text) - header.end()
    decoded = data // 4 * 3 - text[-2:].count(b"=") if data % 4 == 0 else -1
    size = width * height * _BYTES_PER_PIXEL[fmt]
    if not 0 < width * height <= limit:
        raise FramingError(f"a {width}x{height} memory image: over the limit of {limit:.3g} pixels "
                           f"(${IMAGE_PIXELS_VARIABLE})")
    if decoded != size:
        raise FramingError(f"a {width}x{height} {fmt.decode()} memory image of {size} bytes whose data holds "
                           f"{max(decoded, 0)}")


def _check_region(text: bytes) -> None:
    """Raise :class:`FramingError` if ``text``, an ``initialize``'s region, is one libtrax
    would misread."""
    region = _REGION.fullmatch(text.decode("ascii"))
    if region is None:
        raise FramingError(f"the region {_start(text)} is not numbers separated by commas, with an optional "
                           "rect:, poly: or mask: in front (VOT's mask files write m; TraX writes mask:)")
    kind, numbers = (region.group(1) or "").lower()[:4], region.group(2).split(",")
    if not _COUNTS.get(kind, lambda n: True)(len(numbers)):
        raise FramingError(f"the region {_start(text)} has {len(numbers)} numbers, too few or too many "
                           f"for a {kind} region (libtrax aborts on it)")
    if kind == "mask":
        x, y, width, height = (float(v) for v in numbers[:4])
        if not (0 <= width and 0 <= height and width * height <= MAX_MASK_PIXELS and abs(x) < 2**31 and abs(y) < 2**31):
            raise FramingError(f"the mask {_start(text)} is {width:g}x{height:g} pixels at ({x:g}, {y:g}); "
                               f"dcfkit takes masks of at most {MAX_MASK_PIXELS} pixels")


def _quoted_end(line: bytes, i: int) -> int:
    """Where the quoted argument whose text begins at ``i`` ends (after its closing quote)."""
    while True:
        m = _QUOTED_SPECIAL.search(line, i)
        if m is None:
            raise FramingError("a quoted argument is not closed on its line (the protocol escapes a line break as \\n)")
        i = m.end()
        if m.group() == b"\\":
            i = _escaped(line, i)
            continue
        if i < len(line) and line[i:i + 1] != b" ":
            raise FramingError(f"a closing quote is followed by {_char(line, i)}, not a space")
        return i


def _unquoted_end(line: bytes, i: int) -> int:
    """Where the unquoted argument whose second character is at ``i`` ends."""
    while True:
        m = _UNQUOTED_SPECIAL.search(line, i)
        if m is None:
            return len(line)
        if m.group() == b" ":
            return m.start()
        i = _escaped(line, m.end())


def _escaped(line: bytes, i: int) -> int:
    """Past the character a backslash escapes, at ``i``."""
    if i >= len(line):
        raise FramingError("a backslash ends the line (the protocol escapes a line break as \\n)")
    return i + 1


def _char(line: bytes, i: int) -> str:
    return repr(line[i:i + 1].decode("ascii", "replace"))


class Framing:
    """Copies whole, checked messages from ``source`` to ``sink`` (file descriptors) on a
    thread; closes ``sink`` at the end of the stream or at the first message it refuses."""

    def __init__(self, source: int, sink: int, image_pixels: int):
        self.source, self.sink, self.image_pixels = source, sink, image_pixels
        self.error: str | None = None
        self.messages = 0
        self._thread = threading.Thread(target=self._copy, name="dcfkit-trax-framing", daemon=True)

    def start(self) -> "Framing":
        self._thread.start()
        return self

    def _copy(self) -> None:
        try:
            self._copy_messages()
        except FramingError as exc:
            self.error = f"message {self.messages + 1} from the client: {exc}"
        except OSError as exc:
            self.error = f"cannot read from the client ({exc.strerror or exc})"
        except Exception as exc:  # a bug of the framing's own: said, not lost in the thread
            self.error = f"the framing of the client's stream failed: {describe_error(exc)}"
        finally:
            with contextlib.suppress(OSError):  # libtrax may have stopped reading: the pipe is closed
                _write_all(self.sink, END_OF_STREAM)
            os.close(self.sink)

    def _copy_messages(self) -> None:
        pending = bytearray()
        scanned = 0  # pending[:scanned] holds no line break
        while True:
            chunk = os.read(self.source, CHUNK_BYTES)
            if not chunk:
                break
            pending += chunk
            end = pending.rfind(b"\n", scanned) + 1
            if end:
                self._pass_on(bytes(pending[:end]))
                del pending[:end]
            scanned = len(pending)
            if len(pending) > MAX_MESSAGE_BYTES:
                raise FramingError(f"a line longer than {MAX_MESSAGE_BYTES} bytes")
        if pending.strip():
            raise FramingError(f"the stream ended inside it ({_start(pending)}...): the client closed it "
                               "without finishing the message")

    def _pass_on(self, lines: bytes) -> None:
        """Write the whole lines of ``lines`` to the sink, each once it is checked: the lines
        before a refused one pass, however the stream was cut into reads."""
        start = 0
        try:
            for line in lines.split(b"\n")[:-1]:
                self._check(line)
                start += len(line) + 1
        finally:
            _write_all(self.sink, lines[:start])

    def _check(self, line: bytes) -> None:
        if len(line) > MAX_MESSAGE_BYTES:
            raise FramingError(f"a line longer than {MAX_MESSAGE_BYTES} bytes")
        if not line.isascii():
            offset = next(i for i, b in enumerate(line) if b > 127)
            raise FramingError(f"byte 0x{line[offset]:02x} at character {offset + 1} of {_start(line)}...: "
                               "libtrax reads a byte over 127 as the end of the stream")
        check_message(line, self.image_pixels)
        if line.startswith(PREFIX):
            self.messages += 1


def _start(line: bytes) -> str:
    return repr(bytes(line[:40]).decode("ascii", "replace"))


def _write_all(fd: int, data: bytes) -> None:
    view = memoryview(data)
    while view:
        view = view[os.write(fd, view):]


@contextlib.contextmanager
def framed_connection(environ=os.environ) -> Iterator[Framing]:
    """For the block: libtrax's input is a pipe fed by a :class:`Framing` of the client's
    stream, its output the client's (``$TRAX_IN``, ``$TRAX_OUT`` and ``$TRAX_SOCKET`` set so
    that ``trax.Server`` built in the block finds them)."""
    saved = {k: environ.get(k) for k in ("TRAX_SOCKET", "TRAX_IN", "TRAX_OUT")}
    with contextlib.ExitStack() as stack:
        if saved["TRAX_SOCKET"]:
            client = stack.enter_context(_connected(saved["TRAX_SOCKET"]))
            source = output = client.fileno()
        else:
            source, output = _open_fd(saved["TRAX_IN"], "TRAX_IN", 0), _open_fd(saved["TRAX_OUT"], "TRAX_OUT", 1)
        image_pixels = max_image_pixels()  # here: a bad $DCFKIT_MAX_IMAGE_PIXELS is said now, not in the thread
        read_end, write_end = os.pipe()
        stack.callback(os.close, read_end)
        framing = Framing(source, write_end, image_pixels).start()
        environ.pop("TRAX_SOCKET", None)
        environ["TRAX_IN"], environ["TRAX_OUT"] = str(read_end), str(output)
        try:
            yield framing
        finally:
            for key, value in saved.items():
                if value is None:
                    environ.pop(key, None)
                else:
                    environ[key] = value


def _open_fd(text: str | None, variable: str, default: int) -> int:
    """The file descriptor ``$variable`` names (``default`` when unset): a number of an open one."""
    if text is None:
        return default
    try:
        if not (text.isascii() and text.isdigit()):
            raise ValueError
        os.fstat(int(text))
        return int(text)
    except (ValueError, OSError):
        raise ProtocolError(f"TraX: ${variable} is {text[:40]!r}, not an open file descriptor") from None


@contextlib.contextmanager
def _connected(port_text: str) -> Iterator[socket.socket]:
    """A TCP connection to the client listening on ``$TRAX_SOCKET`` (a port on localhost)."""
    try:
        if not (port_text.isascii() and port_text.isdigit()):
            raise ValueError
        port = int(port_text)
        if not 0 < port < 65536:
            raise ValueError
    except ValueError:
        raise ProtocolError(f"TraX: $TRAX_SOCKET is {port_text[:40]!r}, not a port number") from None
    deadline = time.monotonic() + CONNECT_SECONDS
    while True:
        try:
            client = socket.create_connection(("127.0.0.1", port), timeout=CONNECT_SECONDS)
            break
        except ConnectionRefusedError as exc:  # the client is not listening yet; anything else is an answer
            if time.monotonic() > deadline:
                raise ProtocolError(f"TraX: cannot connect to the client at $TRAX_SOCKET={port} "
                                   f"for {CONNECT_SECONDS:.0f} s ({exc.strerror or exc})") from None
            time.sleep(0.2)
        except OSError as exc:
            raise ProtocolError(f"TraX: cannot connect to the client at $TRAX_SOCKET={port} "
                                f"({exc.strerror or exc})") from None
    client.settimeout(None)
    client.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
    with client:
        yield client

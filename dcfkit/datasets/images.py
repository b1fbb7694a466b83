"""Frames read from image files, whose damage is an error naming the file (docs/hardening.md)."""
from __future__ import annotations

import functools
import io
import logging
import os
import re
import stat
import struct
import warnings
import zlib
from pathlib import Path

import numpy as np

from dcfkit.errors import DatasetError, InputWarning
from dcfkit.limits import IMAGE_PIXELS_VARIABLE, max_image_pixels

_FEW_LEVELS_WARNED: set[str] = set()
log = logging.getLogger(__name__)


def regular_file_bytes(path, name: str, limit: int, over: str) -> bytes:
    """The bytes of ``path``: a regular file (a FIFO would block, /dev/zero never end) of at
    most ``limit`` bytes, else a :class:`DatasetError` ``cannot read <name> (...)`` (``over``
    ends the one of a file too large); an OSError of the file system passes."""
    info = os.stat(path)
    if not stat.S_ISREG(info.st_mode):
        raise DatasetError(f"cannot read {name} (not a regular file)")
    if info.st_size > limit:
        raise DatasetError(f"cannot read {name} ({info.st_size:.3g} bytes{over})")
    with open(path, "rb") as file:
        return file.read(info.st_size + 1)  # a file growing meanwhile is cut: its size was checked


def _read_image_bytes(path, what: str) -> bytes:
    """The bytes of an image file: a regular file no larger than an uncompressed image of the
    pixel limit could be."""
    try:
        return regular_file_bytes(path, f"{what}: {path}", 6 * max_image_pixels() + 2**20,  # 16-bit BGR, headers
                                   f", more than an image of the limit of {max_image_pixels():.3g} pixels can take: "
                                   f"${IMAGE_PIXELS_VARIABLE}")
    except OSError as exc:
        reason = "file does not exist" if not os.path.exists(path) else exc.strerror
        raise DatasetError(f"cannot read {what}: {path} ({reason})") from None


def read_frame(path: str | os.PathLike, what: str = "frame") -> np.ndarray:
    """A BGR image; :class:`DatasetError` naming the file when it is missing, not an image, larger
    than :func:`~dcfkit.limits.max_image_pixels` (read from its header, before decoding), a
    truncated JPEG (``cv2.imread`` would return one grey below the cut, with a warning only), a
    JPEG whose data libjpeg reports corrupt (``cv2.imread`` would return it with a warning, part
    of it grey or wrong), or a TIFF whose data libtiff cannot decode (likewise). A JPEG that
    lacks just its end-of-image marker, or has zero bytes before it, common defects, is read as
    imread would. The pixels are OpenCV's, unchanged: a 16-bit image keeps its high byte, with a
    warning when that leaves fewer than 64 grey levels (12-bit data in a 16-bit PNG keeps 16).
    A clean JPEG is decoded once, by simplejpeg (:func:`_clean_jpeg`)."""
    import cv2  # deferred: listing sequences needs no OpenCV

    data = _read_image_bytes(path, what)
    _check_size(data, path, what)
    image = _clean_jpeg(data)
    if image is not None:
        return image
    if data.startswith(_TIFF_SIGNATURES):
        _check_tiff_data(data, path, what)
    image = cv2.imdecode(np.frombuffer(data, np.uint8), cv2.IMREAD_COLOR | cv2.IMREAD_ANYDEPTH)
    if image is not None and image.dtype != np.uint8:
        _warn_if_few_levels(image, path)
        image = cv2.imdecode(np.frombuffer(data, np.uint8), cv2.IMREAD_COLOR)  # OpenCV's own 8-bit conversion
    if image is None and _missing_end_marker(data):
        data += _JPEG_END
        image = cv2.imdecode(np.frombuffer(data, np.uint8), cv2.IMREAD_COLOR)
        if image is not None and (image[-8:, -8:] == 128).all():  # libjpeg's fill for missing data
            raise DatasetError(f"cannot read {what}: {path} (truncated JPEG: the image data stops "
                               f"before its end)")
    if image is None:
        raise DatasetError(f"cannot read {what}: {path} (not a readable image)")
    if data.startswith(b"\xff\xd8"):
        _check_jpeg_data(data, path, what)
    return image


def _clean_jpeg(data: bytes) -> np.ndarray | None:
    """The BGR pixels of a JPEG that libjpeg decodes without a warning, else None (the caller
    then decodes with OpenCV and checks with :func:`jpeg_damage`). simplejpeg and OpenCV both
    decode with libjpeg-turbo's defaults (the accurate integer IDCT, fancy upsampling), whose
    SIMD paths give the C code's bits: the same pixels in 3.5 ms for a 1280x720 frame, where
    OpenCV and the damage check took 6.3 ms (``benchmarks/frame_reading.py``); the strict
    decode is that check. A JPEG with EXIF data is left to OpenCV, which turns the image as its
    orientation tag says: the whole file is searched for the EXIF header, as a segment before
    it may hold the bytes of any marker (an ICC profile, a thumbnail), and a false match costs
    only the slower path."""
    if not data.startswith(b"\xff\xd8") or b"Exif\0\0" in data or not decoders_agree():
        return None
    import simplejpeg  # deferred, as OpenCV

    try:
        return simplejpeg.decode_jpeg(data, colorspace="BGR", strict=True)
    except ValueError:  # a warning, an error, or a layout it does not decode (12-bit, lossless)
        return None


@functools.cache
def decoders_agree() -> bool:
    """Whether simplejpeg decodes as OpenCV does here (once a process): a patterned image in
    each chroma subsampling, baseline and progressive, decoded by both. They agree where both
    bundle libjpeg-turbo (the pip wheels); an OpenCV built on IJG's libjpeg 7 or later, which
    upsamples chroma otherwise, would not, and then OpenCV decodes every frame."""
    try:
        return _decode_alike()
    except Exception as exc:  # an OpenCV without the JPEG encoder or its sampling options, say
        log.info("simplejpeg's decode not checked against OpenCV's (%s): OpenCV decodes every frame", exc)
        return False


def _decode_alike() -> bool:
    """:func:`decoders_agree`'s check."""
    import cv2  # deferred, as in read_frame
    import simplejpeg  # deferred, as OpenCV

    rows, cols = np.mgrid[0:37, 0:53]
    image = np.stack([(rows * 7 + cols * 3) % 256, (rows * cols) % 251, ((rows - cols) ** 2) % 241], -1).astype(np.uint8)
    for sampling in ("411", "420", "422", "440", "444"):
        for progressive in (0, 1):
            params = [cv2.IMWRITE_JPEG_SAMPLING_FACTOR, getattr(cv2, f"IMWRITE_JPEG_SAMPLING_FACTOR_{sampling}"),
                      cv2.IMWRITE_JPEG_PROGRESSIVE, progressive]
            data = cv2.imencode(".jpg", image, params)[1].tobytes()
            expected = cv2.imdecode(np.frombuffer(data, np.uint8), cv2.IMREAD_COLOR)
            try:
                same = np.array_equal(simplejpeg.decode_jpeg(data, colorspace="BGR", strict=True), expected)
            except ValueError:
                same = False
            if not same:
                log.info("simplejpeg decodes JPEGs otherwise than OpenCV here (%s sampling): OpenCV decodes "
                         "every frame", sampling)
                return False
    return True


def _warn_if_few_levels(image: np.ndarray, path) -> None:
    """Warn when a 16-bit image read as 8 bits (its high byte) keeps fewer than 64 grey levels."""
    folder = str(Path(path).parent)
    if image.dtype == np.uint16 and int(image.max()) >> 8 < 64 and folder not in _FEW_LEVELS_WARNED:
        _FEW_LEVELS_WARNED.add(folder)  # once a folder: warnings' own once-only is reset whenever a filter changes
        warnings.warn(f"{folder}: 16-bit frames whose values stay below {64 << 8} keep fewer than 64 "
                      f"grey levels read as 8 bits (12-bit data keeps 16); convert them to 8 bits, scaled to "
                      f"their range, to track them", DatasetWarning, stacklevel=3)


class DatasetWarning(InputWarning):
    """A benchmark file dcfkit reads, but maybe not as its author meant."""


def _check_size(data: bytes, path, what: str) -> None:
    """DatasetError unless the image header declares at most ``max_image_pixels()`` pixels: a
    small file can declare billions (a 876 KB PNG of 30000x30000 decodes to 2.7 GB). Pillow reads
    the header only (JPEG, PNG, BMP, TIFF, WebP and more); a file whose header it cannot read is
    refused, as its size is unknown, unless it is a PNG with an intact IHDR (:func:`_png_size`)."""
    from PIL import Image  # deferred, as OpenCV: listing sequences reads no image

    limit = max_image_pixels()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", Image.DecompressionBombWarning)  # dcfkit's limit is the one that applies
        try:
            with Image.open(io.BytesIO(data)) as header:
                width, height = header.size
        except Image.DecompressionBombError:  # Pillow's own limit, which it checks first: its size is not said
            raise DatasetError(f"cannot read {what}: {path} (its header declares more pixels than Pillow reads: "
                               f"{2 * Image.MAX_IMAGE_PIXELS:.3g}, twice PIL.Image.MAX_IMAGE_PIXELS)") from None
        except Exception:  # Pillow's plugins raise several types for a header they cannot read
            size = _png_size(data)
            if size is None:
                raise DatasetError(f"cannot read {what}: {path} (not a readable image)") from None
            width, height = size
    if width * height > limit:
        raise DatasetError(f"cannot read {what}: {path} (its header declares {width}x{height} = "
                           f"{width * height:.3g} pixels, over the limit of {limit:.3g}: ${IMAGE_PIXELS_VARIABLE})")


_PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


def _png_size(data: bytes) -> tuple[int, int] | None:
    """Width and height from a PNG's IHDR chunk, if it is intact; else None. Pillow reads the
    chunks up to the image data and refuses a bad CRC in any, while libpng (OpenCV's decoder)
    only warns about one in an ancillary chunk (tEXt, say) and decodes the image; it refuses
    damage to the critical ones (IHDR, IDAT), so ``cv2.imdecode`` returns None for those."""
    if not data.startswith(_PNG_SIGNATURE) or len(data) < 33:
        return None
    length, kind, width, height = struct.unpack(">I4sII", data[8:24])
    if length != 13 or kind != b"IHDR" or zlib.crc32(data[12:29]) != int.from_bytes(data[29:33], "big"):
        return None
    return width, height


_TIFF_SIGNATURES = (b"II*\0", b"MM\0*", b"II+\0", b"MM\0+")  # TIFF and BigTIFF, either byte order


# Pillow's names of the TIFF compressions whose data any bytes are: nothing for a decode to find
_TIFF_UNCHECKABLE = ("raw", "packbits")


_TIFF_DAMAGE = ("decoder error", "image file is truncated")  # how Pillow's decoders say the data is broken


def _check_tiff_data(data: bytes, path, what: str) -> None:
    """DatasetError if libtiff cannot decode a compressed TIFF's image data (a broken LZW or
    Deflate stream). OpenCV's decoder (its own libtiff) prints the error and returns the image,
    wrong or blank from the damage on; Pillow's raises. So Pillow decodes it too, first (the two
    images are not held at once): twice the decoding time, for compressed TIFF frames only,
    which no benchmark uses. Pillow's other failures (a layout it does not read) say nothing
    about damage and leave the file to OpenCV."""
    from PIL import Image  # deferred, as OpenCV

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # metadata warnings: the header was checked, the verdict is the decode's
        try:
            with Image.open(io.BytesIO(data)) as image:
                compression = image.info.get("compression", "unknown")
                if compression not in _TIFF_UNCHECKABLE:
                    image.load()
        except Exception as exc:  # as in _check_size, several types
            if str(exc).startswith(_TIFF_DAMAGE):
                raise DatasetError(f"cannot read {what}: {path} (corrupt TIFF data: libtiff cannot decode its "
                                   f"{compression} data)") from None


def _check_jpeg_data(data: bytes, path, what: str) -> None:
    """DatasetError if libjpeg reports the JPEG's data corrupt (:func:`jpeg_damage`)."""
    damage = jpeg_damage(data)
    if damage is not None:
        raise DatasetError(f"cannot read {what}: {path} (corrupt JPEG data: {damage})")


def jpeg_damage(data: bytes, decodable: bool = False) -> str | None:
    """What libjpeg reports wrong with a JPEG's data, or None. OpenCV's decoder only prints
    such a warning and returns the image, grey or garbled from the damage on; simplejpeg (the
    same libjpeg-turbo) raises instead. Its decode at 1/8 scale reads every coded coefficient,
    so it sees the same errors, at a third of a full decode's time. None too for a JPEG
    simplejpeg cannot decode at all (CMYK, say), which has nothing to say about corruption,
    unless it is known to be ``decodable`` (a video frame, whose first frame libjpeg decoded);
    and for one with zero padding before its end-of-image marker (:func:`_without_zero_padding`)."""
    complaint = _libjpeg_complaint(data)
    if complaint is None or (not decodable and not jpeg_decodable(data)):
        return None
    unpadded = _without_zero_padding(data, complaint)
    if unpadded is not None and _libjpeg_complaint(unpadded) is None:
        return None
    return complaint


def jpeg_decodable(data: bytes) -> bool:
    """Whether libjpeg (simplejpeg's) decodes ``data``, warnings or not."""
    return _libjpeg_complaint(data, strict=False) is None


def _libjpeg_complaint(data: bytes, strict: bool = True) -> str | None:
    """libjpeg's first warning (``strict``) or error decoding ``data`` at 1/8 scale, or None."""
    import simplejpeg  # deferred, as OpenCV

    try:
        simplejpeg.decode_jpeg(data, colorspace="BGR", min_height=1, min_width=1, strict=strict)
    except ValueError as exc:
        return str(exc)
    return None


# libjpeg's JWRN_EXTRANEOUS_DATA for the end-of-image marker (its wording since libjpeg 6)
_EXTRANEOUS_BEFORE_END = re.compile(r"\d+ extraneous bytes before marker 0xd9")


def _without_zero_padding(data: bytes, complaint: str) -> bytes | None:
    """``data`` without the zero bytes just before its end-of-image marker, if libjpeg's
    ``complaint`` is about bytes there: padding some writers add. The caller checks that the
    rest decodes cleanly, all its blocks from its own data; then the padding was never read
    and OpenCV's decode is the same with it. Other bytes there are refused: damage that makes
    the decoder reach the last block early leaves coded data there and gets the same warning
    (47% of JPEGs with 1 to 5 random bytes of coded data changed did), and damage that makes
    it run past the end reads the padding as data."""
    end = data.find(_JPEG_END, data.rfind(b"\xff\xda"))  # markers cannot occur in coded data
    if not _EXTRANEOUS_BEFORE_END.search(complaint) or end < 0:
        return None
    start = len(data[:end].rstrip(b"\0"))
    return data[:start] + data[end:] if start < end else None


_JPEG_END = b"\xff\xd9"


def _missing_end_marker(data: bytes) -> bool:
    """A JPEG whose last scan (SOS marker) has no end-of-image marker after it (markers cannot
    occur inside entropy-coded data, where 0xFF is stuffed)."""
    return data.startswith(b"\xff\xd8") and data.rfind(b"\xff\xd9") < data.rfind(b"\xff\xda")

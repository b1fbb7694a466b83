"""How fast dcfkit reads frames, and that it reads OpenCV's pixels.

    python benchmarks/frame_reading.py ../shared/data/UAV123_10fps ../shared/data/DTB70 ...

Reads every frame of every sequence under each root (its layout detected) twice, one read
after the other (each first in turn), in one thread: with :func:`dcfkit.datasets.read_frame`,
which decodes a clean JPEG once with simplejpeg, and with its OpenCV path alone
(``cv2.imdecode``, then libjpeg's damage check at 1/8 scale), as every frame was read before
0.17.0. Prints each root's frames,
ms a frame each way and the ratio, and exits with 1 if any frame's pixels differ. ``--every N``
reads every N-th frame only.
"""
import argparse
import sys
import time
from unittest import mock

import cv2
import numpy as np

from dcfkit.datasets import images, load_dataset


def timed(read, path) -> tuple[np.ndarray, float]:
    start = time.perf_counter()
    image = read(path)
    return image, time.perf_counter() - start


def opencv_path(path) -> np.ndarray:
    """read_frame as it was: every image decoded by OpenCV (and a JPEG checked by libjpeg)."""
    with mock.patch.object(images, "_clean_jpeg", lambda data: None):
        return images.read_frame(path)


def compare_root(root: str, every: int) -> tuple[int, float, float, list[str]]:
    """Frames read, seconds with read_frame and with the OpenCV path, and the frames that differ."""
    frames, fast, slow, differ = 0, 0.0, 0.0, []
    for seq in load_dataset(None, root):
        for i, path in enumerate(seq.frames[::every]):
            if i % 2:  # alternate which read comes first: the first may find the file out of the page cache
                reference, reference_seconds = timed(opencv_path, path)
                image, seconds = timed(images.read_frame, path)
            else:
                image, seconds = timed(images.read_frame, path)
                reference, reference_seconds = timed(opencv_path, path)
            frames, fast, slow = frames + 1, fast + seconds, slow + reference_seconds
            if image.shape != reference.shape or not np.array_equal(image, reference):
                differ.append(str(path))
    return frames, fast, slow, differ


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("roots", nargs="+", help="benchmark roots (UAV123_10fps, DTB70, UAVDT, OTB, ...)")
    parser.add_argument("--every", type=int, default=1, help="read every N-th frame (default: all)")
    args = parser.parse_args()
    cv2.setNumThreads(1)
    print(f"{'root':<40} {'frames':>7} {'read_frame ms':>14} {'OpenCV ms':>10} {'ratio':>6} {'differ':>7}")
    differ_all = []
    for root in args.roots:
        frames, fast, slow, differ = compare_root(root, args.every)
        differ_all += differ
        print(f"{root[-40:]:<40} {frames:>7} {1e3 * fast / max(frames, 1):>14.2f} {1e3 * slow / max(frames, 1):>10.2f} "
              f"{slow / fast if fast else float('nan'):>6.2f} {len(differ):>7}", flush=True)
    for path in differ_all[:20]:
        print(f"pixels differ: {path}")
    return 1 if differ_all else 0


if __name__ == "__main__":
    sys.exit(main())

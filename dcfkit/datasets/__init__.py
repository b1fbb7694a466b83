"""Benchmark sequences: UAV123 (+@10fps, 20L), DTB70, UAVDT, OTB, LaSOT, GOT-10k, TrackingNet
and VOT, each in its own layout.

Conventions
-----------
* Boxes in memory are ``(x, y, w, h)`` float64 in **0-based** pixel coordinates of the
  top-left corner. Most benchmark annotation files are **1-based** (OTB convention), so the
  loaders subtract 1 from x and y (w and h are unchanged); TrackingNet's and VOT's are
  0-based and read as they are. Result files written by :mod:`dcfkit.running.evaluation` add the 1
  back, so they score unchanged in the MATLAB / pysot toolkits.
* A row of NaN marks a frame where the target is out of view (absent). Such rows are kept
  (the frame still exists and the tracker still sees it); each scoring protocol of
  :mod:`dcfkit.protocols` says how they count. A test split that publishes frame 1's box
  only has NaN rows after it and ``ground_truth_withheld`` set (:func:`scored_sequences`).
* Images are read as OpenCV decodes them (:func:`read_frame`): ``(H, W, 3) uint8``, **BGR** channel order.

Only sequences present on disk are listed. :func:`load_datasets` pools the sequences of several
roots into one set. Each layout lives in its own module and registers
itself in :mod:`~dcfkit.datasets.layout` (name, aliases, loader, detection, description);
another benchmark is added with :func:`register_layout`. See ``docs/evaluation.md`` for the
layouts.
"""
from dcfkit.datasets.annotations import read_boxes
from dcfkit.datasets.base import ATTRIBUTE_NAMES, DatasetError, Sequence, scored_sequences
from dcfkit.datasets.catalog import (
    DATASETS,
    benchmark_protocol,
    canonical_name,
    detect_dataset,
    get_layout,
    layouts,
    load_dataset,
)
from dcfkit.datasets.images import DatasetWarning, read_frame
from dcfkit.datasets.layout import Evidence, Layout, register_layout, registered_layout, unregister_layout
from dcfkit.datasets.pooling import load_datasets, pair_roots

# Importing a layout module registers it; the import order is the order of the names in
# messages ("valid names: uav123, uav123_10fps, ..."), so it is not alphabetical.
# isort: off
from dcfkit.datasets.uav123_layout import uav123, uav123_10fps, uav123_20l
from dcfkit.datasets.dtb70_layout import dtb70
from dcfkit.datasets.uavdt_layout import uavdt
from dcfkit.datasets.otb_layout import otb
from dcfkit.datasets.lasot_layout import lasot, lasot_test
from dcfkit.datasets.got10k_layout import got10k_test, got10k_train, got10k_val
from dcfkit.datasets.trackingnet_layout import trackingnet, trackingnet_train
from dcfkit.datasets.vot_layout import vot, vot_area
# isort: on

__all__ = [
    "ATTRIBUTE_NAMES",
    "DATASETS",
    "DatasetError",
    "DatasetWarning",
    "Evidence",
    "Layout",
    "Sequence",
    "benchmark_protocol",
    "canonical_name",
    "detect_dataset",
    "dtb70",
    "get_layout",
    "got10k_test",
    "got10k_train",
    "got10k_val",
    "lasot",
    "lasot_test",
    "layouts",
    "load_dataset",
    "load_datasets",
    "otb",
    "pair_roots",
    "read_boxes",
    "read_frame",
    "register_layout",
    "registered_layout",
    "scored_sequences",
    "trackingnet",
    "trackingnet_train",
    "uav123",
    "uav123_10fps",
    "uav123_20l",
    "uavdt",
    "unregister_layout",
    "vot",
    "vot_area",
]

"""Where an ablation's runs go: each variant's in ``OUT/<folder>/[<experiment>/]``, the layout
of ``dcfkit eval`` (:mod:`dcfkit.running.layout`), so ``dcfkit report OUT`` and ``dcfkit
compare OUT/A OUT/B`` read them as the ablation's summary does; a variant's folder is its name
where that is a usable folder name (:func:`variant_folders`). ``dcfkit search`` keeps its runs
the same way (docs/search.md). dcfkit <= 0.10 kept both commands' runs in
``OUT/jobs/<dataset>/<key>/``, never reused now (:func:`warn_old_layout`)."""
from __future__ import annotations

import logging
from pathlib import Path
from typing import Iterable

from dcfkit.ablation.spec import AblationSpec
from dcfkit.running.layout import folder_names
from dcfkit.running.plan import Entry

log = logging.getLogger(__name__)

OLD_RUNS = "jobs"  # dcfkit <= 0.10: OUT/jobs/<dataset>/<key>/[<experiment>/] held the runs of ablate and search
CONFIGS = "configs"  # OUT/configs/<key>.json: the config behind a run key


def variant_folders(spec: AblationSpec, outputs: Iterable[str]) -> dict[str, str]:
    """Variant name -> the name of its folder in ``OUT`` (:func:`~dcfkit.running.layout.folder_names`),
    none of them ``configs``, ``jobs`` or one of the ablation's ``outputs``
    (:func:`~dcfkit.ablation.summary.output_names`)."""
    return folder_names([v.name for v in spec.variants], (CONFIGS, OLD_RUNS, *outputs))


def variant_entries(spec: AblationSpec, folders: dict[str, str]) -> list[Entry]:
    """The run plan's entries (:class:`~dcfkit.running.plan.Entry`): each variant's config under its folder."""
    return [Entry(folders[v.name], v.config) for v in spec.variants]


def warn_old_layout(out: Path, command: str, layout: str) -> None:
    """One warning when ``out`` holds runs in the layout of dcfkit <= 0.10, which ``command``
    recomputes into ``layout``."""
    old = Path(out) / OLD_RUNS
    if old.is_dir():
        log.warning("%s holds runs of dcfkit <= 0.10 in the old layout (jobs/<dataset>/<run key>/); every run key "
                    "changed in 0.11, so `%s` recomputes them into the new layout (%s); `dcfkit report %s/<dataset>` "
                    "still scores them", old, command, layout, old)

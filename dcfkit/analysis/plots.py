"""Success and precision plots (matplotlib, drawn off screen)."""
from __future__ import annotations

import io
import math
from pathlib import Path
from typing import Mapping
from typing import Sequence as Seq

from dcfkit.analysis.scoring import best_first
from dcfkit.protocols import DEFAULT, Protocol, get_protocol
from dcfkit.store.files import atomic_write

#: title, axis labels, score and legend place of the plots of each curve kind
PLOT_STYLE = {
    "precision": dict(title="Precision plots of OPE", xlabel="Location error threshold (pixels)",
                      ylabel="Precision", score="precision_score", loc="lower right"),
    "success": dict(title="Success plots of OPE", xlabel="Overlap threshold",
                    ylabel="Success rate", score="auc", loc="lower left"),
    "norm_precision": dict(title="Normalized precision plots of OPE",
                           xlabel="Normalized location error threshold",
                           ylabel="Normalized precision", score="norm_precision_score",
                           loc="lower right"),
}


def plot_title(kind: str, experiment: str = "ope") -> str:
    """``Success plots of TRE``: the title of a ``kind`` plot of ``experiment``'s runs."""
    return PLOT_STYLE[kind]["title"].removesuffix(" of OPE") + f" of {experiment.upper()}"


def plot_curves(curves: Mapping[str, Mapping], kind: str, path_stem, title: str | None = None,
                formats: Seq[str] = ("png", "svg"), protocol: str | Protocol = DEFAULT) -> list[Path]:
    """OTB-style plot of one curve per tracker; legend ``Name [score]`` sorted by score.
    ``title`` (default: :func:`plot_title` of OPE) names the experiment.

    ``curves`` maps tracker -> the dict of :func:`evaluate`'s ``curves`` (computed under
    ``protocol``, whose thresholds are the x axis and whose name ends the title); ``kind``
    is ``"precision"`` (score at 20 px), ``"success"`` (AUC) or ``"norm_precision"``.
    Writes ``path_stem.png`` and ``path_stem.svg``; returns the paths.
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg  # lazy: matplotlib is slow to import,
    from matplotlib.figure import Figure  # and only plots need it

    proto = get_protocol(protocol)
    style = PLOT_STYLE[kind]
    x = proto.thresholds[kind]
    fig = Figure(figsize=(5.2, 4.2))
    FigureCanvasAgg(fig)
    ax = fig.add_subplot(1, 1, 1)
    order = sorted(curves, key=lambda t: best_first(curves[t][style["score"]]))
    colours = [f"C{i}" for i in range(10)]
    styles = ["-", "--", "-.", ":"]
    for i, tracker in enumerate(order):
        score = curves[tracker][style["score"]]
        label = f"{tracker} [{score:.3f}]" if score is not None and math.isfinite(score) else f"{tracker} [-]"
        ax.plot(x, curves[tracker][kind], color=colours[i % 10], linestyle=styles[(i // 10) % 4],
                linewidth=2.0 if i < 10 else 1.5, label=label)
    ax.set_xlim(x[0], x[-1])
    ax.set_ylim(0, 1)
    ax.set_title(f"{title or style['title']} [protocol {proto.name}]")
    ax.set_xlabel(style["xlabel"])
    ax.set_ylabel(style["ylabel"])
    ax.grid(True, linestyle=":", linewidth=0.6)
    if order:
        ax.legend(loc=style["loc"], fontsize=8, framealpha=0.9)
    fig.tight_layout()
    paths = [Path(f"{path_stem}.{ext}") for ext in formats]
    for path in paths:
        save_figure(fig, path)
    return paths


def save_figure(fig, path: Path) -> None:
    """Render a matplotlib figure (format from the suffix) and write it atomically."""
    buffer = io.BytesIO()
    fig.savefig(buffer, format=path.suffix[1:], dpi=150)
    atomic_write(path, buffer.getvalue())

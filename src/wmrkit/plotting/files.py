"""Figure files: the formats wmrkit draws to, chosen by the file's extension, checked before the drawing; and which
items of a long sequence a figure or an animation draws."""

from __future__ import annotations

import os

import numpy as np

from ..errors import WmrkitError

#: File formats of every figure wmrkit writes, by extension.
FORMATS = (".png", ".svg", ".pdf")


class PlotError(WmrkitError, ValueError):
    """A drawing cannot be made as asked (e.g. an unknown file extension)."""


def check_figure_path(path: str | os.PathLike[str], what: str = "") -> None:
    """Refuse a figure file whose extension is not one of :data:`FORMATS` (for a name without one, matplotlib would
    write ``path + ".png"`` and report success); call it before the work that draws. `what` (e.g. ``"--plot"``)
    starts the message."""
    name = os.fspath(path)
    suffix = os.path.splitext(name)[1].lower()
    if suffix not in FORMATS:
        raise PlotError(f"{what + ' ' if what else ''}{name}: cannot draw to '{suffix or 'no extension'}' (plot files "
                        f"are {', '.join(FORMATS)})")


def spread_indices(n: int, most: int) -> np.ndarray:
    """Indices of at most `most` of `n` items, spread evenly, the first and the last included (the frames of an
    animation, the configurations drawn over each other)."""
    return np.unique(np.linspace(0, n - 1, min(n, most)).round().astype(int))

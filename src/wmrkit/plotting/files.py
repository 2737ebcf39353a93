"""Figure files: the formats wmrkit draws to, chosen by the file's extension, checked before the drawing; which
items of a long sequence a figure or an animation draws; animations written as GIFs."""

from __future__ import annotations

import numbers
import os
from collections.abc import Callable, Iterable

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


def check_count(name: str, value: object, lo: int, hi: int) -> None:
    """Raise :class:`PlotError` naming `name` unless `value` is an integer from `lo` to `hi` (an animation's
    frames, its frames a second), before the work that draws."""
    if isinstance(value, bool) or not isinstance(value, numbers.Integral) or not lo <= value <= hi:
        raise PlotError(f"{name}: expected an integer from {lo} to {hi}, got {value!r}")


def spread_indices(n: int, most: int) -> np.ndarray:
    """Indices of at most `most` of `n` items, spread evenly, the first and the last included (the frames of an
    animation, the configurations drawn over each other)."""
    return np.unique(np.linspace(0, n - 1, min(n, most)).round().astype(int))


#: Limit [MB] of an HTML animation's embedded frames: 800 frames at 80 dpi of an 8 x 4.6 in figure are at most
#: about 1 GB as base64 PNGs (1.3 MB each), and typically 30 MB.
MAX_EMBED_MB = 2048


def save_gif(fig, draw: Callable[[int], object], frames: Iterable[int], path: str | os.PathLike[str], *,
             fps: float, dpi: float | None = None, blit: bool = False) -> None:
    """Write a GIF of `fig`, calling ``draw(k)`` for each item of `frames` before rendering it (Agg, off-screen).

    Each frame is rendered once and kept as a palette image (1 byte a pixel, the palette of a fast octree), as GIF
    stores it: matplotlib's ``FuncAnimation.save`` with ``PillowWriter`` rendered every frame twice and kept it as
    RGBA until the end (800 frames of 640 x 368 px: 4 min and 840 MB on the shared 2-core machine). With `blit`,
    ``draw(k)`` returns every artist it changes or adds, as for ``FuncAnimation(..., blit=True)``: the rest of the
    figure is rendered once and each frame draws only those, in their z-order, over it (a parking plan's 200 frames:
    about 2 s instead of 20)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from PIL import Image

    if dpi is not None:
        fig.set_dpi(dpi)
    canvas = FigureCanvasAgg(fig)
    frames = list(frames)
    background = None
    if blit and frames:
        for artist in draw(frames[0]):
            artist.set_animated(True)  # left out of the background
        canvas.draw()
        background = canvas.copy_from_bbox(fig.bbox)
    images = []
    for k in frames:
        changed = draw(k)
        if background is None:
            canvas.draw()
        else:
            canvas.restore_region(background)
            for artist in sorted(changed, key=lambda a: a.get_zorder()):
                artist.set_animated(True)
                fig.draw_artist(artist)
        rgb = Image.fromarray(np.asarray(canvas.buffer_rgba())).convert("RGB")
        images.append(rgb.quantize(256, method=Image.Quantize.FASTOCTREE))
    images[0].save(os.fspath(path), save_all=True, append_images=images[1:], duration=int(1000 / fps), loop=0)


def save_html(fig, draw: Callable[[int], object], frames: Iterable[int], path: str | os.PathLike[str], *,
              fps: float, dpi: float | None = None) -> None:
    """Write an HTML page playing `fig`'s frames (matplotlib's ``HTMLWriter``, PNG frames embedded), calling
    ``draw(k)`` for each item of `frames` before rendering it once. ``FuncAnimation.to_jshtml`` rendered every
    frame twice, and past its embedding limit (rcParams, 20 MB: about 500 frames of a parking plan) dropped the rest
    of the frames with only a log message; here the limit is :data:`MAX_EMBED_MB`, beyond the frames callers allow."""
    from matplotlib.animation import HTMLWriter

    writer = HTMLWriter(fps=fps, embed_frames=True, embed_limit=MAX_EMBED_MB)
    with writer.saving(fig, os.fspath(path), dpi if dpi is not None else fig.dpi):
        for k in frames:
            draw(k)
            writer.grab_frame()

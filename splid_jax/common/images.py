"""Figures written as PNGs of at most 256 colours: line plots use a few dozen, and a palette keeps each
committed figure a fraction of its full-colour size, so that results stay within the repository's budget."""

from __future__ import annotations

import io
import os

PALETTE_COLOURS = 256


def save_figure(fig, path: str, dpi: int, **kwargs) -> None:
    """``fig.savefig(path, dpi=dpi, **kwargs)``; a ``.png`` is quantised to a palette first (median cut),
    any other format is written as matplotlib writes it."""
    if os.path.splitext(path)[1].lower() != ".png":
        fig.savefig(path, dpi=dpi, **kwargs)
        return
    from PIL import Image

    buffer = io.BytesIO()
    fig.savefig(buffer, format="png", dpi=dpi, **kwargs)
    buffer.seek(0)
    with Image.open(buffer) as image:
        paletted = image.convert("RGB").quantize(colors=PALETTE_COLOURS, method=Image.Quantize.MEDIANCUT)
    paletted.save(path, format="PNG", optimize=True)

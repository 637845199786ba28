"""Figures are written as palette PNGs that keep the plotted colours; other formats as matplotlib writes them."""

import numpy as np
from matplotlib.figure import Figure
from PIL import Image

from splid_jax.common.images import save_figure


def _figure():
    fig = Figure(figsize=(3, 2))
    ax = fig.add_subplot()
    x = np.linspace(0, 1, 50)
    ax.plot(x, x, color="#d62728", linewidth=4)
    ax.fill_between(x, 0, x**2, color="#1f77b4", alpha=0.3)  # blended shades: far more than 256 colours unquantised
    return fig


def test_a_png_is_written_with_a_palette_that_keeps_the_curve_colour(tmp_path):
    path = str(tmp_path / "f.png")
    save_figure(_figure(), path, dpi=80)
    with Image.open(path) as image:
        assert image.format == "PNG" and image.mode == "P"
        assert len(image.getcolors(maxcolors=1 << 16)) <= 256
        rgb = np.asarray(image.convert("RGB")).reshape(-1, 3).astype(int)
    nearest = np.abs(rgb - np.array([0xD6, 0x27, 0x28])).sum(axis=1).min()
    assert nearest <= 12  # the red line's colour survives quantisation


def test_other_formats_are_left_to_matplotlib(tmp_path):
    path = str(tmp_path / "f.pdf")
    save_figure(_figure(), path, dpi=80)
    with open(path, "rb") as fh:
        assert fh.read(5) == b"%PDF-"

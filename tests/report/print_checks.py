"""Checks that a figure is fit for print: a 300 dpi PNG with its SVG beside it, symbols as symbols."""

from __future__ import annotations

import html
import re
from pathlib import Path

import pytest
from PIL import Image

from poro2d.report.figure_file import DPI

#: text a figure must not show as typed text (outside mathtext)
FORBIDDEN = ("tau_peak", "+-", "sigma_", "phi_")


def svg_texts(svg: Path) -> list[str]:
    """The text of every Text artist in an SVG written by matplotlib (each one precedes its glyphs
    as a comment, its markup characters escaped)."""
    return [html.unescape(t.strip()) for t in re.findall(r"<!-- (.*?) -->", svg.read_text(), flags=re.S)]


def typed_text(text: str) -> str:
    """``text`` without its mathtext parts (``$...$``), which render as symbols."""
    return re.sub(r"(?<!\\)\$.*?(?<!\\)\$", " ", text)


def check_print_ready(png: Path) -> list[str]:
    """Assert ``png`` is a 300 dpi PNG with an SVG beside it and no symbol typed as text; return
    the SVG's texts."""
    with Image.open(png) as im:
        assert im.format == "PNG"
        assert im.info["dpi"] == pytest.approx((DPI, DPI), abs=0.01)
    svg = png.with_suffix(".svg")
    assert svg.read_text().lstrip().startswith("<?xml")
    texts = svg_texts(svg)
    assert texts, svg
    for text in texts:
        for bad in FORBIDDEN:
            assert bad not in typed_text(text), (png.name, text)
    return texts

"""The paper's Fig. 1 and Fig. 2 are written, non-empty and readable as images."""

from __future__ import annotations

import pytest

from poro2d import porosity as P
from poro2d.cli import main
from poro2d.report.conversion_figures import fig1_relations, fig2_lim_parabola, write_relation_figures

NAMES = ["fig1_relations", "fig2_lim_parabola"]
PNG_MAGIC = b"\x89PNG\r\n\x1a\n"


def _check_written(out_dir):
    for stem in NAMES:
        png = out_dir / f"{stem}.png"
        svg = out_dir / f"{stem}.svg"
        assert png.stat().st_size > 10_000
        assert png.read_bytes()[:8] == PNG_MAGIC
        text = svg.read_text()
        assert svg.stat().st_size > 10_000 and "<svg" in text


def test_write_relation_figures(tmp_path):
    paths = write_relation_figures(tmp_path / "out", mark_n_lab=0.3434)
    assert sorted(p.name for p in paths) == sorted(f"{s}.{e}" for s in NAMES for e in ("png", "svg"))
    _check_written(tmp_path / "out")
    assert not list((tmp_path / "out").glob(".*tmp"))


def test_cli_plot_relations(tmp_path, capsys):
    main(["plot", "relations", "-o", str(tmp_path), "--n-max", "0.45", "--n-min", "0.30"])
    out = capsys.readouterr().out
    assert "fig1_relations.png" in out
    _check_written(tmp_path)


def test_fig1_contents():
    fig = fig1_relations(P.PAPER_N_MAX, P.PAPER_N_MIN)
    ax = fig.axes[0]
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    for needle in ("Eq. 1", "Eq. 2", "Eq. 3", "Eq. 4", "Eq. 5", "Eqs. 6-7", "Eqs. 8-11", "Eq. 12"):
        assert any(needle in lab for lab in labels), needle
    assert ax.get_xlim() == pytest.approx((P.PAPER_N_MIN, P.PAPER_N_MAX))
    assert ax.get_ylim()[0] < 0  # negative values are shown, not clipped away


def test_fig2_marks_the_three_construction_points():
    fig = fig2_lim_parabola()
    ax = fig.axes[0]
    pts = [ln for ln in ax.get_lines() if ln.get_label() == "construction points of Eq. 12"]
    assert len(pts) == 1
    xs, ys = pts[0].get_data()
    assert list(xs) == pytest.approx([0.0, P.FCC_3D, P.SIMPLE_CUBIC_3D])
    assert list(ys) == pytest.approx([0.0, P.HEXAGONAL_2D, P.SQUARE_2D])


def test_figure_input_errors():
    from poro2d.errors import InputError

    with pytest.raises(InputError):
        fig1_relations(0.3, 0.4)
    with pytest.raises(InputError):
        fig2_lim_parabola(0.45, 0.30, mark_n_lab=0.9)

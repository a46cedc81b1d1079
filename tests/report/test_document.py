"""The report document model: Markdown and self-contained HTML."""

import base64

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from poro2d.report.document import to_html, to_markdown, write_report  # noqa: E402


def _png(path):
    fig, ax = plt.subplots(figsize=(2, 1))
    ax.plot([0, 1], [0, 1])
    fig.savefig(path)
    plt.close(fig)
    return path


def test_markdown_and_html_hold_every_block(tmp_path):
    img = _png(tmp_path / "f.png")
    blocks = [
        ("h1", "Title"),
        ("p", "a <b> & c"),
        ("ul", ["one", "two"]),
        ("table", ["q", "poro2d", "paper"], [["n2D", 0.19, 0.15], ["count", 2440, None]]),
        ("img", img, "Fig. 1"),
        ("note", "careful"),
        ("code", "x = 1"),
    ]
    md = to_markdown(blocks, tmp_path)
    assert "# Title" in md and "| n2D | 0.19 | 0.15 |" in md and "| count | 2440 | - |" in md
    assert "![Fig. 1](f.png)" in md
    html = to_html(blocks, "T")
    assert "a &lt;b&gt; &amp; c" in html  # escaped
    b64 = base64.b64encode(img.read_bytes()).decode()
    assert f"data:image/png;base64,{b64}" in html  # embedded, no external file needed
    assert "<td>0.19</td>" in html and "<li>two</li>" in html


def test_missing_figure_is_said_not_hidden(tmp_path):
    html = to_html([("img", tmp_path / "nope.png", "cap")], "T")
    assert "figure missing: nope.png" in html


def test_write_report_writes_both(tmp_path):
    files = write_report([("h1", "x")], tmp_path, "report", "T")
    assert [f.name for f in files] == ["report.md", "report.html"]
    assert all(f.stat().st_size > 0 for f in files)


def test_save_figure_writes_each_format_atomically_and_closes(tmp_path):
    from poro2d.report.figure_file import save_figure

    fig, ax = plt.subplots(figsize=(2, 1))
    ax.plot([0, 1], [0, 1])
    png, svg = tmp_path / "sub" / "f.png", tmp_path / "sub" / "f.svg"
    assert save_figure(fig, png, svg) == png
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and "<svg" in svg.read_text()
    assert sorted(p.name for p in png.parent.iterdir()) == ["f.png", "f.svg"]  # no temporaries left
    assert not plt.fignum_exists(fig.number)


def test_figures_are_drawn_and_saved_only_in_report():
    """Every figure is drawn in report/ and written by report/figure_file.py (one dpi, atomic)."""
    from pathlib import Path

    package = Path(__file__).resolve().parents[2] / "src" / "poro2d"
    drawing = [p for p in package.rglob("*.py") if "matplotlib" in p.read_text()]
    assert drawing and all(p.parent.name == "report" for p in drawing), drawing
    saving = [p.name for p in package.rglob("*.py") if ".savefig(" in p.read_text()]
    assert saving == ["figure_file.py"]

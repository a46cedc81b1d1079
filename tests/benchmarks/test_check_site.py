"""The browser check of the built site (benchmarks/check_site.py), on small sites made here, each
with the faults it must find: a link to a missing page, a missing anchor, an image that does not
render, a notebook page without outputs."""

import base64
import os
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "benchmarks"))

import check_site  # noqa: E402

#: a 1 x 1 PNG (one grey pixel): an image a browser renders
PIXEL = base64.b64decode(
    "iVBORw0KGgoAAAANSUhEUgAAAAEAAAABCAAAAAA6fptVAAAACklEQVR4nGNoAAAAggCBd81ytgAAAABJRU5ErkJggg=="
)


def page(body: str) -> str:
    return f"<!doctype html><html><head><title>t</title></head><body>{body}</body></html>"


STDERR = (
    '<div class="jp-OutputArea-output" data-mime-type="application/vnd.jupyter.stderr"><pre>{}</pre></div>'
)


def notebook(outputs: int, stderr: str) -> str:
    """A page as mkdocs-jupyter renders a notebook: three code cells, ``outputs`` of the first two
    with an output, the third with ``stderr`` written to the standard error."""
    cells = []
    for k in range(2):
        output = '<div class="jp-OutputArea-output"><pre>42</pre></div>' if k < outputs else ""
        cells.append(f'<div class="jp-Cell jp-CodeCell"><pre>x = {k}</pre>{output}</div>')
    cells.append(f'<div class="jp-Cell jp-CodeCell"><pre>run()</pre>{STDERR.format(stderr)}</div>')
    return page("".join(cells))


def make_site(root: Path, *, faults: bool) -> Path:
    """A site of a home page, a guide with a heading and a figure, and a notebook; with ``faults``
    each of the four faults the check looks for."""
    site = root / "site"
    for folder in ("guide", "notebooks/demo", "img"):
        (site / folder).mkdir(parents=True)
    (site / "img" / "dot.png").write_bytes(PIXEL)
    links = (
        '<a href="guide/">guide</a> <a href="guide/#results">results</a> <a href="https://example.org/">x</a>'
    )
    if faults:
        links += ' <a href="missing/">gone</a> <a href="guide/#no-such-part">no anchor</a>'
    (site / "index.html").write_text(page(links))
    figure = '<h2 id="results">Results</h2><img src="../img/dot.png">'
    if faults:
        figure += '<img src="../img/absent.png">'
    (site / "guide" / "index.html").write_text(page(figure + '<a href="../">home</a>'))
    traceback = "Traceback (most recent call last):\n  File ...\nValueError: bad"
    stderr = traceback if faults else "WARNING - Worker process still alive"  # a log line is no fault
    (site / "notebooks" / "demo" / "index.html").write_text(
        notebook(outputs=0 if faults else 1, stderr=stderr)
    )
    (site / "404.html").write_text(page("not found"))
    return site


def test_pages_are_the_sites_html_files_but_404_and_search(tmp_path):
    site = make_site(tmp_path, faults=False)
    (site / "search").mkdir()
    (site / "search" / "index.html").write_text(page(""))
    assert check_site.site_pages(site) == ["guide/", "", "notebooks/demo/"]


def test_a_page_report_from_what_the_browser_found(tmp_path):
    """The findings of one page as the runner page hands them over, judged without a browser."""
    site = make_site(tmp_path, faults=True)
    with check_site.served(site, []) as base:
        ids = {"/guide/": {"results"}, "/": set()}
        found = {
            "url": f"{base}/",
            "links": [f"{base}/guide/", f"{base}/guide/#results", f"{base}/missing/",
                      f"{base}/guide/#no-such-part", f"{base}/img/dot.png", "https://example.org/"],
            "images": [{"src": "img/dot.png", "width": 1}, {"src": "img/absent.png", "width": 0}],
            "notebook": None,
        }  # fmt: skip
        report = check_site.page_report(found, base, ids, site)
    assert report.links == 6 and report.images == 2
    assert report.problems == [
        "broken link /missing/",
        "missing anchor /guide/#no-such-part",
        "image not rendered img/absent.png",
    ]


def test_a_notebook_page_needs_outputs(tmp_path):
    site = make_site(tmp_path, faults=False)
    cells = {"code_cells": 2, "with_output": 0, "stderr": 0, "errors": 0}
    found = {"url": "http://127.0.0.1:1/notebooks/demo/", "links": [], "images": [], "notebook": cells}
    report = check_site.page_report(found, "http://127.0.0.1:1", {}, site)
    assert report.outputs == "0/2" and report.problems == ["no cell output: the notebook was not executed"]


def chromium() -> str:
    """Chromium; CI (CI=true) must have it, elsewhere the browser tests are skipped without it."""
    exe = check_site.chromium()
    if exe is None:
        if os.environ.get("CI", "").lower() == "true":
            pytest.fail("CI=true but Chromium is not installed (apt-get install -y chromium)")
        pytest.skip("Chromium is not installed")
    return exe


@pytest.mark.scenario  # a headless browser renders the pages
def test_a_sound_site_passes_in_the_browser(tmp_path, capsys):
    chromium()
    site = make_site(tmp_path, faults=False)
    assert check_site.main([str(site)]) == 0
    out = capsys.readouterr().out
    assert "3 pages" in out and "all ok" in out
    rows = {line.split()[0]: line for line in out.splitlines()[1:4]}
    assert rows["/guide/"].split()[1:4] == ["1", "1", "ok"]  # one link, one image, rendered
    assert rows["/notebooks/demo/"].split()[3:] == ["2/3", "(1", "stderr)", "ok"]


@pytest.mark.scenario
def test_each_fault_is_found_in_the_browser(tmp_path, capsys):
    chromium()
    site = make_site(tmp_path, faults=True)
    assert check_site.main([str(site)]) == 1
    reports = {r.path: r.problems for r in check_site.check_site(site)}
    assert reports == {
        "/": ["broken link /missing/", "missing anchor /guide/#no-such-part"],
        "/guide/": ["image not rendered ../img/absent.png"],
        "/notebooks/demo/": ["1 error output(s): a traceback"],
    }


def test_no_site_is_refused(tmp_path, capsys):
    assert check_site.main([str(tmp_path / "nowhere")]) == 2
    assert "no built site" in capsys.readouterr().err

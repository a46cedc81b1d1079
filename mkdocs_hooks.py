"""MkDocs hooks: the repository's own top-level pages in the site, with their links resolved.

README.md, ARCHITECTURE.md and benchmarks/README.md live outside docs/ and link to docs/ pages
by repository paths (``docs/api.md``); the guides link to ``../benchmarks/README.md``. The site
takes each file as it is (no copy to keep in step) and maps those paths onto site pages, so
that every link is still checked by ``mkdocs build --strict``.
"""

from __future__ import annotations

import json
import os
import posixpath
import re
import tempfile
from pathlib import Path

from mkdocs.structure.files import File

ROOT = Path(__file__).resolve().parent

#: site page -> repository file it is made from
PAGES = {
    "index.md": "README.md",
    "architecture.md": "ARCHITECTURE.md",
    "benchmarks.md": "benchmarks/README.md",
}

#: repository paths, as the pages outside docs/ and the guides write them -> site pages
LINKS = {
    "docs/": "",
    "../benchmarks/README.md": "benchmarks.md",
    "benchmarks/README.md": "benchmarks.md",
    "ARCHITECTURE.md": "architecture.md",
}

#: seconds a notebook cell may run before the build fails (the longest measured: docs/building-docs.md)
CELL_TIMEOUT = 600

_LINK = re.compile(r"\]\((" + "|".join(re.escape(k) for k in LINKS) + r")")


def rewrite_links(markdown: str) -> str:
    """``markdown`` with the repository paths of :data:`LINKS` replaced by their site pages."""
    return _LINK.sub(lambda m: "](" + LINKS[m.group(1)], markdown)


def on_config(config):
    """A timeout on every notebook cell: mkdocs-jupyter has no option for it, but its nbconvert
    reads the user's Jupyter config, where ``NotebookClient.timeout`` reaches the cells' executor."""
    folder = Path(tempfile.mkdtemp(prefix="poro2d-docs-jupyter-"))
    settings = {"NotebookClient": {"timeout": CELL_TIMEOUT}}
    (folder / "jupyter_nbconvert_config.json").write_text(json.dumps(settings))
    os.environ["JUPYTER_CONFIG_PATH"] = os.pathsep.join(
        p for p in (str(folder), os.environ.get("JUPYTER_CONFIG_PATH", "")) if p
    )
    return config


def on_files(files, config):
    for page, source in PAGES.items():
        text = rewrite_links((ROOT / source).read_text(encoding="utf-8"))
        files.append(File.generated(config, page, content=text))
    return files


def on_page_markdown(markdown, page, config, files):
    return rewrite_links(markdown)


#: a relative link to a Markdown page in a rendered notebook: href="../shear.md#anchor"
_NOTEBOOK_LINK = re.compile(r'href="((?:\.\./|\./)?[\w./-]+)\.md(#[^"]*)?"')


def notebook_links(html: str, source: str, url: str) -> str:
    """``html`` of the notebook ``source`` (``notebooks/own-soil.ipynb``), shown at ``url``
    (``notebooks/own-soil/``), with its links to pages (``../sand.md``, right beside the file)
    pointed at those pages' site addresses (``../../sand/``).

    A notebook's Markdown cells are not Markdown pages: MkDocs neither rewrites nor checks their
    links (benchmarks/check_site.py finds those that still break in the built site).
    """

    def site_link(match: re.Match) -> str:
        page = posixpath.normpath(posixpath.join(posixpath.dirname(source), match.group(1)))
        target = "" if page == "index" else page.removesuffix("/index") + "/"
        return f'href="{posixpath.relpath(target or ".", url)}/{match.group(2) or ""}"'

    return _NOTEBOOK_LINK.sub(site_link, html)


def on_post_page(output, page, config):
    if page.file.src_uri.endswith(".ipynb"):
        return notebook_links(output, page.file.src_uri, page.url)
    return output

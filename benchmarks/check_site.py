"""The built documentation site, checked in a real browser (headless Chromium).

    python3 benchmarks/check_site.py [SITE_DIR]        # default: site/, made by `mkdocs build --strict`

Serves SITE_DIR on a local port and opens every page of it in Chromium, one after the other in a
frame of one runner page, so that one browser renders them all. For each page it checks that

* every internal link resolves: the page it names is served (no 404), and its anchor (``#part``),
  if any, is an element of that page;
* every ``<img>`` rendered: its ``naturalWidth`` is above zero once the page has loaded;
* a notebook page (``notebooks/...``) shows outputs: at least one of its code cells has one, and
  none is a traceback (its outputs on stderr, a library's warnings, are counted in the table).

It prints one row per page and exits with 1 if any page has a problem (2 if the check could not
run: no Chromium, no site). Only the Python standard library and the ``chromium`` executable are
used: the runner page collects what the browser rendered and Chromium's ``--dump-dom`` hands it
back, so no driver library (Selenium, Playwright) and no browser download are needed.
"""

from __future__ import annotations

import argparse
import contextlib
import functools
import json
import os
import re
import select
import shutil
import signal
import subprocess
import sys
import tempfile
import threading
import time
import urllib.error
import urllib.request
from dataclasses import dataclass, field
from http.server import SimpleHTTPRequestHandler, ThreadingHTTPServer
from pathlib import Path
from urllib.parse import unquote, urldefrag, urlsplit

#: the page the browser opens: it loads each page of the site into its frame and writes what it found
RUNNER = "__check_site__.html"

#: runs in the browser: every page in turn in the frame, its links, anchors, images and notebook cells
SCRIPT = r"""
const frame = document.getElementById("page");
function loaded(url) {
  return new Promise((done) => { frame.onload = done; frame.src = url; });
}
function imagesDone(doc) {
  return Promise.all([...doc.images].map((img) => img.complete ? null : new Promise((done) => {
    img.addEventListener("load", done); img.addEventListener("error", done);
  })));
}
function notebook(doc) {
  const cells = [...doc.querySelectorAll(".jp-CodeCell")];
  if (!cells.length) return null;
  const stderr = [...doc.querySelectorAll(
    '.jp-OutputArea-output[data-mime-type="application/vnd.jupyter.stderr"]')];
  const traceback = /Traceback \(most recent call last\)|^\w+(Error|Exception)\b/m;
  return {
    code_cells: cells.length,
    with_output: cells.filter((c) => c.querySelector(".jp-OutputArea-output")).length,
    stderr: stderr.length,
    errors: stderr.filter((o) => traceback.test(o.textContent)).length,
  };
}
async function check(url) {
  await loaded(url);
  const doc = frame.contentDocument;
  await imagesDone(doc);
  return {
    url: url,
    title: doc.title,
    ids: [...doc.querySelectorAll("[id], a[name]")].map((e) => e.id || e.name),
    links: [...doc.querySelectorAll("a[href]")].map((a) => a.href),
    images: [...doc.images].map((img) => ({src: img.getAttribute("src").slice(0, 120),
                                           width: img.naturalWidth})),
    notebook: notebook(doc),
  };
}
async function checkPages() {
  const results = [];
  for (const url of PAGES) {
    try { results.push(await check(url)); }
    catch (err) { results.push({url: url, failure: String(err)}); }
  }
  return results;
}
"""


@dataclass
class PageReport:
    """What one page showed in the browser, and what is wrong with it."""

    path: str
    links: int = 0
    images: int = 0
    outputs: str = ""
    problems: list[str] = field(default_factory=list)


def site_pages(site: Path) -> list[str]:
    """The site's pages as URL paths (``api/``, ``index.html``...), the search and 404 pages aside."""
    pages = []
    for index in sorted(site.rglob("*.html")):
        rel = index.relative_to(site).as_posix()
        if rel in ("404.html", RUNNER) or rel.startswith(("assets/", "search/")):
            continue
        pages.append(rel.removesuffix("index.html") or "")
    return pages


def runner_page(pages: list[str]) -> str:
    """The runner page for ``pages`` (paths from the site's root)."""
    urls = json.dumps(["/" + page for page in pages])
    return (
        '<!doctype html><html><head><meta charset="utf-8"><title>site check</title></head><body>'
        '<iframe id="page" style="width:1280px;height:4000px;border:0"></iframe>'
        f"<script>const PAGES = {urls};{SCRIPT}</script></body></html>"
    )


class SiteHandler(SimpleHTTPRequestHandler):
    """The site's files, and the runner page (:data:`RUNNER`, kept in memory, never in the site),
    served without a log line per request."""

    runner = ""

    def do_GET(self) -> None:
        if self.path != "/" + RUNNER:
            return super().do_GET()
        body = self.runner.encode("utf-8")
        self.send_response(200)
        self.send_header("Content-Type", "text/html; charset=utf-8")
        self.send_header("Content-Length", str(len(body)))
        self.end_headers()
        self.wfile.write(body)

    def log_message(self, format, *args) -> None:  # noqa: A002 (the base class's name)
        pass


@functools.cache
def chromium() -> str | None:
    """The Chromium executable (Debian's ``chromium``, or one of the usual names), or None."""
    names = ("chromium", "chromium-browser", "google-chrome", "google-chrome-stable")
    return next((exe for exe in map(shutil.which, names) if exe), None)


@contextlib.contextmanager
def served(site: Path, pages: list[str]):
    """``site`` and the runner page of ``pages`` on a local port for the time of the block; yields
    the base address (``http://127.0.0.1:PORT``)."""
    handler = type("Handler", (SiteHandler,), {"runner": runner_page(pages)})
    with ThreadingHTTPServer(("127.0.0.1", 0), functools.partial(handler, directory=str(site))) as server:
        threading.Thread(target=server.serve_forever, daemon=True).start()
        try:
            yield f"http://127.0.0.1:{server.server_address[1]}"
        finally:
            server.shutdown()


def browse(base: str, timeout: float) -> list[dict]:
    """What the runner page at ``base`` collected of every page, as Chromium rendered them."""
    # Chromium's helper processes may still be writing the profile as the folder goes: what
    # they leave there is no result
    with (
        tempfile.TemporaryDirectory(ignore_cleanup_errors=True) as profile,
        Browser(Path(profile), timeout) as browser,
    ):
        session = browser.open(f"{base}/{RUNNER}")
        return browser.evaluate(session, "checkPages()")


class Browser:
    """Headless Chromium driven through its DevTools protocol on a pair of pipes
    (``--remote-debugging-pipe``: JSON messages ended by a NUL byte, commands on the browser's
    descriptor 3, answers and events on 4), so that the standard library is enough."""

    def __init__(self, profile: Path, timeout: float) -> None:
        self.deadline = time.monotonic() + timeout
        self.timeout = timeout
        to_browser, self.commands = os.pipe()  # not inheritable: only the copies made below reach it
        self.answers, from_browser = os.pipe()

        def descriptors() -> None:  # in the child: its ends of the pipes as descriptors 3 and 4
            command_end, answer_end = os.dup(to_browser), os.dup(from_browser)
            os.dup2(command_end, 3)
            os.dup2(answer_end, 4)

        cmd = [
            chromium(), "--headless", "--no-sandbox", "--disable-gpu", "--no-first-run", "--disable-sync",
            "--disable-background-networking", "--disable-component-update", "--disable-extensions",
            f"--user-data-dir={profile}", "--window-size=1280,4000", "--remote-debugging-pipe", "about:blank",
        ]  # fmt: skip
        # its own process group, so that the renderer and helper processes end with it
        self.process = subprocess.Popen(
            cmd,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
            close_fds=False,
            preexec_fn=descriptors,
            start_new_session=True,
        )
        os.close(to_browser)
        os.close(from_browser)
        self.buffer, self.events, self.next_id = b"", [], 0

    def __enter__(self) -> Browser:
        return self

    def __exit__(self, *exc) -> None:
        try:
            os.killpg(self.process.pid, signal.SIGKILL)
        except ProcessLookupError:  # the whole group has already ended
            pass
        self.process.wait()
        os.close(self.commands)
        os.close(self.answers)

    def send(self, method: str, params: dict | None = None, session: str | None = None) -> dict:
        """The result of one command (to the browser, or to the page of ``session``)."""
        self.next_id += 1
        message = {"id": self.next_id, "method": method, "params": params or {}}
        if session:
            message["sessionId"] = session
        os.write(self.commands, json.dumps(message).encode() + b"\0")
        while True:
            answer = self.receive()
            if answer.get("id") == self.next_id:
                if "error" in answer:
                    raise RuntimeError(f"{method}: {answer['error']}")
                return answer["result"]
            self.events.append(answer)

    def receive(self) -> dict:
        """The browser's next message, within the deadline."""
        while b"\0" not in self.buffer:
            left = self.deadline - time.monotonic()
            if left <= 0 or not select.select([self.answers], [], [], left)[0]:
                raise RuntimeError(f"the browser did not finish the pages within {self.timeout:g} s")
            chunk = os.read(self.answers, 1 << 20)
            if not chunk:
                raise RuntimeError("the browser ended before the pages were checked")
            self.buffer += chunk
        message, self.buffer = self.buffer.split(b"\0", 1)
        return json.loads(message)

    def open(self, url: str) -> str:
        """A new tab showing ``url``, once loaded; its session."""
        target = self.send("Target.createTarget", {"url": "about:blank"})["targetId"]
        session = self.send("Target.attachToTarget", {"targetId": target, "flatten": True})["sessionId"]
        self.send("Page.enable", session=session)
        self.send("Page.navigate", {"url": url}, session)
        while not any(e.get("method") == "Page.loadEventFired" for e in self.events):
            self.events.append(self.receive())
        return session

    def evaluate(self, session: str, expression: str):
        """The value of ``expression`` in the page of ``session``, its promise awaited."""
        params = {"expression": expression, "awaitPromise": True, "returnByValue": True}
        result = self.send("Runtime.evaluate", params, session)
        if "exceptionDetails" in result:
            raise RuntimeError(f"{expression}: {result['exceptionDetails']}")
        return result["result"]["value"]


def status_of(url: str) -> int:
    """The HTTP status of ``url`` from the local server (a page, an image, a notebook file)."""
    try:
        with urllib.request.urlopen(url, timeout=30) as response:
            return response.status
    except urllib.error.HTTPError as exc:
        return exc.code


def link_problems(links: list[str], base: str, ids: dict[str, set[str]], site: Path) -> list[str]:
    """Each internal link of a page that does not resolve: a missing page or file, or a missing anchor.

    ``ids`` maps each rendered page's URL path to the ids on it; a target that is not one of those
    pages (a file of the site) is asked of the server.
    """
    problems, seen = [], set()
    for link in links:
        target, anchor = urldefrag(link)
        if not target.startswith(base) or link in seen:
            continue  # another site's link (not checked here), or one already checked
        seen.add(link)
        path = unquote(urlsplit(target).path)
        if path not in ids and status_of(target) != 200:
            problems.append(f"broken link {path}")
        elif anchor and unquote(anchor) not in ids.get(path, anchors_of(site, path)):
            problems.append(f"missing anchor {path}#{anchor}")
    return problems


def anchors_of(site: Path, path: str) -> set[str]:
    """The ids of a served HTML file that the browser did not render as a page (none for other files)."""
    file = site / path.lstrip("/")
    file = file / "index.html" if file.is_dir() else file
    if file.suffix != ".html" or not file.is_file():
        return set()
    return set(re.findall(r'\sid="([^"]+)"', file.read_text(encoding="utf-8", errors="replace")))


def page_report(found: dict, base: str, ids: dict[str, set[str]], site: Path) -> PageReport:
    """One page's row: its counts and its problems."""
    report = PageReport(urlsplit(found["url"]).path if "://" in found["url"] else found["url"])
    if "failure" in found:
        report.problems.append(f"not rendered: {found['failure']}")
        return report
    report.links = len(found["links"])
    report.images = len(found["images"])
    report.problems += link_problems(found["links"], base, ids, site)
    report.problems += [f"image not rendered {img['src']}" for img in found["images"] if not img["width"]]
    cells = found.get("notebook")
    if report.path.startswith("/notebooks/"):
        if cells is None:
            report.problems.append("a notebook page without code cells")
        else:
            report.outputs = f"{cells['with_output']}/{cells['code_cells']}"
            if cells["stderr"]:  # shown to the reader (warnings, logs), but no failure: said, not refused
                report.outputs += f" ({cells['stderr']} stderr)"
            if cells["with_output"] == 0:
                report.problems.append("no cell output: the notebook was not executed")
            if cells["errors"]:
                report.problems.append(f"{cells['errors']} error output(s): a traceback")
    return report


def check_site(site: Path, timeout: float = 300.0) -> list[PageReport]:
    """Every page of the built ``site`` checked in Chromium (:func:`page_report` of each)."""
    pages = site_pages(site)
    with served(site, pages) as base:
        rendered = browse(base, timeout)
        ids = {urlsplit(r["url"]).path: set(r.get("ids", ())) for r in rendered}
        return [page_report(r, base, ids, site) for r in rendered]


def table(reports: list[PageReport]) -> str:
    """The reports as a plain table: page, links, images, notebook outputs, problems."""
    width = max([len(r.path) for r in reports] + [4])
    lines = [f"{'page':<{width}}  {'links':>5}  {'images':>6}  {'outputs':>16}  problems"]
    for r in reports:
        problems = "; ".join(r.problems) or "ok"
        lines.append(f"{r.path:<{width}}  {r.links:>5}  {r.images:>6}  {r.outputs:>16}  {problems}")
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("site", nargs="?", default="site", type=Path, help="the built site (default: site/)")
    parser.add_argument("--timeout", type=float, default=300.0, help="seconds the browser may take (300)")
    args = parser.parse_args(argv)
    if not (args.site / "index.html").is_file():
        print(f"check_site: no built site in {args.site} (mkdocs build --strict first)", file=sys.stderr)
        return 2
    if chromium() is None:
        print("check_site: no Chromium found (Debian: apt-get install -y chromium)", file=sys.stderr)
        return 2
    start = time.perf_counter()
    reports = check_site(args.site, args.timeout)
    print(table(reports))
    bad = [r for r in reports if r.problems]
    links, images = sum(r.links for r in reports), sum(r.images for r in reports)
    print(
        f"{len(reports)} pages, {links} links, {images} images checked in Chromium in "
        f"{time.perf_counter() - start:.0f} s: " + (f"{len(bad)} page(s) with problems" if bad else "all ok")
    )
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())

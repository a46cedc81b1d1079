"""A small document model rendered both as Markdown and as self-contained HTML.

Blocks are plain tuples so report builders stay readable:
``("h1"|"h2"|"h3", text)``, ``("p", text)``, ``("ul", [items])``,
``("table", headers, rows)``, ``("img", path, caption)``, ``("code", text)``.
Images are embedded in the HTML as base64 data, so the file opens without a server.
"""

from __future__ import annotations

import base64
import html
import os
from pathlib import Path

from poro2d.io_utils import atomic_path

Block = tuple

_CSS = """
body{font-family:-apple-system,Segoe UI,Helvetica,Arial,sans-serif;max-width:980px;margin:2em auto;
padding:0 1em;color:#222;line-height:1.5}
h1{border-bottom:2px solid #b2182b;padding-bottom:.2em}h2{margin-top:2em;border-bottom:1px solid #ddd}
table{border-collapse:collapse;margin:1em 0;font-size:.92em;display:block;overflow-x:auto;max-width:100%}
th,td{border:1px solid #ccc;padding:.3em .6em;text-align:right;white-space:nowrap}
th{background:#f4f1ea}td:first-child,th:first-child{text-align:left}
figure{margin:1.2em 0}figure img{max-width:100%;height:auto;border:1px solid #eee}
figcaption{font-size:.9em;color:#555}pre{background:#f6f6f6;padding:.8em;overflow-x:auto;font-size:.85em}
.note{background:#fff8e1;border-left:4px solid #f0b400;padding:.5em 1em}
"""


def _fmt(v) -> str:
    if v is None:
        return "-"
    if isinstance(v, float):
        if v != v:
            return "nan"
        if v == 0.0:
            return "0"
        a = abs(v)
        return f"{v:.4g}" if 1e-3 <= a < 1e5 else f"{v:.3e}"
    return str(v)


def to_markdown(blocks: list[Block], base: Path) -> str:
    out: list[str] = []
    for b in blocks:
        kind = b[0]
        if kind in ("h1", "h2", "h3"):
            out.append("#" * int(kind[1]) + " " + b[1])
        elif kind == "p":
            out.append(b[1])
        elif kind == "note":
            out.append("> " + b[1])
        elif kind == "ul":
            out.append("\n".join(f"- {it}" for it in b[1]))
        elif kind == "table":
            headers, rows = b[1], b[2]
            out.append("| " + " | ".join(headers) + " |")
            out.append("| " + " | ".join("---" for _ in headers) + " |")
            out.extend("| " + " | ".join(_fmt(c) for c in r) + " |" for r in rows)
        elif kind == "img":
            # relative to the report file itself, so the links work wherever the folder goes
            rel = Path(os.path.relpath(Path(b[1]).resolve(), Path(base).resolve())).as_posix()
            out.append(f"![{b[2]}]({rel})\n\n*{b[2]}*")
        elif kind == "code":
            out.append("```\n" + b[1] + "\n```")
        out.append("")
    return "\n".join(out)


def to_html(blocks: list[Block], title: str) -> str:
    e = html.escape
    parts = [f"<!doctype html><html><head><meta charset='utf-8'><title>{e(title)}</title>",
             f"<style>{_CSS}</style></head><body>"]  # fmt: skip
    for b in blocks:
        kind = b[0]
        if kind in ("h1", "h2", "h3"):
            parts.append(f"<{kind}>{e(b[1])}</{kind}>")
        elif kind == "p":
            parts.append(f"<p>{e(b[1])}</p>")
        elif kind == "note":
            parts.append(f"<p class='note'>{e(b[1])}</p>")
        elif kind == "ul":
            parts.append("<ul>" + "".join(f"<li>{e(str(it))}</li>" for it in b[1]) + "</ul>")
        elif kind == "table":
            head = "".join(f"<th>{e(h)}</th>" for h in b[1])
            body = "".join("<tr>" + "".join(f"<td>{e(_fmt(c))}</td>" for c in r) + "</tr>" for r in b[2])
            parts.append(f"<table><thead><tr>{head}</tr></thead><tbody>{body}</tbody></table>")
        elif kind == "img":
            p = Path(b[1])
            if p.is_file():
                data = base64.b64encode(p.read_bytes()).decode()
                mime = "image/svg+xml" if p.suffix == ".svg" else "image/png"
                parts.append(
                    f"<figure><img alt='{e(b[2])}' src='data:{mime};base64,{data}'>"
                    f"<figcaption>{e(b[2])}</figcaption></figure>"
                )
            else:
                parts.append(f"<p class='note'>figure missing: {e(str(p.name))}</p>")
        elif kind == "code":
            parts.append(f"<pre>{e(b[1])}</pre>")
    parts.append("</body></html>")
    return "\n".join(parts)


def write_report(blocks: list[Block], out_dir: str | os.PathLike, stem: str, title: str) -> list[Path]:
    d = Path(out_dir)
    md, ht = d / f"{stem}.md", d / f"{stem}.html"
    with atomic_path(md) as tmp:
        tmp.write_text(to_markdown(blocks, d))
    with atomic_path(ht) as tmp:
        tmp.write_text(to_html(blocks, title))
    return [md, ht]

"""The building blocks of fracid's self-contained HTML pages: escaping, numbers, tables, embedded
images, the provenance section and the page itself (inline CSS, images as ``data:image/png;base64``
URIs, no external resource). A small inline script counts the images that decoded after the page
loaded and writes the counts to ``<body data-images-loaded=".." data-images-total="..">`` so a
headless browser can check the page.
"""

from __future__ import annotations

import base64
import datetime
import html
import math
from pathlib import Path

_CSS = """
body { font-family: -apple-system, "Segoe UI", Helvetica, Arial, sans-serif; margin: 2em auto; max-width: 1100px;
       padding: 0 1em; color: #222; line-height: 1.4; }
h1 { border-bottom: 2px solid #444; padding-bottom: .2em; }
h2 { border-bottom: 1px solid #bbb; padding-bottom: .15em; margin-top: 1.8em; }
table { border-collapse: collapse; margin: .8em 0; font-size: 0.92em; }
th, td { border: 1px solid #ccc; padding: .25em .6em; text-align: right; }
th { background: #f0f0f0; }
td.text, th.text { text-align: left; }
tr.failed td { color: #888; }
figure { margin: 1em 0; }
figure img { max-width: 100%; height: auto; border: 1px solid #ddd; }
figcaption { font-size: 0.9em; color: #555; }
.meta { color: #555; }
.warn { color: #a40000; font-weight: bold; }
ul.notes li { margin: .2em 0; }
"""

_SCRIPT = """
window.addEventListener("load", function () {
  var images = Array.prototype.slice.call(document.images);
  var loaded = images.filter(function (img) { return img.complete && img.naturalWidth > 0; }).length;
  document.body.dataset.imagesLoaded = String(loaded);
  document.body.dataset.imagesTotal = String(images.length);
});
"""

def esc(value) -> str:
    return html.escape(str(value), quote=True)


def num(value, digits: int = 6) -> str:
    try:
        v = float(value)
    except (TypeError, ValueError):
        return esc(value)
    if math.isnan(v):
        return "n/a"
    if math.isinf(v):
        return "inf" if v > 0 else "-inf"
    return f"{v:.{digits}g}"


def duration(seconds) -> str:
    try:
        s = float(seconds)
    except (TypeError, ValueError):
        return esc(seconds)
    if not math.isfinite(s):
        return "n/a"
    if s < 60:
        return f"{s:.1f} s"
    h, rest = divmod(round(s), 3600)
    m, sec = divmod(rest, 60)
    return f"{s:.0f} s ({h} h {m} min {sec} s)" if h else f"{s:.0f} s ({m} min {sec} s)"


def html_table(header, rows, text_columns=(), row_classes=None) -> str:
    """HTML table; header and cells are already-formatted strings (escaped here)."""
    def cell(tag, k, value):
        cls = ' class="text"' if k in text_columns else ""
        return f"<{tag}{cls}>{esc(value)}</{tag}>"

    out = ["<table>", "<tr>" + "".join(cell("th", k, h) for k, h in enumerate(header)) + "</tr>"]
    for r, row in enumerate(rows):
        cls = f' class="{esc(row_classes[r])}"' if row_classes and row_classes[r] else ""
        out.append(f"<tr{cls}>" + "".join(cell("td", k, v) for k, v in enumerate(row)) + "</tr>")
    out.append("</table>")
    return "\n".join(out)


def html_image(png: bytes, alt: str, caption: str) -> str:
    data = base64.b64encode(png).decode("ascii")
    return (f'<figure><img src="data:image/png;base64,{data}" alt="{esc(alt)}">'
            f"<figcaption>{esc(caption)}</figcaption></figure>")


# ------------------------------------------------------------------------------------ metrics


def provenance_section(provenance) -> str:
    """A collapsed ``<details>`` "How this was run": version, command, date, machine, data files with
    their SHA-256, specimen and mesh, parameters, bounds and the configuration (as JSON); empty
    without a provenance."""
    import json

    if not provenance:
        return ""
    p = dict(provenance)
    files = html_table(["data file", "bytes", "SHA-256"], [[f.get("path", ""), f.get("bytes", ""),
                                                      f.get("sha256", f.get("error", ""))]
                                                     for f in p.get("data_files") or []], text_columns=(0, 2))
    rows = [["fracid", p.get("fracid", "")], ["command", p.get("command", "")], ["date (UTC)", p.get("date", "")]]
    rows += [[key.replace("_", " "), value] for key, value in (p.get("machine") or {}).items()]
    parts = [html_table(["", ""], rows, text_columns=(0, 1)), files if p.get("data_files") else ""]
    for key, heading in (("specimen", "Specimen and mesh"), ("parameters", "Model parameters (the fixed ones at "
                         "their values)"), ("bounds", "Bounds of the identified parameters"), ("config",
                         "Configuration (as read, defaults filled)")):
        if p.get(key) is not None:
            parts.append(f"<h3>{esc(heading)}</h3>\n<pre>{esc(json.dumps(p[key], indent=1))}</pre>")
    return ('<details class="provenance">\n<summary>How this was run</summary>\n' + "\n".join(x for x in parts if x)
            + "\n</details>")


def generated_now() -> str:
    """The local date and time for a report's "Generated ..." line."""
    return datetime.datetime.now().astimezone().strftime("%Y-%m-%d %H:%M %Z")


def write_document(path, title: str, body) -> Path:
    """Write a self-contained HTML page: the report's style and image check around ``body``.

    Parameters
    ----------
    path : str or Path
        The HTML file to write (parent directories are created).
    title : str
        Page title (escaped here).
    body : sequence of str
        HTML fragments, in order (not escaped).

    Returns
    -------
    Path
        The file written.
    """
    path = Path(path)
    document = "\n".join([
        "<!DOCTYPE html>",
        '<html lang="en">',
        "<head>",
        '<meta charset="utf-8">',
        '<meta name="viewport" content="width=device-width, initial-scale=1">',
        f"<title>{esc(title)}</title>",
        f"<style>{_CSS}</style>",
        "</head>",
        "<body>",
        *body,
        f"<script>{_SCRIPT}</script>",
        "</body>",
        "</html>",
        "",
    ])
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(document, encoding="utf-8")
    return path


__all__ = ["duration", "esc", "generated_now", "html_image", "html_table", "num", "provenance_section", "write_document"]

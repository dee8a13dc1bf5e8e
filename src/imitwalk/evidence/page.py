"""The report pages' common parts: style, inline images, sections, and the tables of a
run's judgements and push recovery (HTML as strings)."""

from __future__ import annotations

import base64
import html
from typing import TYPE_CHECKING

from imitwalk.evidence import curves, plots
from imitwalk.judge import tables
from imitwalk.judge.records import ProtocolVerdict, PushVerdict
from imitwalk.runs import RunDir

if TYPE_CHECKING:
    from matplotlib.figure import Figure

__all__ = ["STYLE", "b64", "evaluations", "figure", "img", "robustness", "section"]


def b64(data: bytes) -> str:
    return base64.b64encode(data).decode("ascii")


def img(fig: Figure, alt: str) -> str:
    png = plots.png_bytes(fig)
    return f'<img src="data:image/png;base64,{b64(png)}" alt="{html.escape(alt)}">'


STYLE = """body{font-family:sans-serif;max-width:1100px;margin:1em auto;padding:0 1em;color:#222}
img,video{max-width:100%;height:auto;display:block;margin:.5em 0}
table{border-collapse:collapse;margin:.5em 0}td,th{border:1px solid #ccc;padding:2px 8px;
text-align:left}.missing{color:#a00}figcaption{font-size:.9em;color:#444;margin-bottom:1em}
pre{background:#f6f6f6;padding:.5em;overflow:auto}"""


def section(title: str, body: str) -> str:
    return f"<section><h2>{html.escape(title)}</h2>\n{body}\n</section>\n"


def figure(img: str, caption: str) -> str:
    return f"<figure>{img}<figcaption>{caption}</figcaption></figure>"


def evaluations(rd: RunDir) -> str:
    found = sorted(p.name for p in rd.path.glob("protocol_*.json"))
    if not found:
        return (
            '<p class="missing">No <code>protocol_*.json</code>: run '
            "<code>imitwalk evaluate RUN --protocol eval</code> (or hard, bullet).</p>"
        )
    return "".join(
        tables.protocol_table(ProtocolVerdict.from_dict(rd.read_json(name), str(rd.file(name))))
        for name in found
    )


def robustness(rd: RunDir, kick: tuple) -> str:
    strip, caption = kick
    body = figure(img(strip, "a kick"), caption)
    if not rd.exists("push_recovery.json"):
        return body + (
            '<p class="missing">No <code>push_recovery.json</code>: run '
            "<code>imitwalk evaluate RUN --push-recovery</code>.</p>"
        )
    name = "push_recovery.json"
    res = PushVerdict.from_dict(rd.read_json(name), str(rd.file(name)))
    return img(curves.push_polar(res), "push recovery") + tables.push_table(res) + body

"""One self-contained HTML report page: verdict first, case table, embedded PNG figures, extra
sections.

The page has no external resource: CSS is inline and every figure is embedded as a
``data:image/png;base64,...`` URI, so ``report.html`` can be mailed or archived alone. All
text (titles, table cells, captions, ``text`` sections) is HTML-escaped; only a section's
``html`` entry is inserted verbatim (trusted, produced by our own code).

The page is written to a temporary file in the target folder and renamed into place.
This module does not import matplotlib.
"""

from __future__ import annotations

import base64
import html as _html
import os
from pathlib import Path
from typing import Any, Mapping, Sequence

from ambseal.analysis import ZONE_RTOL
from ambseal.errors import AmbsealError
from ambseal.files import write_text
from ambseal.report.verdict import (
    ZONE_COLOURS,
    ZONE_WORDS,
    detail_table_html,
    verdict_table_html,
    verdicts,
)

__all__ = ["render_report", "write_report"]

_CSS = """
body{font-family:system-ui,Segoe UI,Helvetica,Arial,sans-serif;margin:1em auto;max-width:1220px;padding:0 10px;color:#222}
h1{font-size:1.5em;margin-bottom:.2em}h2{font-size:1.2em;border-bottom:1px solid #ccc;padding-bottom:.2em;margin-top:1.4em}
table{border-collapse:collapse;font-size:.82em;max-width:100%}th,td{border:1px solid #bbb;padding:.25em .45em;text-align:right}
th{background:#f0f0f0;text-align:center}td.text{text-align:left}tr.unstable td{background:#fde8e8}
td.zone{text-align:center;font-weight:bold;color:#111}table.detail thead tr+tr th{white-space:nowrap}table.verdict{font-size:.92em}
table.verdict td.verdict{min-width:22em;max-width:34em}
figure{margin:.6em 0}figure img{max-width:100%;height:auto;border:1px solid #ddd}
figcaption{font-size:.85em;color:#555}.judged{font-size:.9em;margin-top:0}.meta{color:#666;font-size:.82em;margin-top:0;overflow-wrap:anywhere}
.legend span{display:inline-block;padding:0 .5em;margin-right:.3em;font-weight:bold}
.failed{background:#fde8e8;border:2px solid #c0392b;padding:.4em .8em}.failed li{margin:.2em 0}
.scroll{overflow-x:auto;max-width:100%}td.unstable{background:#fde8e8}
@media (max-width:1000px){table.verdict,table.verdict tbody,table.verdict tr,table.verdict td{display:block;width:auto;max-width:none;min-width:0}
table.verdict thead{display:none}table.verdict tr{border:1px solid #bbb;margin:.5em 0}
table.verdict td{border:none;border-bottom:1px solid #eee;text-align:left}
table.verdict td::before{content:attr(data-label) ": ";font-weight:normal;color:#555}
table.verdict td.zone::before{color:inherit}}
"""


def _esc(s: Any) -> str:
    return _html.escape(str(s), quote=True)


def _png_data_uri(path: str | os.PathLike) -> str:
    p = Path(path)
    try:
        data = p.read_bytes()
    except OSError as exc:
        raise AmbsealError(f"report: cannot read figure {str(p)!r}: {exc}") from exc
    if not data.startswith(b"\x89PNG\r\n\x1a\n"):
        raise AmbsealError(f"report: figure {str(p)!r} is not a PNG file")
    return "data:image/png;base64," + base64.b64encode(data).decode("ascii")


def _figure_html(path: str | os.PathLike, caption: str | None, alt: str) -> str:
    cap = f"<figcaption>{_esc(caption)}</figcaption>" if caption else ""
    return f'<figure><img src="{_png_data_uri(path)}" alt="{_esc(alt)}">{cap}</figure>'


def _zone_legend() -> str:
    zones = " ".join(f'<span style="background:{c}">{z}</span>{_esc(ZONE_WORDS[z])}'
                     for z, c in ZONE_COLOURS.items())
    return (f'<p class="legend">ISO 14839-3 zones: {zones}; A/B, B/C, C/D: a peak within '
            f"{100 * ZONE_RTOL:g} % of the limit between two zones, on their boundary</p>")


def render_report(
    *,
    title: str,
    metrics: Sequence[Mapping[str, Any]],
    figures: Sequence[tuple[str, str | os.PathLike]] = (),
    sections: Sequence[Mapping[str, Any]] = (),
    meta: str | None = None,
    clearances_um: Mapping[str, float] | None = None,
    judged_on: tuple[str, str] | None = None,
    failed: Sequence[str] = (),
    stability: Sequence[Mapping[str, Any]] = (),
    designs: Mapping[str, Mapping[str, Any]] | None = None,
) -> str:
    """The report page as a string (see :func:`write_report`)."""

    parts = [
        "<!DOCTYPE html>",
        '<html lang="en"><head><meta charset="utf-8">',
        f"<title>{_esc(title)}</title><style>{_CSS}</style></head><body>",
        f"<h1>{_esc(title)}</h1>",
    ]
    if meta:
        parts.append(f'<p class="meta">{_esc(meta)}</p>')
    if judged_on:
        text, href = judged_on
        parts.append(f'<p class="judged"><b>Judged on:</b> {_esc(text)} '
                     f'(<a href="{_esc(href)}">what the main job judges on</a>)</p>')
    if failed:
        parts += ['<h2>Failed controllers</h2><div class="failed"><ul>',
                  *(f"<li>{_esc(line)}</li>" for line in failed), "</ul></div>"]
    if metrics:
        parts += ["<h2>Verdict</h2>", verdict_table_html(verdicts(metrics, clearances_um, stability, designs)),
                  _zone_legend(), "<h2>Every judged condition</h2>",
                  f'<div class="scroll">{detail_table_html(metrics)}</div>']
    for caption, path in figures:
        parts += [f"<h2>{_esc(caption)}</h2>", _figure_html(path, None, caption)]
    for i, sec in enumerate(sections):
        if "title" not in sec:
            raise AmbsealError(f"report: section {i} has no 'title'")
        parts.append(f"<h2>{_esc(sec['title'])}</h2>")
        if "text" in sec:
            parts.append(f"<p>{_esc(sec['text'])}</p>")
        if "html" in sec:
            parts.append(str(sec["html"]))
        if "figure" in sec:
            parts.append(_figure_html(sec["figure"], sec.get("caption"), sec["title"]))
        if not any(k in sec for k in ("text", "html", "figure")):
            raise AmbsealError(f"report: section {sec['title']!r} needs 'text', 'html' or 'figure'")
    parts.append("</body></html>")
    return "\n".join(parts)


def write_report(
    path: str | os.PathLike,
    *,
    title: str = "ambseal report",
    metrics: Sequence[Mapping[str, Any]] = (),
    figures: Sequence[tuple[str, str | os.PathLike]] = (),
    sections: Sequence[Mapping[str, Any]] = (),
    meta: str | None = None,
    clearances_um: Mapping[str, float] | None = None,
    judged_on: tuple[str, str] | None = None,
    failed: Sequence[str] = (),
    stability: Sequence[Mapping[str, Any]] = (),
    designs: Mapping[str, Mapping[str, Any]] | None = None,
) -> Path:
    """Write one self-contained ``report.html``.

    Parameters
    ----------
    path : path-like
        Output file (its folder must exist).
    title : str
        Page title and heading (escaped).
    metrics : sequence of mapping
        The judged cases of :func:`ambseal.analysis.judge.judge` (``controller``,
        ``pressure_bar``, ``speed_hz``, ``stable``, ``max_real_pole``, ``sensitivity_peak``
        and ``_per_axis``, ``iso_zone`` and ``_per_axis``, ``compliance_peak_m_per_n``,
        ``unbalance_peak_um``, ``impulse_peak_um``, ``impulse_settling_s``): shown first as
        one verdict per controller (:mod:`ambseal.report.verdict`), then as a table of every
        case; unstable rows are shaded, missing values shown as ``—``.
    figures : sequence of (caption, png_path)
        Figures, each under its own heading, embedded as base64 data URIs.
    sections : sequence of mapping
        Extra sections, each with ``title`` and any of ``text`` (escaped paragraph),
        ``html`` (inserted verbatim — trusted content only), ``figure`` (PNG path) with
        optional ``caption``.
    meta : str, optional
        A line under the title (escaped), e.g. rig file and version.
    clearances_um : mapping, optional
        Clearances (µm) the unbalance orbit is set against, e.g. ``{"air gap": 500}``.
    judged_on : (str, str), optional
        What the loops were judged on, in words, and a link to the manual's page that
        explains it: a line under the stamp.
    failed : sequence of str
        Controllers that failed, one plain line each with the reason
        (:class:`ambseal.analysis.delivery.FailedController` ``reason``): shown first,
        above the verdict, under "Failed controllers".
    stability : sequence of mapping
        ``metrics.json`` ``stability``: every controller's loop from standstill to the top
        speed (stability and ISO 14839-3 zones, which the verdict counts); an unstable
        one makes its verdict "not acceptable".
    designs : mapping, optional
        ``metrics.json`` ``controllers``: each design's bound (γ, μ and whether robust
        performance is met) beside its verdict.

    Returns
    -------
    pathlib.Path

    Raises
    ------
    AmbsealError
        If a figure is missing or not a PNG, a section is malformed, or the folder is missing.
    """
    path = Path(path)
    if not path.parent.is_dir():
        raise AmbsealError(f"report folder {str(path.parent)!r} does not exist")
    text = render_report(title=title, metrics=metrics, figures=figures, sections=sections,
                         meta=meta, clearances_um=clearances_um, judged_on=judged_on,
                         failed=failed, stability=stability, designs=designs)
    write_text(path, text)
    return path

"""One self-contained HTML report page: metrics table, embedded PNG figures, extra sections.

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
import math
import os
from pathlib import Path
from typing import Any, Mapping, Sequence

from ambseal.errors import AmbsealError
from ambseal.files import write_text

__all__ = ["METRIC_COLUMNS", "render_report", "write_report", "format_value"]

#: Preferred column order and headers of the metrics table; other keys follow in order seen.
METRIC_COLUMNS: dict[str, str] = {
    "controller": "Controller",
    "pressure_bar": "Pressure (bar)",
    "stable": "Stable",
    "max_real_pole": "Max Re(pole) (1/s)",
    "sensitivity_peak": "Peak σ̄(S_o) (-)",
    "iso_zone": "ISO 14839-3 zone",
    "compliance_peak_m_per_n": "Peak compliance (m/N)",
    "unbalance_peak_um": "Peak unbalance resp. (µm)",
    "impulse_peak_um": "Impulse peak (µm)",
    "impulse_settling_s": "Settling 2 % (s)",
}

_CSS = """
body{font-family:system-ui,Segoe UI,Helvetica,Arial,sans-serif;margin:2em auto;max-width:1100px;color:#222}
h1{font-size:1.6em}h2{font-size:1.25em;border-bottom:1px solid #ccc;padding-bottom:.2em;margin-top:1.6em}
table{border-collapse:collapse;font-size:.9em}th,td{border:1px solid #bbb;padding:.3em .6em;text-align:right}
th{background:#f0f0f0}td.text{text-align:left}tr.unstable td{background:#fde8e8}
figure{margin:1em 0}figure img{max-width:100%;height:auto;border:1px solid #ddd}
figcaption{font-size:.85em;color:#555}.meta{color:#666;font-size:.85em}
"""


def format_value(v: Any) -> str:
    """Text of one table cell: 4 significant digits for floats, yes/no, ``—`` for None."""
    if v is None:
        return "—"
    if isinstance(v, bool):
        return "yes" if v else "no"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        if math.isnan(v):
            return "—"
        if math.isinf(v):
            return "∞" if v > 0 else "−∞"
        return f"{v:.4g}"
    return str(v)


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


def _table_html(metrics: Sequence[Mapping[str, Any]]) -> str:
    if not metrics:
        return "<p>No cases.</p>"
    keys = [k for k in METRIC_COLUMNS if any(k in m for m in metrics)]
    for m in metrics:
        keys += [k for k in m if k not in keys]
    head = "".join(f"<th>{_esc(METRIC_COLUMNS.get(k, k))}</th>" for k in keys)
    rows = []
    for m in metrics:
        cls = ' class="unstable"' if m.get("stable") is False else ""
        cells = []
        for k in keys:
            v = m.get(k)
            kind = ' class="text"' if isinstance(v, str) else ""
            cells.append(f"<td{kind}>{_esc(format_value(v))}</td>")
        rows.append(f"<tr{cls}>{''.join(cells)}</tr>")
    return f"<table><thead><tr>{head}</tr></thead><tbody>{''.join(rows)}</tbody></table>"


def render_report(
    *,
    title: str,
    metrics: Sequence[Mapping[str, Any]],
    figures: Sequence[tuple[str, str | os.PathLike]] = (),
    sections: Sequence[Mapping[str, Any]] = (),
    meta: str | None = None,
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
    parts += ["<h2>Metrics</h2>", _table_html(metrics)]
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
) -> Path:
    """Write one self-contained ``report.html``.

    Parameters
    ----------
    path : path-like
        Output file (its folder must exist).
    title : str
        Page title and heading (escaped).
    metrics : sequence of mapping
        One dict per case, e.g. keys ``controller``, ``pressure_bar``, ``stable``,
        ``max_real_pole``, ``sensitivity_peak``, ``iso_zone``, ``compliance_peak_m_per_n``,
        ``unbalance_peak_um``, ``impulse_peak_um``, ``impulse_settling_s`` (known keys first, in
        :data:`METRIC_COLUMNS` order, then any others). Values: str, bool, int, float, None;
        ``inf`` (float or the string ``"inf"``) is shown as such; rows with ``stable`` False
        are highlighted.
    figures : sequence of (caption, png_path)
        Figures, each under its own heading, embedded as base64 data URIs.
    sections : sequence of mapping
        Extra sections, each with ``title`` and any of ``text`` (escaped paragraph),
        ``html`` (inserted verbatim — trusted content only), ``figure`` (PNG path) with
        optional ``caption``.
    meta : str, optional
        A line under the title (escaped), e.g. rig file and version.

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
    text = render_report(title=title, metrics=metrics, figures=figures, sections=sections, meta=meta)
    write_text(path, text)
    return path

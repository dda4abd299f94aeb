"""Tests of ambseal.report.html: a self-contained, escaped report page."""

from __future__ import annotations

import base64
import re
import subprocess
import sys

import numpy as np
import pytest

from ambseal.errors import AmbsealError
from ambseal.report import figures, html


def _metrics():
    return [
        {"controller": "PID <b>", "pressure_bar": 2.04, "stable": True, "max_real_pole": -12.5,
         "sensitivity_peak": 3.0, "iso_zone": "B", "compliance_peak_m_per_n": 2.1e-7,
         "unbalance_peak_um": 7.9, "impulse_peak_um": 12.3, "impulse_settling_s": 0.03, "note": "x&y"},
        {"controller": "PID", "pressure_bar": 4.08, "stable": False, "max_real_pole": 3.2,
         "sensitivity_peak": None, "iso_zone": "D", "impulse_settling_s": "inf"},
    ]


def test_report_is_self_contained_and_escaped(tmp_path):
    """Reference: self-containment by construction — no external src/href (every <img> is a
    data:image/png;base64 URI whose bytes decode to the written PNG); HTML escaping of user text
    (html.escape, WHATWG HTML §13.1.2) — a '<b>' in a controller name must not become markup."""
    f = np.logspace(0, 3, 50)
    png = figures.sensitivity_figure(tmp_path / "s.png", [("PID", f, 1 + 0 * f)])
    png2 = figures.unbalance_figure(tmp_path / "u.png", [("PID", f, f / 100)])
    out = html.write_report(
        tmp_path / "report.html", title="Seal <test>", metrics=_metrics(),
        figures=[("Sensitivity", png)],
        sections=[{"title": "Notes & caveats", "text": "<script>alert(1)</script>"},
                  {"title": "Unbalance", "figure": png2, "caption": "G2.5, 69 kg"},
                  {"title": "Raw", "html": "<p id='raw'>ok</p>"}],
        meta="rig=testrig.toml",
    )
    text = out.read_text(encoding="utf-8")
    assert text.startswith("<!DOCTYPE html>")
    assert "<script>" not in text and "&lt;script&gt;" in text
    assert "PID &lt;b&gt;" in text and "Seal &lt;test&gt;" in text and "x&amp;y" in text
    assert "<p id='raw'>ok</p>" in text
    refs = re.findall(r"""(?:src|href)\s*=\s*["']?([^"'\s>]*)""", text, flags=re.I)
    assert refs and all(r.startswith("data:image/png;base64,") for r in refs)
    assert "<link" not in text and "@import" not in text and "url(" not in text
    srcs = re.findall(r'<img src="data:image/png;base64,([^"]+)"', text)
    assert len(srcs) == 2
    assert base64.b64decode(srcs[0]) == png.read_bytes()
    assert text.count("<tr") == 3 and 'class="unstable"' in text
    assert "inf" in text  # settling "inf" string is shown as given
    assert not [p for p in tmp_path.iterdir() if p.name.endswith(".tmp")]


def test_format_value():
    """Reference: table conventions of this module's docstring (4 significant digits, yes/no,
    — for missing, ∞ for inf)."""
    assert html.format_value(0.0123456) == "0.01235"
    assert html.format_value(True) == "yes" and html.format_value(None) == "—"
    assert html.format_value(float("inf")) == "∞" and html.format_value(float("nan")) == "—"


def test_bad_inputs_raise(tmp_path):
    """Reference: interface contract — a non-PNG figure or an empty section raises AmbsealError."""
    bad = tmp_path / "x.png"
    bad.write_bytes(b"not a png")
    with pytest.raises(AmbsealError):
        html.write_report(tmp_path / "r.html", figures=[("x", bad)])
    with pytest.raises(AmbsealError):
        html.write_report(tmp_path / "r.html", sections=[{"title": "empty"}])
    assert not (tmp_path / "r.html").exists()


def test_imports_stay_light():
    """Reference: DESIGN.md 'light imports' — import ambseal, ambseal.analysis (and its numeric
    modules, which import python-control lazily) and ambseal.report.html without matplotlib."""
    code = ("import sys, ambseal, ambseal.analysis, ambseal.report, ambseal.report.html\n"
            "import ambseal.analysis.loops, ambseal.analysis.iso, ambseal.analysis.unbalance\n"
            "import ambseal.analysis.response, ambseal.lti.freqresp\n"
            "assert 'matplotlib' not in sys.modules, 'matplotlib imported'\n")
    subprocess.run([sys.executable, "-c", code], check=True)

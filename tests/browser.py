"""Headless Chromium for the report tests: a screenshot, and the page's own account of itself.

Chromium (Debian's ``chromium``; ``.ci/run`` installs it where it can) loads, in one run
that also takes the screenshot, a copy of the report with a small script put first in
its ``<head>``: it records ``window.onerror`` and ``console.error`` calls and, at the
``load`` event (every image fetched and decoded or failed), writes what it found — console
errors, images without decoded pixels (``complete`` and ``naturalWidth`` > 0), document
and viewport widths, whether the verdict table is there and where its bottom edge lies — as
JSON into the DOM, which ``--dump-dom`` prints.
"""

from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
from pathlib import Path

_PROBE = """<script>
window.__errors = [];
window.addEventListener("error", e => window.__errors.push(String(e.message || e.type)), true);
const _ce = console.error; console.error = (...a) => { window.__errors.push(a.join(" ")); _ce(...a); };
window.addEventListener("load", () => {
  const imgs = Array.from(document.images);
  const bad = imgs.map((im, i) => (im.complete && im.naturalWidth > 0) ? -1 : i)
                  .filter(i => i >= 0);
  const v = document.getElementById("verdict");
  const out = {errors: window.__errors, images: imgs.length, bad_images: bad,
               doc_width: document.documentElement.scrollWidth, view_width: window.innerWidth,
               verdict: !!v, verdict_bottom: v ? v.getBoundingClientRect().bottom : null,
               view_height: window.innerHeight};
  const pre = document.createElement("pre"); pre.id = "probe";
  pre.textContent = JSON.stringify(out); document.body.appendChild(pre);
});
</script>"""


def chromium() -> str | None:
    """Path of a Chromium binary, or None."""
    for name in ("chromium", "chromium-browser", "google-chrome"):
        path = shutil.which(name)
        if path:
            return path
    return None


def probe(report: Path, screenshot: Path | None = None, width: int = 1280,
          height: int = 900) -> dict:
    """Open a probed copy of ``report`` at ``width`` × ``height`` CSS px in one Chromium run;
    the probe's JSON, and the first screen as a PNG at ``screenshot`` when given."""
    text = report.read_text(encoding="utf-8")
    probed = report.with_name(report.stem + "_probe.html")
    probed.write_text(text.replace("<head>", "<head>" + _PROBE, 1), encoding="utf-8")
    cmd = [chromium(), "--headless", "--no-sandbox", "--disable-gpu", "--hide-scrollbars",
           "--disable-extensions", "--disable-background-networking", "--disable-sync",
           "--disable-component-update", "--no-default-browser-check", "--mute-audio",
           f"--window-size={width},{height}", "--dump-dom"]
    if screenshot is not None:
        cmd.append(f"--screenshot={screenshot}")
    env = {**os.environ, "DBUS_SESSION_BUS_ADDRESS": "disabled:"}  # no D-Bus wait
    try:
        dom = subprocess.run(cmd + [probed.as_uri()], capture_output=True, text=True,
                             timeout=120, env=env).stdout
    finally:
        probed.unlink()
    m = re.search(r'<pre id="probe">(.*?)</pre>', dom, flags=re.S)
    if m is None:
        raise AssertionError(f"the probe did not report (page did not load?): {dom[:300]!r}")
    return json.loads(m.group(1).replace("&quot;", '"').replace("&amp;", "&"))

"""Read a run's report.html back and hold every verdict in it against metrics.json.

The reference is metrics.json's numbers, graded here on their own: ISO 14839-3:2006's zone
limits on the sensitivity peaks (3, 4, 5: 9.5, 12 and 14 dB, a peak on a limit in the
upper zone; within 0.1 % of a limit, the grid's resolution of a peak, on the boundary of
the two zones, "A/B"), an unstable loop — judged, or anywhere in the speed range, continuous or as
it runs — zone D and "not acceptable", the sign-off's outcome per criterion. Each table
of the page is parsed from its HTML: a row says what its cells say, not what the code
meant them to say.
"""

from __future__ import annotations

import json
from html.parser import HTMLParser
from pathlib import Path

#: ISO 14839-3:2006 upper limits of zones A, B and C on the sensitivity peak
ISO_LIMITS = ((3.0, "A"), (4.0, "B"), (5.0, "C"))
#: The relative band around a limit that the report grades on the boundary of two zones
BAND = 1e-3


def zone_of(peak: float | None) -> str:
    """The zone of a sensitivity peak, ``"A/B"`` within :data:`BAND` of the limit between
    A and B; None (an unstable loop's) is D."""
    if peak is None:
        return "D"
    for (limit, z), upper in zip(ISO_LIMITS, "BCD"):
        if abs(peak - limit) <= BAND * limit:
            return f"{z}/{upper}"
    return next((z for limit, z in ISO_LIMITS if peak < limit), "D")


def worst(zones) -> str:
    """The worst zone, a boundary between its two (``"A/B"`` is worse than A, better than
    B)."""
    return max(zones, key=lambda z: sum(map("ABCD".index, z.split("/"))) / len(z.split("/")),
               default="A")


class _Tables(HTMLParser):
    """Every ``<table>`` of a page: its attributes and its rows of cell texts."""

    def __init__(self):
        super().__init__()
        self.tables: list[tuple[dict, list[list[str]]]] = []
        self._open: list = []
        self._cell: list[str] | None = None

    def handle_starttag(self, tag, attrs):
        if tag == "table":
            self._open.append((dict(attrs), []))
        elif tag == "tr" and self._open:
            self._open[-1][1].append([])
        elif tag in ("td", "th") and self._open:
            self._cell = []

    def handle_endtag(self, tag):
        if tag in ("td", "th") and self._cell is not None and self._open:
            self._open[-1][1][-1].append(" ".join("".join(self._cell).split()))
            self._cell = None
        elif tag == "table" and self._open:
            self.tables.append(self._open.pop())

    def handle_data(self, data):
        if self._cell is not None:
            self._cell.append(data)


def _table(tables, test) -> list[list[str]]:
    found = [rows for attrs, rows in tables if test(attrs, rows)]
    assert len(found) == 1, f"{len(found)} tables match"
    return found[0]


def _unstable(case: dict) -> bool:
    return not case["stable"] or not (case.get("discrete") or {}).get("stable", True)


def check_report_agrees(out: Path) -> None:
    """Assert that ``out/report.html`` says what ``out/metrics.json`` holds."""
    m = json.loads((out / "metrics.json").read_text())
    parser = _Tables()
    parser.feed((out / "report.html").read_text(encoding="utf-8"))
    tables = parser.tables
    names = list(dict.fromkeys(c["controller"] for c in m["cases"]))

    verdict = _table(tables, lambda a, r: a.get("id") == "verdict")
    head, rows = verdict[0], {r[0]: dict(zip(verdict[0], r)) for r in verdict[1:]}
    assert list(rows) == names, (list(rows), names)
    for name in names:
        cases = [c for c in m["cases"] if c["controller"] == name]
        speed = [c for c in m.get("stability") or [] if c["controller"] == name]
        lost = any(not c["stable"] for c in cases) or any(_unstable(c) for c in speed)
        row = rows[name]
        # every loop graded: judged and speed-range conditions, continuous and as it runs
        loops = [b for c in [*cases, *speed] for b in (c, c.get("discrete") or {})
                 if b.get("stable") and b.get("sensitivity_peak") is not None]
        sigma = "D" if lost else worst(zone_of(b["sensitivity_peak"]) for b in loops)
        axis = "D" if lost else worst(zone_of(v) for b in loops
                                      for v in b["sensitivity_peak_per_axis"].values())
        assert row[head[2]] == axis and row[head[3]] == sigma, (name, row)
        assert axis <= sigma  # σ̄(S_o) bounds every axis's peak
        words = row[head[-1]]
        # an amplifier asked for more than a whole limit fails the controller too
        cap = (m["controllers"].get(name) or {}).get("capacity") or {}
        saturated = any(cap.get(q) is not None and cap[q] > 1
                        for q in ("current_used", "voltage_used", "bias_used"))
        # and so does an unbalance orbit beyond a clearance of the rig
        beyond = "unbalance orbit" in ((m.get("failed") or {}).get(name) or {}).get("reason", "")
        assert words.startswith("Not acceptable") == (lost or saturated or beyond), (name, words)
        if not (lost or saturated or beyond):
            assert words.startswith(f"Zone {axis}"), (name, words)
        else:
            assert name in m["failed"], (name, m["failed"])
        peaks = [b["sensitivity_peak"] for b in loops]
        assert row[head[4]] == (f"{max(peaks):.3g}" if peaks else "—"), (name, row)
        bad = sum(_unstable(c) for c in speed)
        over = row[head[1]]
        if speed and not bad:
            # what was judged, no more: standstill only where 0 Hz was among the speeds;
            # lost at the judged conditions, only the speed range's speeds hold
            lost_judged = all(not c["stable"] for c in cases)
            hz = sorted({c["speed_hz"] for c in [*([] if lost_judged else cases), *speed]})
            span = (f"standstill to {hz[-1]:g} Hz" if hz[0] == 0 else
                    f"{hz[0]:g}–{hz[-1]:g} Hz (standstill not judged)")
            if lost_judged:
                n = len(speed)
                assert over == (f"none; stable at {'its' if n > 1 else 'the'} {n} speed-range "
                                f"condition{'s' if n > 1 else ''} ({span})"), (over, span)
            else:
                assert over.endswith(span), (over, span)
        elif bad:
            assert f"unstable at {bad} of {len(speed)} speed-range conditions" in over, over

    detail = _table(tables, lambda a, r: a.get("class") == "detail")
    body = detail[2:]
    assert len(body) == len(m["cases"])
    for row, case in zip(body, m["cases"]):
        assert row[0] == case["controller"]
        assert row[2] == ("yes" if case["stable"] else "no"), (row, case)
        n_axes = len(case["sensitivity_peak_per_axis"])
        assert row[4 + n_axes + 1] == (zone_of(case["sensitivity_peak"])
                                       if case["stable"] else "D"), (row, case)

    if m.get("stability"):
        speeds = sorted({c["speed_hz"] for c in m["stability"]})
        grid = _table(tables, lambda a, r: r and r[0][:1] == ["Controller"]
                      and r[0][1:] == [f"{f:g} Hz" for f in speeds])
        for row in grid[1:]:
            for f, cell in zip(speeds, row[1:]):
                at = [c for c in m["stability"] if c["controller"] == row[0]
                      and c["speed_hz"] == f]
                ok = bool(at) and not any(map(_unstable, at))
                zones = [z for c in at for b in (c, c.get("discrete") or {})
                         for z in (b.get("iso_zone_per_axis") or {}).values()]
                want = ("stable" + (f", zone {worst(zones)}" if zones else "")) if ok else None
                # σ̄(S_o) over all axes, graded here from its peaks, where worse than any axis
                peaks = [b["sensitivity_peak"] for c in at for b in (c, c.get("discrete") or {})
                         if b.get("sensitivity_peak") is not None]
                mimo = worst([zone_of(x) for x in peaks])
                if ok and zones and worst([mimo, worst(zones)]) != worst(zones):
                    want += f"; σ̄(S_o) zone {mimo} ({max(peaks):.3g})"
                assert (cell == want if ok else cell.startswith("unstable") if at
                        else cell == "—"), (row[0], f, cell)

    if m.get("signoff"):
        s = m["signoff"]
        outcome = _table(tables, lambda a, r: r and r[0][:2] == ["controller", "criterion"])
        expected = [(name, c["criterion"], c["passed"], c["counts"], c["graded"],
                     c["outcome"])
                    for name, per in s["controllers"].items() for c in per["criteria"]]
        assert len(outcome) - 1 == len(expected)
        for row, (name, criterion, passed, counts, graded, said) in zip(outcome[1:],
                                                                       expected):
            assert row[:2] == [name, criterion] and row[-1] == said, (row, said)
            assert (row[-1] == "passed") == (passed and counts and graded), (row, passed)
            if not graded:
                assert row[-1] == "not graded" and not passed, row
            elif counts:
                assert row[-1] == ("passed" if passed else "FAILED"), row
        page = (out / "report.html").read_text(encoding="utf-8")
        assert ("Sign-off PASSED" in page) == s["passed"]
        assert s["passed"] == all(c["passed"] for per in s["controllers"].values()
                                  for c in per["criteria"] if c["counts"] and c["graded"])

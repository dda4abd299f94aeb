"""Docstrings and comments state the contract; history and measurements live in
benchmarks/README.md and CHANGELOG.md. This test refuses the words of a lab notebook in the
package and the tests: what code "used to" do, what was done "as before" or at an "earlier
tuning", what "the issue" asked; in the package also a measurement record ("Measured: …")."""

from __future__ import annotations

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
HISTORY = re.compile(
    r"\bused to be\b|\b(that|which|it) used to\b|\bas before\b|\bearlier tuning\b"
    r"|\bthe issue\b|\bissue #?\d+|\bbefore this (change|commit|session)\b", re.IGNORECASE)
#: A measurement record, refused in the package only (a test may state what it measured)
RECORD = re.compile(r"\bMeasured:")


def _hits(folder: str, *patterns: re.Pattern) -> list[str]:
    out = []
    for path in sorted((ROOT / folder).rglob("*.py")):
        if path == Path(__file__).resolve():
            continue
        for n, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
            if any(p.search(line) for p in patterns):
                out.append(f"{path.relative_to(ROOT)}:{n}: {line.strip()}")
    return out


def test_pattern_finds_what_it_refuses():
    """The pattern itself: each refused phrase is found, ordinary uses of the words are not."""
    for text in ("the bisection that used to be here", "as before, M = 3", "the issue's bar",
                 "issue 42", "the earlier tuning", "before this change"):
        assert HISTORY.search(text), text
    assert RECORD.search("Measured: the pump")
    for text in ("the matrix used to build the plant", "the issued controller",
                 "measured displacements", "before the run starts"):
        assert not HISTORY.search(text) and not RECORD.search(text), text


def test_package_has_no_history_in_its_text():
    assert _hits("src/ambseal", HISTORY, RECORD) == []


def test_tests_have_no_history_in_their_text():
    assert _hits("tests", HISTORY) == []

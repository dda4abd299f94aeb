"""Sphinx glue of the manual's generated references (:mod:`ambseal_reference` has the
content). Directives:

``.. ambseal-rig-keys::``
    Every key of the rig file and the truth file.
``.. ambseal-cli::``
    Every command and option of ``ambseal``.
``.. ambseal-json-schema:: PATH``
    A JSON Schema shipped in the package (path relative to the repository), or a note
    that it is not shipped yet.
"""

from __future__ import annotations

import os
import re
from pathlib import Path

from docutils import nodes
from docutils.statemachine import StringList
from sphinx.util.docutils import SphinxDirective
from sphinx.util.nodes import nested_parse_with_titles

import ambseal_reference as ref

ROOT = Path(__file__).resolve().parents[2]


class _RstDirective(SphinxDirective):
    """Parses the reStructuredText a generator returns into the page."""

    def text(self) -> str:  # pragma: no cover - overridden
        raise NotImplementedError

    def run(self):
        container = nodes.container()
        lines = StringList(self.text().splitlines(), source=f"<{self.name}>")
        nested_parse_with_titles(self.state, lines, container, self.content_offset)
        return container.children


class RigKeys(_RstDirective):
    def text(self) -> str:
        return ref.rig_keys_rst()


class Cli(_RstDirective):
    def text(self) -> str:
        return ref.cli_rst()


class JsonSchema(_RstDirective):
    required_arguments = 1

    def text(self) -> str:
        rel = self.arguments[0]
        path = ROOT / rel
        self.env.note_dependency(str(path))
        here = Path(self.env.doc2path(self.env.docname)).parent
        return ref.json_schema_rst(path, rel, os.path.relpath(path, here))


def _lenient_in_docstrings(app, domain, node) -> bool | None:
    """Missing Python references inside docstrings are not errors: the docstrings refer to
    modules the API reference leaves out (the layers' private helpers) and are the code's
    business. The manual's own pages stay strict (``-n``)."""
    source = node.source or ""
    if domain is not None and domain.name == "py" and "docstring of" in source:
        return True
    return None


_SPANS = re.compile(r"(``.+?``|`[^`]*`)")


def _bars_as_text(app, what, name, obj, options, lines: list[str]) -> None:
    """``|x|`` in a docstring is an absolute value or a norm, never a reStructuredText
    substitution (the code uses none): escape the bars outside literals, math and tables,
    so that the docstrings stay plain text for the reader of the source."""
    block_indent = None  # indentation of the line that opened a literal or directive block
    for i, line in enumerate(lines):
        stripped = line.lstrip()
        indent = len(line) - len(stripped)
        if block_indent is not None:
            if not stripped or indent > block_indent:
                continue  # inside the block: not prose
            block_indent = None
        if stripped.startswith(".. "):
            block_indent = indent
            continue
        end = stripped.rstrip()
        if not stripped or stripped.startswith(">>>") or (
                stripped[0] in "+|" and end[-1] == stripped[0] and end.count(end[0]) >= 3):
            continue  # doctest, or a grid table's row
        lines[i] = _escape_bars(line)
        if line.rstrip().endswith("::"):
            block_indent = indent


def _escape_bars(text: str) -> str:
    parts = _SPANS.split(text)
    return "".join(p if k % 2 else p.replace("|", "\\|") for k, p in enumerate(parts))


def setup(app):
    app.connect("autodoc-process-docstring", _bars_as_text)
    app.connect("warn-missing-reference", _lenient_in_docstrings)
    app.add_directive("ambseal-rig-keys", RigKeys)
    app.add_directive("ambseal-cli", Cli)
    app.add_directive("ambseal-json-schema", JsonSchema)
    return {"parallel_read_safe": True, "parallel_write_safe": True, "version": "1"}

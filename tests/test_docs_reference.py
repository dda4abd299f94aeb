"""The manual's generated references list what the code has (docs/_ext/ambseal_reference.py
builds them at every Sphinx build; these tests need no Sphinx)."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "docs" / "_ext"))

import ambseal_reference as ref  # noqa: E402


def test_every_configuration_field_has_a_unit_and_a_meaning():
    """Reference: the pydantic models of ambseal.config. A field added without an entry in
    the key reference, or an entry left for a removed field, fails here (and the build)."""
    missing, stale = ref.missing_key_docs()
    assert missing == [] and stale == []


def test_the_rig_key_page_lists_exactly_the_models_fields():
    """Reference: RigConfig and TruthSection walked field by field (every nested model),
    independently of the page generator; the keys the page lists, read back from its text,
    are the same set."""
    page = ref.rig_keys_rst(design_defaults=False)
    assert ref.page_keys(page) == ref.model_keys()


def test_the_rig_key_page_states_the_derived_design_defaults():
    """Reference: ambseal design --show-defaults of the embedded rig without [design]; its
    rules appear on the page beside the keys (e.g. D_e = air gap / 25, P5 §3.1.4)."""
    page = ref.rig_keys_rst()
    assert "air gap / 25" in page and "bias current / 6" in page
    assert "k ± 100 % of every seal" in page


def test_the_cli_page_lists_every_command_and_option():
    """Reference: the argparse parser ``ambseal`` runs (ambseal.cli); every command and
    every option string of every command is on the page."""
    import argparse

    page = ref.cli_rst()
    parser = ref._parser()
    subs = ref._subparsers(parser)
    assert set(subs) == ref.cli_commands() and len(subs) >= 11
    for name, sub in subs.items():
        assert f"ambseal {name}\n" in page
        for action in sub._actions:
            if isinstance(action, argparse._HelpAction):
                continue
            for opt in action.option_strings:
                assert f"``{opt}" in page or f", {opt}" in page, (name, opt)


@pytest.mark.parametrize("exists", [False, True])
def test_the_schema_page_renders_a_schema_only_when_shipped(exists, tmp_path):
    """Without the file the page says it is coming and invents nothing; with one, it lists
    the file's properties (a two-key schema written here)."""
    path = tmp_path / "metrics.schema.json"
    if exists:
        path.write_text('{"type": "object", "required": ["rig"], "properties": {"rig": '
                        '{"type": "string", "description": "the rig file"}, "cases": '
                        '{"type": "array", "items": {"type": "object", "properties": '
                        '{"stable": {"type": "boolean"}}}}}}', encoding="utf-8")
    text = ref.json_schema_rst(path, "src/ambseal/data/metrics.schema.json")
    if exists:
        assert "``rig``" in text and "``cases[].stable``" in text and "(required)" in text
    else:
        assert "Not shipped yet" in text and "``" not in text.split("Not shipped yet")[0][:20]

"""The metrics.json schema shipped in the package is the one the result types give (the
embedded run, the turboexpander and every example validate against it in their tests)."""

import json

from ambseal.app.metrics import SCHEMA_PATH, SCHEMA_VERSION, schema_text


def test_the_shipped_schema_is_the_one_the_types_give():
    """The file a user reads cannot drift from the code that writes metrics.json
    (regenerate with ``ambseal.app.metrics.schema_text()``)."""
    assert SCHEMA_PATH.read_text(encoding="utf-8") == schema_text()
    assert json.loads(schema_text())["properties"]["schema_version"]["const"] == SCHEMA_VERSION

"""Validation of a metrics.json document against the JSON Schema shipped in the package."""

import json

import jsonschema

from ambseal.app.metrics import SCHEMA_PATH


def validate_metrics(metrics: dict) -> None:
    """Raise jsonschema.ValidationError unless ``metrics`` fits the shipped schema."""
    schema = json.loads(SCHEMA_PATH.read_text(encoding="utf-8"))
    jsonschema.Draft202012Validator.check_schema(schema)
    jsonschema.Draft202012Validator(schema).validate(metrics)

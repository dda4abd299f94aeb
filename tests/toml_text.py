"""TOML text of a rig dict, for tests that edit the example rigs (tomllib only reads)."""

import json
import math
import re


def _key(k: str) -> str:
    return k if re.fullmatch(r"[A-Za-z0-9_-]+", k) else json.dumps(k)


def _toml(v) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, str):
        return json.dumps(v)  # JSON's string escapes are TOML basic-string escapes
    if isinstance(v, float) and not math.isfinite(v):
        return "nan" if v != v else ("inf" if v > 0 else "-inf")
    if isinstance(v, dict):
        return "{ " + ", ".join(f"{_key(k)} = {_toml(x)}" for k, x in v.items()) + " }"
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_toml(x) for x in v) + "]"
    return repr(v)


def dump(data: dict) -> str:
    """A rig dict as TOML: scalars first, then tables (nested tables inline) and arrays of
    tables; reads back equal with tomllib."""
    head, tables = [], []
    for key, val in data.items():
        if isinstance(val, list) and val and all(isinstance(i, dict) for i in val):
            for item in val:
                tables += [f"[[{_key(key)}]]"]
                tables += [f"{_key(k)} = {_toml(x)}" for k, x in item.items()]
        elif isinstance(val, dict):
            tables += [f"[{_key(key)}]"] + [f"{_key(k)} = {_toml(x)}" for k, x in val.items()]
        else:
            head.append(f"{_key(key)} = {_toml(val)}")
    return "\n".join(head + tables) + "\n"

"""The project's own exceptions.

Every error raised on bad input names the file, key or column and what was expected; the
CLI turns an :class:`AmbsealError` into one line on stderr and exit code 2.
"""

from __future__ import annotations

__all__ = ["AmbsealError", "ConfigError", "DataError", "ModelError", "IdentificationError",
           "SynthesisError", "describe_validation_error", "PRIMITIVE_TAGS", "NAME_PATTERN",
           "LABEL_PATTERN", "with_source"]


class AmbsealError(Exception):
    """Base class of every error ambseal raises on purpose."""


class ConfigError(AmbsealError, ValueError):
    """A rig file is missing a key, has a wrong type or an inconsistent value."""


class DataError(AmbsealError, ValueError):
    """A measurement file is malformed (non-uniform time, NaN, wrong channels, ...)."""


class ModelError(AmbsealError, ValueError):
    """A model cannot be built or reduced as asked."""


class IdentificationError(AmbsealError):
    """A parameter fit failed or did not converge."""


class SynthesisError(AmbsealError):
    """A controller cannot be synthesised (unstabilisable plant, rank-deficient D12, ...)."""


#: Type names pydantic puts into an error's location for the branches of a union.
PRIMITIVE_TAGS = {"float", "int", "str", "bool", "list[float]", "tuple[float, float]"}
#: A name that becomes part of parameter, signal and C names (``A.Ki_zeta``): a C identifier.
NAME_PATTERN = r"^[A-Za-z_][A-Za-z0-9_]*$"
#: A label (free text shown in reports): one line, no control characters.
LABEL_PATTERN = r"^[^\x00-\x1f\x7f]*$"
_PATTERNS = {NAME_PATTERN: "a name of ASCII letters, digits and '_' that does not start with "
             "a digit (it makes parameter, signal and C names)",
             LABEL_PATTERN: "text on one line (no control characters)"}


#: Prefixes of the branch names pydantic gives a constrained number or a validator.
_BRANCH_PREFIXES = ("function-", "constrained-")


def _loc(loc: tuple, tags: set[str]) -> str:
    out = ""
    for part in loc:
        if isinstance(part, int):
            out += f"[{part}]"
        elif part in tags or "[" in str(part) or str(part).startswith(_BRANCH_PREFIXES):
            continue  # union branch names that pydantic inserts
        else:
            out += ("." if out else "") + str(part)
    return out or "(top level)"


def _pick_error(exc, tags: set[str]) -> dict:
    """The error that says what is wrong: at the first failing key, in the union branch
    the value was meant for (a table is not a number: the branch with the fewest errors
    among the tables; a number: its own branch)."""
    errs = exc.errors()
    where = _loc(errs[0]["loc"], tags)
    same = [e for e in errs if _loc(e["loc"], tags).startswith(where.split(".")[0])]
    branches: dict[tuple, list] = {}
    for e in same:
        tag = next((p for p in e["loc"] if p in tags or str(p).startswith("constrained-")),
                   None)
        number = tag in PRIMITIVE_TAGS or str(tag).startswith("constrained-")
        if number and isinstance(e.get("input"), (dict, list)):
            continue  # the value is a table: the number branch's complaint is beside the point
        branches.setdefault(tag, []).append(e)
    if not branches:
        return errs[0]
    # a branch whose keys all fit (only its values are wrong) before one of another shape
    shape = ("extra_forbidden", "missing", "model_type", "dict_type")
    return min(branches.values(), key=lambda es: (sum(e["type"] in shape for e in es),
                                                  len(es)))[0]


_BOUNDS = {"greater_than": ">", "greater_than_equal": ">=", "less_than": "<",
           "less_than_equal": "<="}


def describe_validation_error(exc, tags: set[str]) -> str:
    """``key.path: what was expected`` for the error of a pydantic ``ValidationError`` that
    matters (:func:`_pick_error`); ``tags`` are the union branch names to leave out of the
    key path (model class names and ``PRIMITIVE_TAGS``)."""
    err = _pick_error(exc, tags)
    kind, msg, value = err["type"], err["msg"], err.get("input")
    if kind == "missing":
        msg = "missing required key"
    elif kind == "extra_forbidden":
        msg = "unknown key (not part of the format; check its spelling)"
    elif kind in ("float_type", "int_type", "string_type", "bool_type") and not isinstance(
            value, (dict, list)):
        want = {"float_type": "a number", "int_type": "an integer",
                "string_type": "a string", "bool_type": "true or false"}[kind]
        msg = f"expected {want}, got {type(value).__name__} {value!r}"
    elif kind == "finite_number":
        msg = f"expected a finite number, got {value!r}"
    elif kind in _BOUNDS:
        limit = next(iter(err.get("ctx", {}).values()), "?")
        msg = f"expected a value {_BOUNDS[kind]} {limit}, got {value!r}"
    elif kind in ("model_type", "dict_type", "model_attributes_type"):
        msg = f"expected a table, got {type(value).__name__} {value!r}"
    elif kind in ("list_type", "tuple_type"):
        msg = f"expected an array, got {type(value).__name__} {value!r}"
    elif kind == "string_pattern_mismatch":
        pattern = err.get("ctx", {}).get("pattern")
        msg = f"expected {_PATTERNS.get(pattern, f'text matching {pattern}')}, got {value!r}"
    elif msg.startswith("Value error, "):
        msg = msg[len("Value error, "):]
    return f"{_loc(err['loc'], tags)}: {msg}"


def with_source(exc: AmbsealError, files: list, source: str) -> AmbsealError:
    """``exc`` with ``source: `` in front unless its message names one of ``files``.

    Parameters
    ----------
    exc : AmbsealError
    files : list of str or path-like
        The files the command read or wrote (None entries are skipped).
    source : str
        What to name when the message names none of ``files``.

    Returns
    -------
    AmbsealError
        ``exc`` itself, or a new error of its type with the source in front.
    """
    msg = str(exc)
    if any(str(f) in msg for f in files if f):
        return exc
    return type(exc)(f"{source}: {msg}")

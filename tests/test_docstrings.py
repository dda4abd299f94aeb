"""The public faces' docstrings pass numpydoc's checks (``[tool.numpydoc_validation]``).

Every class and function a package exports (``__all__`` of each layer's ``__init__.py``) is
validated by ``numpydoc.validate.validate``; the checks, the excluded names and the
overrides are read from ``pyproject.toml`` with the meaning ``numpydoc lint`` gives them, so
the table there is the one statement of the rule. Constants and type aliases in ``__all__``
have no docstring of their own and are not validated.
"""

from __future__ import annotations

import importlib
import importlib.util
import inspect
import re
import sys
import tomllib
import types
from dataclasses import dataclass
from pathlib import Path

import pytest
from numpydoc.docscrape import get_doc_object
from numpydoc.validate import get_validation_checks, validate

ROOT = Path(__file__).resolve().parents[1]
FACES = ["lti", "robust", "machine", "config", "model", "identify", "design", "analysis",
         "report", "export", "io", "app"]
#: Public modules that are a face of their own (no package around them).
MODULE_FACES = ["threads"]
#: Public names that share their module's name and are kept (part of a published face); the
#: module is then reached by its dotted name (``from ambseal.machine.scheduled_digital
#: import …``), not as the package's attribute.
HIDING = {"ambseal.machine.scheduled_digital"}

_TABLE = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))[
    "tool"]["numpydoc_validation"]
CHECKS = get_validation_checks(set(_TABLE["checks"]))
EXCLUDE = [re.compile(p) for p in _TABLE.get("exclude", [])]
OVERRIDES = {key.removeprefix("override_").upper(): [re.compile(p) for p in patterns]
             for key, patterns in _TABLE.items() if key.startswith("override_")}


def _public(face: str) -> list[tuple[str, object]]:
    """(name in the face, object) of every class and function in ``ambseal.<face>``."""
    module = importlib.import_module(f"ambseal.{face}")
    objects = [(f"ambseal.{face}.{name}", getattr(module, name)) for name in module.__all__]
    return [(name, obj) for name, obj in objects
            if inspect.isclass(obj) or inspect.isfunction(obj)]


def _documented(obj) -> set[str]:
    """Names under Parameters and Attributes (``a, b : float`` names two); for a class, also
    those its base classes document (the fields a dataclass inherits)."""
    package = obj.__module__.split(".")[0]
    owners = [c for c in inspect.getmro(obj) if c.__module__.split(".")[0] == package] \
        if inspect.isclass(obj) else [obj]
    return {n.strip().lstrip("*") for owner in owners
            for section in ("Parameters", "Attributes")
            for p in get_doc_object(owner)[section] for n in p.name.split(",")}


def _signature(obj) -> set[str]:
    """The constructor's or the function's parameters; none of a protocol, which is never
    constructed (its signature is typing's ``*args, **kwargs``)."""
    if getattr(obj, "_is_protocol", False):
        return set()
    try:
        return set(inspect.signature(obj).parameters)
    except (TypeError, ValueError):
        return set()


def problems(name: str, obj) -> list[str]:
    """The findings of the configured checks on one public name, as ``name: CODE message``."""
    defined = f"{obj.__module__}.{obj.__qualname__}"
    if any(p.search(defined) or p.search(name) for p in EXCLUDE):
        return []
    docstring = inspect.cleandoc(obj.__doc__ or "")
    out = []
    for code, message in validate(name)["errors"]:
        if code not in CHECKS:
            continue
        if any(p.search(docstring) for p in OVERRIDES.get(code, [])):
            if code == "PR01":  # the Attributes rule: every parameter must be named there
                missing = _signature(obj) - _documented(obj)
                if missing:
                    out.append(f"{name}: PR01 {sorted(missing)} under neither Parameters "
                               "nor Attributes")
            continue
        out.append(f"{name}: {code} {message}")
    return out


@pytest.mark.parametrize("face", FACES + MODULE_FACES)
def test_the_public_names_are_documented(face):
    """Reference: numpydoc's docstring standard; pyproject.toml says which checks and why."""
    found = [line for name, obj in _public(face) for line in problems(name, obj)]
    assert found == [], "\n".join(found)


@pytest.mark.parametrize("face", FACES)
def test_no_public_name_hides_a_module(face):
    """A function exported under its module's name would replace the module as the
    package's attribute (``import ambseal.model.modes as m`` would give the function)."""
    module = importlib.import_module(f"ambseal.{face}")
    hidden = [f"ambseal.{face}.{name}" for name in module.__all__
              if importlib.util.find_spec(f"ambseal.{face}.{name}") is not None]
    hidden = [name for name in hidden if name not in HIDING]
    assert hidden == []


def test_the_checks_see_what_they_are_for(monkeypatch):
    """The rule can fail: a function with no Returns section and an undocumented parameter,
    a class without a docstring, and a dataclass naming one field of two under Attributes
    are each found (so the tests above are not vacuous)."""
    fake = types.ModuleType("ambseal_fake_face")

    def area(width, height):
        """Area of a rectangle.

        Parameters
        ----------
        width : float
            Width, m.
        """
        return width * height

    class Bare:
        pass

    @dataclass
    class Pair:
        """Two numbers.

        Attributes
        ----------
        a : float
            The first, m.
        """

        a: float
        b: float

    for obj in (area, Bare, Pair):
        obj.__module__, obj.__qualname__ = fake.__name__, obj.__name__
        setattr(fake, obj.__name__, obj)
    monkeypatch.setitem(sys.modules, fake.__name__, fake)
    codes = {n: [line.split()[1] for line in problems(f"{fake.__name__}.{n}", getattr(fake, n))]
             for n in ("area", "Bare", "Pair")}
    assert codes == {"area": ["PR01", "RT01"], "Bare": ["GL08"], "Pair": ["PR01"]}
    assert {"GL08", "PR01", "RT01"} <= CHECKS

"""ambseal.io: other tools' formats in and out — :mod:`ambseal.io.ross` (ROSS rotors in).

* :func:`import_ross_file` — a ROSS rotor file as an ambseal rig file.

The names load on first use (PEP 562 ``__getattr__``, as :mod:`ambseal.identify` does), so
``import ambseal.io`` imports nothing heavy.
"""

import importlib

#: Each public name (``__all__``) and the module that defines it.
_FROM = {"import_ross_file": "ross"}

__all__ = sorted(_FROM)


def __getattr__(name: str):
    """Import a public name from its module on first use (PEP 562)."""
    if name not in _FROM:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = getattr(importlib.import_module(f"{__name__}.{_FROM[name]}"), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    """The module's names, the lazily loaded ones included."""
    return sorted(set(globals()) | set(__all__))

"""ambseal.io: other tools' formats in and out — :mod:`ambseal.io.ross` (ROSS rotors in).

* :func:`import_ross_file` — a ROSS rotor file as an ambseal rig file.

The names load on first use (PEP 562 ``__getattr__``, ``ambseal.lazy.lazy_face``), so
``import ambseal.io`` imports nothing heavy.
"""

from ambseal.lazy import lazy_face

#: Each public name (``__all__``) and the module that defines it.
_FROM = {"import_ross_file": "ross"}

__all__ = sorted(_FROM)

__getattr__, __dir__ = lazy_face(__name__, _FROM)

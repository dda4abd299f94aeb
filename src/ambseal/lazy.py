"""A package face whose public names load on first use (PEP 562 module ``__getattr__``).

A face that imported its modules eagerly would load their heavy dependencies with the
package: ``import ambseal.report`` would load matplotlib, ``ambseal --help`` the numerics of
every command, ``ambseal modes`` python-control. The faces of :mod:`ambseal.lti`,
:mod:`ambseal.model`, :mod:`ambseal.robust`, :mod:`ambseal.analysis`,
:mod:`ambseal.identify`, :mod:`ambseal.io`, :mod:`ambseal.report` and :mod:`ambseal.app`
list each public name with the module that defines it and load it when it is first asked
for.
"""

from __future__ import annotations

import importlib
import sys
from collections.abc import Callable, Mapping

__all__ = ["lazy_face"]


def lazy_face(package: str, sources: Mapping[str, str]
              ) -> tuple[Callable[[str], object], Callable[[], list[str]]]:
    """The module ``__getattr__`` and ``__dir__`` of a package face whose names load on
    first use.

    Parameters
    ----------
    package : str
        The package's name (its ``__name__``).
    sources : mapping of str to str
        Each public name → the module of ``package`` that defines it (``"run_report"``
        for ``package.run_report``).

    Returns
    -------
    (__getattr__, __dir__)
        ``__getattr__(name)`` imports ``name`` from its module, keeps it in the package's
        namespace (the next lookup does not come back) and returns it; it raises
        ``AttributeError`` for a name not in ``sources``. ``__dir__()`` lists the
        package's names, the names not yet loaded included.
    """

    def __getattr__(name: str) -> object:
        if name not in sources:
            raise AttributeError(f"module {package!r} has no attribute {name!r}")
        value = getattr(importlib.import_module(f"{package}.{sources[name]}"), name)
        setattr(sys.modules[package], name, value)
        return value

    def __dir__() -> list[str]:
        return sorted(set(vars(sys.modules[package])) | set(sources))

    return __getattr__, __dir__

"""The controller methods, named once: what every layer lists, labels, colours or asks of
a kind of controller.

The rig file's ``[design.<name>]`` sections, the CLI's ``--method`` choices, the designs
and remedies of ``ambseal run``, the names in messages and reports and the colours of the
figures all read :data:`METHODS`. A method's design lives in :mod:`ambseal.design`; what the
other layers need to know of it is here.
"""

from __future__ import annotations

from dataclasses import dataclass

from ambseal.errors import ConfigError

__all__ = ["Method", "METHODS", "method", "method_label", "method_names"]


@dataclass(frozen=True)
class Method:
    """One controller method.

    Attributes
    ----------
    name : str
        Its key: ``--method``, ``[design.<name>]``, ``metrics.json`` ``controllers``.
    label : str
        How messages and reports name it.
    colour : str or None
        Its colour in every figure (matplotlib hex); None: the next free one of the
        report's palette.
    fixed : bool
        Designed by :func:`ambseal.design.recipes.design`: one linear time-invariant
        controller for one operating condition (``ambseal run`` designs every such one).
    synthesised : bool
        Synthesised on a generalised plant (H∞, μ; thesis P5 §4): its discretisation keeps
        the rise of its design loop's bound in view, and ``ambseal run`` tries remedies
        (:mod:`ambseal.app.remedies`) where its full-order loop fails.
    option : bool
        A choice of ``ambseal design --method`` and ``ambseal export --method``.
    robust : bool
        Synthesised against the specification's uncertain parameters (μ, thesis P5 §4.3):
        on the perturbed plant, judged by μ on a frequency grid; the method ``ambseal run``
        names as the robust controller.
    """

    name: str
    label: str
    colour: str | None
    fixed: bool
    synthesised: bool
    option: bool
    robust: bool = False


#: Every method, in the order runs design them and reports list them. The colours are the
#: first of matplotlib's tab10 cycle, the same for a method in every report.
METHODS: tuple[Method, ...] = (
    Method("pid", "PID", "#1f77b4", fixed=True, synthesised=False, option=True),
    Method("hinf", "H∞", "#d62728", fixed=True, synthesised=True, option=True),
    Method("mu", "μ", "#2ca02c", fixed=True, synthesised=True, option=True, robust=True),
    Method("lpv", "LPV", "#9467bd", fixed=False, synthesised=False, option=True),
    Method("tracked", "tracked", None, fixed=False, synthesised=False, option=False),
)
_BY_NAME = {m.name: m for m in METHODS}


def method(name: str) -> Method:
    """The method called ``name``.

    Parameters
    ----------
    name : str
        A method's key (``"pid"``, ``"hinf"``, ...).

    Returns
    -------
    Method

    Raises
    ------
    ConfigError
        No method has that name (the known names listed).
    """
    try:
        return _BY_NAME[name]
    except KeyError:
        raise ConfigError(f"method {name!r}: expected one of "
                          f"{', '.join(_BY_NAME)}") from None


def method_label(name: str) -> str:
    """How messages and reports name the controller ``name``: its method's label, or the
    name itself for a controller that is no method's (e.g. a user's file).

    Parameters
    ----------
    name : str
        A controller's name.

    Returns
    -------
    str
    """
    m = _BY_NAME.get(name)
    return m.label if m is not None else name


def method_names(*, fixed: bool | None = None, synthesised: bool | None = None,
                 option: bool | None = None, robust: bool | None = None) -> tuple[str, ...]:
    """The names of the methods with the given properties (None: either), in
    :data:`METHODS`' order.

    Parameters
    ----------
    fixed, synthesised, option, robust : bool or None
        Properties of :class:`Method` to select on.

    Returns
    -------
    tuple of str
    """
    want = {"fixed": fixed, "synthesised": synthesised, "option": option, "robust": robust}
    return tuple(m.name for m in METHODS
                 if all(v is None or getattr(m, k) == v for k, v in want.items()))

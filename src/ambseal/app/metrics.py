"""``metrics.json``: the main job's results as one typed document, and its JSON Schema.

:class:`RunMetrics` is what ``ambseal run`` writes (:meth:`RunMetrics.to_dict`); every
document carries :data:`SCHEMA_VERSION`, and the JSON Schema of the document
(:func:`metrics_schema`, generated from these types by pydantic) ships in the package as
``ambseal/data/metrics.schema.json`` so that a user's script can check a file before it
reads it. The version follows the document: a key added raises the minor version, a key
moved or removed the major one.

The cases are :class:`ambseal.analysis.judge.JudgedCase`; the parts that follow the rig's
design policy (``design_spec``, the controllers' design summaries, the identification) are
typed at their first level, where a script finds its way.
"""

from __future__ import annotations

import json
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

from pydantic import TypeAdapter

from ambseal.analysis import FailedController, JudgedCase, StabilityCase

__all__ = ["SCHEMA_VERSION", "SCHEMA_PATH", "OpenLoop", "ControllerSummary", "RunMetrics",
           "metrics_schema", "schema_text"]

#: Version of the ``metrics.json`` document (module docstring).
SCHEMA_VERSION = "1.6.0"
#: The JSON Schema shipped with the package.
SCHEMA_PATH = Path(__file__).resolve().parents[1] / "data" / "metrics.schema.json"


@dataclass(frozen=True)
class OpenLoop:
    """The rig's open loop.

    Attributes
    ----------
    unstable_poles : list of [float, float]
        Real and imaginary parts (rad/s) of the open-loop poles that are not stable.
    n_states_full, n_states_reduced : int
        States of the full-order model and of its modal reduction.
    """

    unstable_poles: list[list[float]]
    n_states_full: int
    n_states_reduced: int


@dataclass(frozen=True)
class ControllerSummary:
    """A designed controller's summary (the keys every method has; each method adds its
    own, e.g. ``mu``, ``reduction`` or an LPV design's ``speeds_hz``).

    Attributes
    ----------
    method : str
        ``pid``, ``hinf``, ``mu``, ``lpv`` or ``tracked``.
    gamma : float or None
        H∞ norm of the design loop (-); None for the PID.
    order : int
        Controller states.
    elapsed_s : float
        Design time (s).
    full_order : dict or None
        The design's own check on the full-order plant (``stable``, the least stable
        condition and mode).
    weights : dict or None
        The weights it was designed with.
    discretisation : dict or None
        The controller that runs on the target (method, sample rate, the candidates
        judged); None when it cannot run there (``cannot_run`` says why).
    """

    method: str
    gamma: float | None
    order: int
    elapsed_s: float
    full_order: dict[str, Any] | None
    weights: dict[str, Any] | None
    discretisation: dict[str, Any] | None
    #: The method's own keys, written beside the ones above.
    details: dict[str, Any] = field(default_factory=dict)

    @classmethod
    def from_dict(cls, d: dict) -> ControllerSummary:
        """From a design summary (``DesignResult.summary()`` and its kin, with its
        ``discretisation``): the common keys typed, the others kept in ``details``."""
        common = {f: d.get(f) for f in ("method", "gamma", "order", "elapsed_s",
                                         "full_order", "weights", "discretisation")}
        return cls(**common, details={k: v for k, v in d.items() if k not in common})

    def to_dict(self) -> dict:
        """The summary as written (the method's own keys beside the common ones)."""
        return {"method": self.method, "gamma": self.gamma, "order": self.order,
                "elapsed_s": self.elapsed_s, "full_order": self.full_order,
                "weights": self.weights, "discretisation": self.discretisation,
                **self.details}


@dataclass(frozen=True)
class SignoffCriterion:
    """One criterion of a controller's sign-off.

    Attributes
    ----------
    criterion : str
        ``stability, Level I``, ``stability, Level II``, ``separation margins``,
        ``vibration at the probes``, ``close clearances`` or ``vibration zone``.
    value, limit : str
        Its value and its limit, in words with their units.
    source : str
        The standard, edition and clause.
    passed : bool
    counts : bool
        Whether it decides the verdict (the stability is Level I's where it passes and
        the loop with every source is stable, else Level II's).
    graded : bool
        Whether it was graded at all (``value`` says why not; ``passed`` is then false).
    outcome : str
        ``passed``, ``FAILED``, ``not graded``, ``not needed`` or ``Level II decides``:
        what the command line and the report print.
    """

    criterion: str
    value: str
    limit: str
    source: str
    passed: bool
    counts: bool
    graded: bool
    outcome: str


@dataclass(frozen=True)
class SignoffController:
    """One controller's sign-off (:class:`ambseal.analysis.signoff.SignOff`).

    Attributes
    ----------
    passed : bool
        Every criterion that counts passed.
    criteria : list of SignoffCriterion
    level1, level2, unbalance, iso14839_2 : dict
        The analyses: :meth:`ambseal.analysis.signoff.level1.Level1.to_dict`,
        :meth:`ambseal.analysis.signoff.level2.Level2.to_dict`,
        :meth:`ambseal.analysis.signoff.unbalance_api617.Api617Unbalance.to_dict`,
        :meth:`ambseal.analysis.signoff.iso_vibration.IsoVibration.to_dict`.
    """

    passed: bool
    criteria: list[SignoffCriterion]
    level1: dict[str, Any]
    level2: dict[str, Any]
    unbalance: dict[str, Any]
    iso14839_2: dict[str, Any]


@dataclass(frozen=True)
class Signoff:
    """The machine's sign-off: API 617 and ISO 14839-2 per delivered controller.

    Attributes
    ----------
    passed : bool
        Every controller passed.
    verdict : str
        The one line a manager reads first.
    controllers : dict of str to SignoffController
    """

    passed: bool
    verdict: str
    controllers: dict[str, SignoffController]

    @classmethod
    def of(cls, results, verdict: str) -> "Signoff":
        """From :class:`ambseal.analysis.signoff.SignOff` results and their verdict."""
        return cls(all(r.passed for r in results), verdict, {
            r.controller: SignoffController(
                r.passed, [SignoffCriterion(**c.to_dict()) for c in r.criteria],
                r.level1.to_dict(), r.level2.to_dict(), r.unbalance.to_dict(),
                r.iso14839_2.to_dict()) for r in results})


@dataclass(frozen=True)
class RunMetrics:
    """The document ``ambseal run`` writes as ``metrics.json``.

    Attributes
    ----------
    schema_version : str
        :data:`SCHEMA_VERSION`.
    rig, rig_name : str
        The rig file and its rotor's name.
    open_loop : OpenLoop
    unbalance : dict
        The unbalance the cases are judged with (ISO 21940-11 grade, law, speeds).
    design_spec : dict
        The design specification, every derived value with its rule (``sources``).
    controllers : dict of str to ControllerSummary
    cannot_run : dict of str to str
        Controllers that cannot run on the target, and why.
    cases : list of JudgedCase
        Every controller at every judged condition.
    stability : list of StabilityCase
        Every controller's loop at each judged pressure and each stability speed
        (standstill to the top speed) that is not a judged condition: stability only.
    failed : dict of str to FailedController
        Controllers whose judged loop is unstable at a judged condition or whose design
        failed, with the reason; a designed one is not delivered (not exported) unless the
        run allowed it. Empty when every controller passed.
    identification, spinup, ramp : dict, optional
        The identification on the virtual facility, the spin-up of a speed-scheduled rig,
        the pressure ramp of the tracked controller — when the run did them.
    signoff : Signoff, optional
        A rig with ``[[stage]]`` tables: the sign-off of each delivered controller as it
        runs (API 617 stability and unbalance response, ISO 14839-2).
    """

    schema_version: str
    rig: str
    rig_name: str
    open_loop: OpenLoop
    unbalance: dict[str, Any]
    design_spec: dict[str, Any]
    controllers: dict[str, ControllerSummary]
    cannot_run: dict[str, str]
    cases: list[JudgedCase]
    stability: list[StabilityCase] = field(default_factory=list)
    failed: dict[str, FailedController] = field(default_factory=dict)
    identification: dict[str, Any] | None = None
    spinup: dict[str, Any] | None = None
    ramp: dict[str, Any] | None = None
    signoff: Signoff | None = None

    def to_dict(self) -> dict:
        """The JSON document (sections the run did not do are left out)."""
        d = {"schema_version": self.schema_version, "rig": self.rig,
             "rig_name": self.rig_name,
             "open_loop": {"unstable_poles": self.open_loop.unstable_poles,
                           "n_states_full": self.open_loop.n_states_full,
                           "n_states_reduced": self.open_loop.n_states_reduced},
             "unbalance": self.unbalance, "design_spec": self.design_spec,
             "controllers": {k: v.to_dict() for k, v in self.controllers.items()},
             "cannot_run": self.cannot_run, "cases": [c.to_dict() for c in self.cases],
             "stability": [c.to_dict() for c in self.stability],
             "failed": {m: asdict(f) for m, f in self.failed.items()}}
        for key in ("identification", "spinup", "ramp"):
            if getattr(self, key) is not None:
                d[key] = getattr(self, key)
        if self.signoff is not None:
            d["signoff"] = asdict(self.signoff)
        return d


def _described(node: dict) -> None:
    """A type's description: its docstring's first paragraph; its properties' from the
    docstring's numpydoc ``Attributes`` section (``name : type`` then indented text)."""
    doc = node.get("description") or ""
    node["description"] = " ".join(doc.split("\n\n")[0].split())
    attrs = doc.split("Attributes\n----------\n", 1)[1] if "Attributes\n---" in doc else ""
    texts: dict[str, list[str]] = {}
    names: list[str] = []
    for line in attrs.splitlines():
        if line and not line.startswith(" "):
            names = [n.strip() for n in line.split(":")[0].split(",")]
            for n in names:
                texts[n] = []
        elif line.strip():
            for n in names:
                texts[n].append(line.strip())
    for name, prop in node.get("properties", {}).items():
        if texts.get(name):
            prop["description"] = " ".join(texts[name])


def metrics_schema() -> dict:
    """The JSON Schema (draft 2020-12) of :class:`RunMetrics`' JSON form."""
    schema = TypeAdapter(RunMetrics).json_schema(mode="serialization")
    for node in [schema, *schema["$defs"].values()]:
        _described(node)
    summary = schema["$defs"]["ControllerSummary"]  # details are written beside the rest
    summary["properties"].pop("details")
    summary["additionalProperties"] = True
    schema["$schema"] = "https://json-schema.org/draft/2020-12/schema"
    schema["title"] = "ambseal metrics.json"
    schema["properties"]["schema_version"]["const"] = SCHEMA_VERSION
    return schema


def schema_text() -> str:
    """:func:`metrics_schema` as the text shipped in :data:`SCHEMA_PATH`."""
    return json.dumps(metrics_schema(), indent=1, sort_keys=True) + "\n"

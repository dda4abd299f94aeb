"""The sign-off of a machine, in one place: API 617's stability and unbalance response and
ISO 14839-2's vibration zone, per controller as it runs (``ambseal signoff``, and the
sign-off of ``ambseal run``).

Read it in the order a rig goes through it:

1. :mod:`~ambseal.analysis.signoff.verdict` — :func:`sign_off` runs the four analyses
   below on one controller, grades each criterion passed, failed or not graded (with why)
   and says whether the machine is signed off (:class:`SignOff`, :func:`verdict_line`);
   the table of criteria, limits and clauses is its docstring.
2. :mod:`~ambseal.analysis.signoff.level1` — API 617 Level I: the stages' cross-coupling
   Q_A, the screened forward mode followed from Q = 0 to Q_0, the CSR on the
   rigid-support critical at standstill (:func:`level1_screening`).
3. :mod:`~ambseal.analysis.signoff.level2` — API 617 Level II: the log decrement with
   each source of cross-coupling added in turn, then all (:func:`level2_analysis`).
4. :mod:`~ambseal.analysis.signoff.unbalance_api617` — API 617's unbalance response:
   U_r from the journal loads, the placements per mode shape, the criticals with their
   amplification factors and separation margins, A_vl, the close clearances
   (:func:`api617_unbalance`).
5. :mod:`~ambseal.analysis.signoff.iso_vibration` — ISO 14839-2's zones at the AMB
   sensors against the backup clearance (:func:`iso14839_2_zones`).
6. :mod:`~ambseal.analysis.signoff.ucs_map` — API 684's undamped critical speed map,
   each controller's AMB stiffness at 1× on it (:func:`ucs_map`; the command's
   ``ucs_map.png``, informative: no criterion).

The closed-loop modes, log decrements and criticals they read are
:mod:`ambseal.analysis.campbell`'s, the synchronous response
:mod:`ambseal.analysis.synchronous`'s; the limits the standards' public text does not
confirm are ``[signoff]`` settings (:class:`ambseal.config.rig.Signoff`).

Each name loads its module on first use (:func:`ambseal.lazy.lazy_face`), as in
:mod:`ambseal.analysis`, whose face re-exports them.
"""

from ambseal.lazy import lazy_face

#: Each public name (``__all__``) and the module that defines it.
_FROM = {
    "sign_off": "verdict", "SignOff": "verdict", "verdict_line": "verdict",
    "critical_speeds_hz": "verdict",
    "level1_screening": "level1", "stage_cross_coupling": "level1", "Level1": "level1",
    "level2_analysis": "level2", "Level2": "level2",
    "api617_unbalance": "unbalance_api617", "Api617Unbalance": "unbalance_api617",
    "iso14839_2_zones": "iso_vibration", "IsoVibration": "iso_vibration",
    "ucs_map": "ucs_map", "UcsMap": "ucs_map", "undamped_criticals_hz": "ucs_map",
}

__all__ = sorted(_FROM)

__getattr__, __dir__ = lazy_face(__name__, _FROM)

"""Two runs' metrics.json compared as a user reads them: what must be the same on every
machine, and what may differ by how much.

A run's numbers differ between machines in their last digits (the BLAS kernels, the thread
count), and a synthesis that follows its path by rounding can deliver another controller.
What may not change is what a user sees:

* the delivered set: the controllers in ``controllers`` less those in ``failed`` and
  ``cannot_run``, and the failed and unrunnable ones with their reasons' words;
* every ISO 14839-3 zone (``iso_zone``, ``iso_zone_per_axis``, continuous and discrete,
  at every judged case and stability condition);
* every verdict's words (``verdict``, the design's ``steps`` and ``notes``, the reasons
  of ``failed`` and ``cannot_run``), with the numbers in them masked: a number printed in
  a sentence is the same number as the one its key holds, compared below;
* the numbers, each within its stated relative tolerance (:data:`RTOL`, keyed by name).

Numbers not listed in :data:`RTOL` (iteration counts, controller orders, poles, CPU
times, discretisation and reduction internals) are a design's path, not what it
delivers, and are not compared.
"""

from __future__ import annotations

import re
from typing import Any

#: Relative tolerance of each compared number, by its key's name: μ and γ 2 %, σ̄(S_o)
#: peaks 5 %, orbits and currents 5 %.
RTOL = {
    "mu": 0.02,
    "gamma": 0.02,
    "sensitivity_peak": 0.05,
    "unbalance_peak_um": 0.05,
    "impulse_peak_um": 0.05,
    "current_used": 0.05,
    "bias_used": 0.05,
    "current_a": 0.05,
    "current_limit_a": 0.05,
}
#: Per-axis tables whose every value is graded by the tolerance of the key named here.
PER_AXIS = {"sensitivity_peak_per_axis": "sensitivity_peak"}
#: Strings compared exactly.
EXACT = {"iso_zone", "controller", "label"}
#: Zone tables compared value by value, exactly.
EXACT_TABLES = {"iso_zone_per_axis"}
#: Sentences compared word for word, numbers masked.
WORDS = {"verdict", "steps", "notes", "sdp_shortfall"}
#: Subtrees that hold a design's path or its inputs, not what it delivers (an LPV's
#: ``sdp_status`` is where each SDP stopped, which its ``sdp_shortfall`` puts in words).
SKIP = {"design_spec", "weights", "discretisation", "reduction", "stopping", "history",
        "full_order", "delay", "uncertainty", "sizing", "worst", "sdp_status"}

_NUMBER = re.compile(r"[-+−]?(?:\d+(?:[.,]\d+)*)(?:[eE][-+]?\d+)?")


def words(text: str) -> str:
    """``text`` with every number replaced by ``#``."""
    return _NUMBER.sub("#", str(text))


def delivered(metrics: dict) -> list[str]:
    """The controllers a run delivers: designed or given, judged, not failed, runnable."""
    out = set(metrics.get("controllers") or {})
    out -= set(metrics.get("failed") or {})
    out -= set(metrics.get("cannot_run") or {})
    return sorted(out)


def _rel(a: float, b: float) -> float:
    scale = max(abs(a), abs(b))
    return 0.0 if scale == 0 else abs(a - b) / scale


def _number(path: str, key: str, a: Any, b: Any, out: list, seen: dict | None) -> None:
    if a is None or b is None:
        if (a is None) != (b is None):
            out.append(f"{path}: {a!r} against {b!r}")
        return
    d = _rel(float(a), float(b))
    if seen is not None:
        seen[key] = max(seen.get(key, 0.0), d)
    if d > RTOL[key]:
        out.append(f"{path}: {a:.6g} against {b:.6g} ({100 * d:.2f} % > "
                   f"{100 * RTOL[key]:g} %)")


def _sentences(path: str, a: Any, b: Any, out: list) -> None:
    la = a if isinstance(a, list) else [a]
    lb = b if isinstance(b, list) else [b]
    if len(la) != len(lb) or any(words(x) != words(y) for x, y in zip(la, lb)):
        out.append(f"{path}: words differ:\n    {la!r}\n    {lb!r}")


def _walk(path: str, a: Any, b: Any, out: list, seen: dict | None = None) -> None:
    if isinstance(a, dict) and isinstance(b, dict):
        for key in sorted(set(a) | set(b)):
            p = f"{path}/{key}"
            if key in SKIP:
                continue
            if (key in a) != (key in b):
                out.append(f"{p}: present in one run only")
                continue
            x, y = a[key], b[key]
            if key in RTOL and not isinstance(x, (dict, list)):
                _number(p, key, x, y, out, seen)
            elif key in PER_AXIS:
                if set(x or {}) != set(y or {}):
                    out.append(f"{p}: axes {sorted(x or {})} against {sorted(y or {})}")
                else:
                    for axis in sorted(x or {}):
                        _number(f"{p}/{axis}", PER_AXIS[key], x[axis], y[axis], out, seen)
            elif key in EXACT or key in EXACT_TABLES:
                if x != y:
                    out.append(f"{p}: {x!r} against {y!r}")
            elif key in WORDS:
                _sentences(p, x, y, out)
            else:
                _walk(p, x, y, out, seen)
    elif isinstance(a, list) and isinstance(b, list):
        if len(a) != len(b):
            if any(isinstance(v, dict) for v in a + b):
                out.append(f"{path}: {len(a)} entries against {len(b)}")
            return
        for i, (x, y) in enumerate(zip(a, b)):
            _walk(f"{path}[{i}]", x, y, out, seen)


def differences(a: dict, b: dict, seen: dict | None = None) -> list[str]:
    """What differs between two runs' metrics.json beyond the stated tolerances, one line
    each (empty: the same delivered answer).

    Parameters
    ----------
    a, b : dict
        The two runs' ``metrics.json``, loaded.
    seen : dict, optional
        Filled with the largest relative difference found under each key of
        :data:`RTOL` (benchmarks/bench_tolerances.py's table), within tolerance or not.

    Returns
    -------
    list of str
    """
    out: list[str] = []
    if delivered(a) != delivered(b):
        out.append(f"delivered: {delivered(a)} against {delivered(b)}")
    for key in ("failed", "cannot_run"):
        fa, fb = a.get(key) or {}, b.get(key) or {}
        if set(fa) != set(fb):
            out.append(f"{key}: {sorted(fa)} against {sorted(fb)}")
        for m in sorted(set(fa) & set(fb)):
            _sentences(f"/{key}/{m}", _reason(fa[m]), _reason(fb[m]), out)
    for key in ("controllers", "cases", "stability"):
        _walk(f"/{key}", a.get(key), b.get(key), out, seen)
    return out


def _reason(entry: Any) -> Any:
    """The sentence of a ``failed``/``cannot_run`` entry (a string, or a dict with one)."""
    if isinstance(entry, dict):
        return entry.get("reason", entry)
    return entry

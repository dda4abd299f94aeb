"""The candidates of :func:`ambseal.robust.digital.choose_method` judged (private
module): the σ̄(S_o) peak of a loop from frequency responses, and the sampled loops closed
in the order of the candidates' errors until one is stable wherever the design is (module
docstring of :mod:`ambseal.robust.digital`, step 3; Franklin, Powell & Workman, *Digital
Control of Dynamic Systems*, 3rd ed., ch. 6)."""

from __future__ import annotations

import numpy as np

from ambseal.lti import feedback_poles

Matrices = tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]


def so_peak(Gw: np.ndarray, Kw: np.ndarray) -> float:
    """Grid peak of σ̄((I + G K)⁻¹) from stacks of responses (n_w, ny, nu), (n_w, nu, ny)."""
    ny = Gw.shape[1]
    eye = np.broadcast_to(np.eye(ny), Gw.shape[:1] + (ny, ny))
    S = np.linalg.solve(np.eye(ny) + Gw @ Kw, eye)
    return float(np.max(np.linalg.svd(S, compute_uv=False)[:, 0]))


def max_abs_z(G: Matrices, Kd: Matrices, T: float) -> float:
    """Largest |z| of the loop of ``Kd`` and the continuous ``G`` sampled by a zero-order
    hold at ``T`` (s) (:func:`~ambseal.lti.interconnect.feedback_poles`: kept for the
    judgement of the same loop)."""
    return float(np.abs(feedback_poles(G, Kd, hold=T)).max())


def first_stable(cands: list, Kd: dict, plants: list, T: float, cont_stable: list
                 ) -> dict | None:
    """The chosen candidate of :func:`~ambseal.robust.digital.choose_method`.

    ``cands`` are taken by increasing ``sensitivity_peak_error`` (a stable sort: the order
    of ``methods`` on a tie, NaN last), each closed with every sampled plant
    (``max_abs_z``), until one is stable wherever the design is: the smallest error among
    the stable candidates, as if all were closed.

    Parameters
    ----------
    cands : list of dict
        The candidates' rows (``method``, ``sensitivity_peak``, ``..._continuous``,
        ``sensitivity_peak_error``), filled in place: ``max_abs_z`` and ``stable`` of those
        closed; of one found unstable, its peaks where its loop is stable only and its
        error over those (``inf`` if none); ``not_checked`` (the reason) of those after the
        chosen one, whose ``stable`` and ``max_abs_z`` stay ``None``.
    Kd : dict
        method → (discrete controllers, the same delayed), one per plant.
    plants : list of (A, B, C, D)
        The continuous plants, each sampled by a zero-order hold.
    T : float
        Sample time (s).
    cont_stable : list of bool
        Where the design's continuous loop is stable (where the sampled one must be).

    Returns
    -------
    dict or None
        The chosen row, ``None`` if no candidate is stable where it must be.
    """
    def key(c):
        e = c["sensitivity_peak_error"]
        return e if e == e else float("inf")

    best = None
    for c in sorted(cands, key=key):
        if best is not None:
            c["not_checked"] = (
                f"σ̄(S_o) peak error {key(c):.4g} is not below the chosen {best['method']}'s "
                f"{key(best):.4g}: it cannot be chosen, so its sampled loops' poles were not "
                "computed (stable and max_abs_z unknown; its peaks are those of loops not "
                "checked for stability)")
            continue
        z = c["max_abs_z"] = [max_abs_z(G, K, T) for G, K in zip(plants, Kd[c["method"]][1])]
        c["stable"] = all(zj < 1 for zj, ok in zip(z, cont_stable) if ok)
        if c["stable"]:
            best = c
            continue
        peaks = c["sensitivity_peak"] = [p if p is not None and zj < 1 else None
                                         for p, zj in zip(c["sensitivity_peak"], z)]
        cont = c["sensitivity_peak_continuous"]
        c["sensitivity_peak_error"] = max(
            (abs(pd - pc) / pc for pd, pc in zip(peaks, cont) if pd is not None),
            default=float("inf") if any(pc is not None for pc in cont) else 0.0)
    return best

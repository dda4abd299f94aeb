"""Controller design for a rig: the reference PID, nominal H∞ and robust μ (thesis P5 §4).

``design(cfg, method)`` builds the design model (the modal reduction of the rig with the
actuator in series, P5 §3.1.4 and Fig. 8), the generalised plant of
:mod:`ambseal.control.plant` with the weights of :mod:`ambseal.control.weights`, and
synthesises:

* ``"pid"`` — the decentralised reference PID of ``[controller.pid]`` (P5 Eq. 6, §4.2);
* ``"hinf"`` — H∞ on the nominal plant at ``pressure_bar`` (P5 §4.4: "designed using the
  nominal plant representation");
* ``"mu"`` — complex D–K iteration on the perturbed plant with the seal's cross-coupled
  stiffness k ± 100 % of its value at ``pressure_bar`` (one δ shared by k and −k, P5 §4.1
  items 2–3), i.e. 0 … 2× the nominal pressure drop; the unbalance force at the seal
  (F_u = m·G·Ω, P5 §4.4.1) enters as a weighted disturbance so that the worst-case orbit
  is part of the robust-performance demand (:meth:`~ambseal.control.weights.Weights.Wf`).

Every controller is returned in the project's convention: a continuous
``control.StateSpace`` from the displacements (m) to the current references (A), used in
negative feedback ``i = −K y`` (:mod:`ambseal.analysis.loops`). Synthesis itself works on
the scaled plant with the LFT's positive feedback ``u = K_P e``; the conversion
``K = −(D_u/D_e) K_P`` is :meth:`GeneralizedPlant.physical_controller`.

Design model versus judgement: the design model keeps the rigid-body modes and, by default,
the first bending-mode pair (557 Hz, ``states=12``) so that the synthesised controller
does not destabilise it; every acceptance check is made on the full-order plant
(``build_plant(cfg, pressure_bar=p)``), see ``tests/control/test_control_design.py``.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Any, Mapping

import numpy as np

from ..errors import ConfigError, SynthesisError
from ..model.amb import channel_names
from .weights import Weights, default_weights

__all__ = ["DesignResult", "design", "METHODS"]

METHODS = ("pid", "hinf", "mu")


@dataclass(frozen=True, eq=False)
class DesignResult:
    """A designed controller and how it was obtained.

    Attributes
    ----------
    method : str
        ``"pid"``, ``"hinf"`` or ``"mu"``.
    K : control.StateSpace
        Continuous controller, inputs ``y_<axis>`` (m), outputs ``u_<axis>`` (A), negative
        feedback ``i = −K y``.
    pressure_bar : float
        Design (nominal) pressure drop (bar).
    gamma : float or None
        Verified H∞ norm of the (nominal, or best D-scaled) closed loop (-).
    mu : float or None
        Peak μ upper bound of ``F_l(P, K_P)`` on the design grid (μ design only).
    order : int
        States of ``K``.
    order_full : int
        States before order reduction.
    history : tuple of dict
        D–K iterations (``iteration``, ``gamma``, ``mu``, ``order``); empty otherwise.
    weights : Weights or None
    uncertainty : dict
        ``{parameter: (low, high)}`` in SI units.
    elapsed_s : float
        Wall time of the synthesis (s).
    reduction : dict or None
        :class:`~ambseal.control.order.ReductionResult` summary when reduced.
    plant : GeneralizedPlant or None
        The generalised plant (not serialised).
    """

    method: str
    K: Any = field(repr=False)
    pressure_bar: float
    gamma: float | None = None
    mu: float | None = None
    order: int = 0
    order_full: int = 0
    history: tuple = ()
    weights: Weights | None = None
    uncertainty: dict = field(default_factory=dict)
    elapsed_s: float = 0.0
    reduction: dict | None = None
    plant: Any = field(default=None, repr=False)

    def summary(self) -> dict:
        """Short JSON-ready summary (no matrices)."""
        return {"method": self.method, "pressure_bar": self.pressure_bar, "gamma": self.gamma,
                "mu": self.mu, "order": self.order, "order_full": self.order_full,
                "elapsed_s": round(self.elapsed_s, 3),
                "weights": self.weights.to_dict() if self.weights else None,
                "uncertainty": {k: list(v) for k, v in self.uncertainty.items()},
                "iterations": len(self.history), "reduction": self.reduction}

    def to_dict(self) -> dict:
        """Summary plus the controller matrices (lists) and the D–K history."""
        d = self.summary()
        d["history"] = [dict(h) for h in self.history]
        d["controller"] = {
            "inputs": list(self.K.input_labels), "outputs": list(self.K.output_labels),
            "input_unit": "m", "output_unit": "A", "feedback": "negative: i = -K y",
            **{k: np.asarray(getattr(self.K, k), float).tolist() for k in ("A", "B", "C", "D")}}
        return d


def _pid(cfg, p):
    from .pid import pid_controller

    pid = getattr(getattr(cfg, "controller", None), "pid", None)
    if pid is None:
        raise ConfigError("design(method='pid'): the rig has no [controller.pid] section")
    chans = channel_names(cfg)
    K = pid_controller(pid.kp, pid.ti, pid.td, pid.eps, chans)
    return DesignResult("pid", K, p, order=int(K.nstates), order_full=int(K.nstates))


def design(
    cfg,
    method: str = "mu",
    *,
    pressure_bar: float | None = None,
    weights: Weights | None = None,
    uncertainty: Mapping[str, Any] | None = None,
    states: int = 12,
    omega: Any = None,
    reduce_to: int | str | None = "auto",
    max_iter: int = 6,
    dk_order: int = 2,
) -> DesignResult:
    """Design a controller for a rig (thesis P5 §4).

    Parameters
    ----------
    cfg : RigConfig
        The rig (``ambseal.config.load_rig()``).
    method : {"pid", "hinf", "mu"}
        Reference PID, nominal H∞, or μ (D–K) robust to the seal's k.
    pressure_bar : float, optional
        Design pressure drop (bar); ``[operating] pressure_bar`` if omitted (2.04 bar).
    weights : Weights, optional
        Weights and scalings; :func:`~ambseal.control.weights.default_weights` for the
        method if omitted.
    uncertainty : mapping, optional
        μ only: ``{parameter: fraction or (low, high)}`` as in
        :func:`~ambseal.control.plant.generalized_plant`; default ``{"seal.k": 1.0}``
        (k ± 100 % of its value at ``pressure_bar``, P5 §4.1). Ignored by ``"hinf"``.
    states : int
        Mechanical states of the design model (8: rigid body only, as the thesis; 12: plus
        the first bending pair, the default, so that the full-order loop stays stable).
    omega : array_like, optional
        μ frequency grid (rad/s); default :func:`~ambseal.control.dk.design_omega`.
    reduce_to : int, "auto" or None
        Reduce the controller to this order (balanced truncation,
        :func:`~ambseal.control.order.reduce_controller`); the rise of γ/μ is reported in
        ``reduction``. ``"auto"``: 28 for μ (the force weight W_f and the D-scales raise
        the order to 42; truncating to 28 changes μ by < 0.1 %), none for H∞. ``None``: no reduction.
    max_iter, dk_order : int
        D–K iterations and D-scale fit order (μ only).

    Returns
    -------
    DesignResult

    Raises
    ------
    ConfigError
        Unknown method, bad weights or uncertainty ranges, ``reduce_to`` not an int,
        ``"pid"`` on a rig without ``[controller.pid]``.
    SynthesisError
        If synthesis fails or the reduced controller no longer stabilises the design loop.

    Examples
    --------
    >>> from ambseal.config import load_rig
    >>> r = design(load_rig(), "hinf")              # doctest: +SKIP
    >>> r.K.ninputs, r.K.noutputs                    # doctest: +SKIP
    (4, 4)
    """
    if method not in METHODS:
        raise ConfigError(f"design: method={method!r}, expected one of {METHODS}")
    p = float(cfg.operating.pressure_bar if pressure_bar is None else pressure_bar)
    if method == "pid":
        return _pid(cfg, p)

    from .plant import generalized_plant

    w = weights or default_weights(method)
    unc = dict(uncertainty) if uncertainty is not None else {"seal.k": 1.0}
    t0 = time.perf_counter()
    Wf = w.Wf()
    fpos = ()
    if Wf is not None:
        if w.force_position_m is not None:
            fpos = (float(w.force_position_m),)
        elif getattr(cfg, "seal", None):
            fpos = (float(cfg.seal[0].position),)
        else:
            raise ConfigError("design: orbit_um needs a force position; the rig has no seal, "
                              "set Weights.force_position_m")
    gp = generalized_plant(cfg, w.Wp(), w.Wu(), uncertainty=unc if method == "mu" else None,
                           pressure_bar=p, states=states, input_disturbance=w.W1(),
                           force_disturbance=Wf, force_positions=fpos, d_e=w.d_e, d_u=w.d_u)
    if method == "hinf":
        from .hinf import hinfsyn

        r = hinfsyn(gp.P_nominal, gp.nmeas, gp.ncon)
        K_P, gamma, mu, hist = r.K, float(r.gamma), None, ()
        P_red, blocks, om = gp.P_nominal, None, None
    else:
        from .dk import design_omega, musyn

        om = design_omega() if omega is None else np.asarray(omega, float)
        r = musyn(gp.P, gp.blocks, gp.nmeas, gp.ncon, om, order=dk_order, max_iter=max_iter)
        K_P, gamma, mu, hist = r.K, float(r.gamma), float(r.mu), r.history
        P_red, blocks = gp.P, gp.blocks
    order_full = int(K_P.nstates)
    if reduce_to == "auto":
        reduce_to = 28 if method == "mu" else None
    elif isinstance(reduce_to, str):
        raise ConfigError(f"design: reduce_to={reduce_to!r}, expected an int, 'auto' or None")
    red = None
    if reduce_to is not None and reduce_to < order_full:
        from .order import reduce_controller

        rr = reduce_controller(P_red, K_P, int(reduce_to), gp.nmeas, gp.ncon,
                               blocks=blocks, omega=om)
        if not np.isfinite(rr.gamma):
            raise SynthesisError(
                f"design: the order-{reduce_to} controller does not stabilise the design loop "
                f"(full order {order_full}); choose a larger reduce_to")
        K_P, red = rr.K, rr.to_dict()
        red.pop("hsv", None)
        gamma = float(rr.gamma) if method == "hinf" else gamma
        mu = float(rr.mu) if rr.mu is not None else mu
    K = gp.physical_controller(K_P, name=f"K_{method}")
    elapsed = time.perf_counter() - t0
    ranges = {q.name: (q.low, q.high) for q in gp.parameters}
    return DesignResult(method, K, p, gamma=gamma, mu=mu, order=int(K.nstates),
                        order_full=order_full, history=tuple(hist), weights=w,
                        uncertainty=ranges, elapsed_s=elapsed, reduction=red, plant=gp)

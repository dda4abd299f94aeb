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
  is part of the robust-performance demand (:meth:`DesignWeights.Wf`).

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

__all__ = ["DesignWeights", "DesignResult", "design", "default_weights", "METHODS"]

METHODS = ("pid", "hinf", "mu")


@dataclass(frozen=True)
class DesignWeights:
    """Tuning of the weights (P5 Eq. 7 and §4.3; P3 Eq. 11).

    Attributes
    ----------
    M : float
        W_p high-frequency sensitivity bound (-).
    omega_b : float
        W_p bandwidth ω_B (rad/s).
    A : float
        W_p steady-state error (-), thesis 1/1000.
    wu_gain : float
        W_u low-frequency gain on the scaled current (-).
    wu_corner_hz, wu_hf_gain : float or None
        Optional high-pass W_u: corner (Hz) and high-frequency gain (-).
    w1_gain : float
        High-frequency gain of the input-disturbance weight W_1 (-).
    w1_corner_hz : float or None
        W_1 = w1_gain·s/(s + 2π·corner) when given (a high-pass: the compliance demand
        where unbalance forces act, not at DC); a constant ``w1_gain`` otherwise.
    orbit_um : float or None
        Unbalance-orbit demand (µm): adds force inputs at ``force_position_m`` weighted by
        :meth:`Wf`, so that ``‖W_p S_o G_f W_f / D_e‖∞ ≤ 1`` reads "worst-case orbit
        σ̄(S_o G_f)·m·G·Ω ≤ orbit_um" below the roll-off (P5 §4.4.1). None: no force channel.
    unbalance_mass_kg, unbalance_grade_mm_s : float
        Rotor mass (kg) and ISO 21940-11 balance grade (mm/s) of the force law
        ``F_u = m·G·Ω`` (thesis: 69 kg, G2.5).
    wf_rolloff_hz : float
        Corner (Hz) of the 4th-order Butterworth roll-off of W_f: above the speed range
        (200 Hz) and well below the first bending mode (557 Hz), where a force at the seal
        excites a resonance no controller can make compliant — a W_f still large there
        makes μ unreachable (≈ 6) and wrecks the design.
    force_position_m : float or None
        Axial position (m) of the force; the rig's first seal if None (0.43 m).
    """

    M: float = 2.5
    omega_b: float = 60.0
    A: float = 1e-3
    wu_gain: float = 0.3
    wu_corner_hz: float | None = None
    wu_hf_gain: float | None = None
    w1_gain: float = 1.0
    w1_corner_hz: float | None = None
    orbit_um: float | None = None
    unbalance_mass_kg: float = 69.0
    unbalance_grade_mm_s: float = 2.5
    wf_rolloff_hz: float = 260.0
    force_position_m: float | None = None

    def Wp(self):
        """W_p as a ``control.TransferFunction``."""
        from .weights import performance_weight

        return performance_weight(self.M, self.omega_b, self.A)

    def Wu(self):
        """W_u as a ``control.TransferFunction``."""
        from .weights import control_weight

        return control_weight(self.wu_gain, corner_hz=self.wu_corner_hz, hf_gain=self.wu_hf_gain)

    def W1(self):
        """W_1 (input disturbance) as a ``control.TransferFunction`` or a float."""
        import control

        if self.w1_corner_hz is None:
            return float(self.w1_gain)
        if not (self.w1_gain > 0 and self.w1_corner_hz > 0):
            raise ValueError(f"W_1: gain {self.w1_gain} and corner {self.w1_corner_hz} Hz must be > 0")
        return control.tf([self.w1_gain, 0.0], [1.0, 2 * np.pi * self.w1_corner_hz])

    def Wf(self, d_e: float = 20e-6):
        """W_f on the unbalance-force inputs (N per unit), or None without ``orbit_um``.

        ``W_f = (m G D_e / orbit) · s · B_4(s) / W_p(s)`` with ``B_4`` the 4th-order
        Butterworth low-pass at ``wf_rolloff_hz``: the product ``W_p W_f / D_e`` on the
        force → performance channel is ``m G s B_4 / orbit``, i.e. the unbalance force
        ``F_u = m·G·Ω`` over the allowed orbit — the 1/W_p factor undoes the performance
        weight, which would otherwise turn the demand into an orbit bound of
        ``M·D_e·/orbit`` ≈ 6× too loose above ω_B and a needless one at DC.
        """
        import control

        if self.orbit_um is None:
            return None
        for nm, v in (("orbit_um", self.orbit_um), ("unbalance_mass_kg", self.unbalance_mass_kg),
                      ("unbalance_grade_mm_s", self.unbalance_grade_mm_s),
                      ("wf_rolloff_hz", self.wf_rolloff_hz)):
            if not (np.isfinite(v) and v > 0):
                raise ValueError(f"W_f: {nm}={v!r} must be finite and > 0")
        c = self.unbalance_mass_kg * self.unbalance_grade_mm_s * 1e-3 * d_e / (self.orbit_um * 1e-6)
        wr = 2 * np.pi * self.wf_rolloff_hz
        b4 = control.tf([wr**4], [1.0, 2.6131259 * wr, 3.4142136 * wr**2, 2.6131259 * wr**3, wr**4])
        Wp = self.Wp()
        return control.tf([c, 0.0], [1.0]) * b4 * control.tf(Wp.den[0][0], Wp.num[0][0])

    def to_dict(self) -> dict:
        return {"M": self.M, "omega_b_rad_s": self.omega_b, "A": self.A,
                "wu_gain": self.wu_gain, "wu_corner_hz": self.wu_corner_hz,
                "wu_hf_gain": self.wu_hf_gain, "w1_gain": self.w1_gain,
                "w1_corner_hz": self.w1_corner_hz, "orbit_um": self.orbit_um,
                "unbalance_mass_kg": self.unbalance_mass_kg,
                "unbalance_grade_mm_s": self.unbalance_grade_mm_s,
                "wf_rolloff_hz": self.wf_rolloff_hz, "force_position_m": self.force_position_m}


def default_weights(method: str) -> DesignWeights:
    """The tuned weights for the thesis test facility (see the module's tests for why).

    H∞ (nominal design): W_p with M = 2.5, ω_B = 60 rad/s, A = 1/1000; W_u = 0.3 constant.

    μ: W_p with M = 3 (ISO 14839-3 zone A), ω_B = 30 rad/s, A = 1/1000; a high-pass
    W_u = 0.02 (1 + s/ω_z)/(1 + s/ω_p) rising from 0.02 to 0.2 above 800 Hz (rolls the
    controller off above the bending mode: |K| ≈ 0.2 MA/m at 10 kHz instead of ≈ 1.3); a
    small constant W_1 = 0.05; and the unbalance force at the seal (0.43 m) as a weighted
    input, :meth:`DesignWeights.Wf` with ``F_u = m·G·Ω`` (69 kg, G2.5, P5 §4.4.1), an orbit
    demand of 6 µm and a 4th-order roll-off at 260 Hz (above the 200 Hz speed range, below
    the 557 Hz bending mode). Result (μ ≈ 1.14): on the full-order plant from 0 to
    4.08 bar σ̄(S_o) ≤ 2.5 (bending-mode resonance resolved) and worst-case orbit up to
    200 Hz ≤ 6.5 µm.

    Why: the force channel must bypass W_p (else the bound is ≈ 6× too loose above ω_B) and
    roll off before the bending mode (else μ ≈ 6 at 557 Hz and the design degrades: orbit
    17–49 µm); without it the orbit is ≈ 10.5 µm. The binding trade-off is the orbit
    against the control effort, not against σ̄(S_o): with W_u = 0.05/0.03/0.02 (constant)
    and a 6 µm demand the orbit is 7.8/6.6/5.8 µm at σ̄(S_o) 2.3/2.1/2.0; W_u = 0.2 (the
    previous value) with the same demand gives σ̄(S_o) 3.6 and 15 µm. With an 8 µm demand
    and this W_u, μ = 0.98 < 1 (robust performance on the design model), orbit 7.0 µm —
    a smaller margin on the acceptance than the 6 µm demand.
    """
    if method == "hinf":
        return DesignWeights(M=2.5, omega_b=60.0, wu_gain=0.3)
    if method == "mu":
        return DesignWeights(M=3.0, omega_b=30.0, wu_gain=0.02, wu_corner_hz=800.0,
                             wu_hf_gain=0.2, w1_gain=0.05, orbit_um=6.0, wf_rolloff_hz=260.0)
    raise ValueError(f"default_weights: no weights for method {method!r} (expected 'hinf' or 'mu')")


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
    weights : DesignWeights or None
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
    weights: DesignWeights | None = None
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
    weights: DesignWeights | None = None,
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
    weights : DesignWeights, optional
        Weights; :func:`default_weights` for the method if omitted.
    uncertainty : mapping, optional
        μ only: ``{parameter: fraction or (low, high)}`` as in
        :func:`~ambseal.control.plant.generalized_plant`; default ``{"seal.k": 1.0}``
        (k ± 100 % of its value at ``pressure_bar``, P5 §4.1). Ignored by ``"hinf"``.
    states : int
        Mechanical states of the design model (8: rigid body only, as the thesis; 12: plus
        the first bending pair, the default, so that the full-order loop stays stable).
    omega : array_like, optional
        μ frequency grid (rad/s); default 60 points log-spaced over 1 Hz … 2 kHz.
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
    ValueError
        Unknown method, bad weights or uncertainty ranges.
    ConfigError
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
        raise ValueError(f"design: method={method!r}, expected one of {METHODS}")
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
            raise ValueError("design: orbit_um needs a force position; the rig has no seal, "
                             "set DesignWeights.force_position_m")
    gp = generalized_plant(cfg, w.Wp(), w.Wu(), uncertainty=unc if method == "mu" else None,
                           pressure_bar=p, states=states, input_disturbance=w.W1(),
                           force_disturbance=Wf, force_positions=fpos)
    if method == "hinf":
        from .hinf import hinfsyn

        r = hinfsyn(gp.P_nominal, gp.nmeas, gp.ncon)
        K_P, gamma, mu, hist = r.K, float(r.gamma), None, ()
        P_red, blocks, om = gp.P_nominal, None, None
    else:
        from .dk import musyn

        om = (2 * np.pi * np.logspace(0.0, np.log10(2000.0), 60) if omega is None
              else np.asarray(omega, float))
        r = musyn(gp.P, gp.blocks, gp.nmeas, gp.ncon, om, order=dk_order, max_iter=max_iter)
        K_P, gamma, mu, hist = r.K, float(r.gamma), float(r.mu), r.history
        P_red, blocks = gp.P, gp.blocks
    order_full = int(K_P.nstates)
    if reduce_to == "auto":
        reduce_to = 28 if method == "mu" else None
    elif isinstance(reduce_to, str):
        raise ValueError(f"design: reduce_to={reduce_to!r}, expected an int, 'auto' or None")
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

"""The generalised plant P of the robust designs (thesis P5 §4.3, Figs. 8–9; P3 Fig. 6).

Interconnection (all signals scaled, P5 §3.1.4: ``D_e^{-1} G_f D_u`` with D_e = 20 µm the
largest allowed displacement error and D_u = 1 A the largest allowed current change)::

    plant current    i   = D_u (u + d_i)                        (A; actuator G_act inside G)
    perturbed plant  ẋ   = A_c x + B_Δ w_Δ + B i                 (G_fi, P5 Eq. 5)
                     z_Δ = C_Δ x + D_Δ i,     w_Δ = Δ z_Δ
    error            e   = (C x + D i) / D_e + d_o               (-, displacement / D_e)
    performance      z_p = W_p e,   z_u = W_u u
    measurement      y   = e

Inputs ``[w_Δ, d_i, d_o, u]`` and outputs ``[z_Δ, z_p, z_u, y]``, i.e. the
``[w_Δ, w, u] / [z_Δ, z, y]`` order of :func:`ambseal.control.hinf.hinfsyn` and
:func:`ambseal.control.dk.musyn`. ``W_p`` shapes ``S_o`` (from ``d_o``) and ``S_o G``
(from ``d_i``); ``W_u`` bounds ``K S_o`` and ``T_i``.

Uncertain parameters: each named LFT parameter θ of :class:`ambseal.model.lft.Plant`
(e.g. ``"seal.k"``) with a range ``[θ_lo, θ_hi]`` is written θ = θ_c + h δ, |δ| ≤ 1
(centre θ_c, half-width h). The design model is the plant at θ_c; its r-fold LFT channel
(r = 2 for a seal's k and −k, one shared δ, P5 §4.1 item 3 and Appendix A) gives one real
repeated scalar block ``(-r, 0)`` in MATLAB ``mussv`` notation; the last block ``(n_w, n_z)``
is the full complex performance block Δ_P (P5 Fig. 9).

Controllers: synthesis returns ``u = K_P y`` in scaled units with the LFT's positive
feedback. The project's controllers map displacements (m) to currents (A) in negative
feedback ``i = −K y_m`` (:mod:`ambseal.analysis.loops`), so
``K = −(D_u / D_e) K_P`` (:meth:`GeneralizedPlant.physical_controller`).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Mapping

import numpy as np

from ..errors import ConfigError, ModelError
from .weights import diagonal_weight

__all__ = ["UncertainParameter", "GeneralizedPlant", "generalized_plant",
           "physical_controller", "physical_matrices"]


@dataclass(frozen=True)
class UncertainParameter:
    """A physical parameter with a range, normalised to θ = centre + half_width·δ, |δ| ≤ 1.

    Attributes
    ----------
    name : str
        LFT parameter name, e.g. ``"seal.k"``.
    nominal : float
        Value in the model the plant was built from (SI).
    low, high : float
        Range (SI), ``low < high``.
    repeats : int
        Times δ appears (size of the repeated scalar block).
    unit : str
        SI unit.
    """

    name: str
    nominal: float
    low: float
    high: float
    repeats: int
    unit: str = ""

    @property
    def centre(self) -> float:
        """Centre θ_c of the range (SI); the design model's value."""
        return 0.5 * (self.low + self.high)

    @property
    def half_width(self) -> float:
        """Half-width h (SI)."""
        return 0.5 * (self.high - self.low)

    def value(self, delta: float) -> float:
        """θ for a normalised δ (SI)."""
        return self.centre + self.half_width * float(delta)

    def delta(self, value: float) -> float:
        """Normalised δ for a value θ (SI)."""
        return (float(value) - self.centre) / self.half_width

    def to_dict(self) -> dict:
        return {"name": self.name, "nominal": self.nominal, "low": self.low, "high": self.high,
                "centre": self.centre, "half_width": self.half_width,
                "repeats": self.repeats, "unit": self.unit}


@dataclass(frozen=True, eq=False)
class GeneralizedPlant:
    """The generalised plant and what is needed to use and interpret it.

    Attributes
    ----------
    P : control.StateSpace
        Inputs ``[w_Δ (n_delta), d_i (nu), d_o (ny), u (nu)]``, outputs
        ``[z_Δ (n_delta), z_p (ny), z_u (nu), y (ny)]``, scaled units (module docstring).
    P_nominal : control.StateSpace
        ``P`` without the Δ channels (inputs ``[d_i, d_o, u]``, outputs ``[z_p, z_u, y]``),
        for nominal H∞ design.
    blocks : tuple of (int, int)
        Structure of ``diag(Δ, Δ_P)`` for :func:`~ambseal.control.mu.mussv` and
        :func:`~ambseal.control.dk.musyn` on ``F_l(P, K_P)``.
    nominal_blocks : tuple of (int, int)
        ``((n_w, n_z),)`` for ``P_nominal``.
    nmeas, ncon : int
        Measurements (= ny) and controls (= nu).
    parameters : tuple of UncertainParameter
    design_plant : ambseal.model.lft.Plant
        The plant at the centre of the ranges (A → m), the design model.
    Wp, Wu : control.StateSpace
        The SISO weights used on every channel.
    d_e, d_u : float
        Scalings (m, A).
    channels : tuple of str
        Actuator axis names (measurement/control order).
    """

    P: Any
    P_nominal: Any
    blocks: tuple
    nominal_blocks: tuple
    nmeas: int
    ncon: int
    parameters: tuple
    design_plant: Any = field(repr=False)
    Wp: Any = field(repr=False)
    Wu: Any = field(repr=False)
    d_e: float = 20e-6
    d_u: float = 1.0
    channels: tuple = ()

    @property
    def n_delta(self) -> int:
        """Number of Δ channels (Σ repeats)."""
        return sum(p.repeats for p in self.parameters)

    def physical_controller(self, K_P, name: str = "K"):
        """:func:`physical_controller` with this plant's scalings and channel names.

        Parameters
        ----------
        K_P : control.StateSpace
            Synthesised controller, ny inputs (scaled error) → nu outputs (scaled current),
            ``u = K_P y``.

        Returns
        -------
        control.StateSpace
            Inputs ``y_<axis>`` (m), outputs ``u_<axis>`` (A), used as ``i = −K y``.
        """
        return physical_controller(K_P, self.d_e, self.d_u, self.channels, name=name)

    def synthesis_controller(self, K):
        """Inverse of :meth:`physical_controller`: ``K_P = −(D_e/D_u) K``."""
        import control

        return control.ss(*physical_matrices(_abcd(K), self.d_u, self.d_e))

    def closed_loop(self, K, *, nominal: bool = False):
        """``F_l(P, K_P)`` for a physical controller ``K`` (m → A, negative feedback)."""
        from .hinf import lft_lower

        P = self.P_nominal if nominal else self.P
        return lft_lower(P, self.synthesis_controller(K), self.nmeas, self.ncon)

    def mu(self, K, omega, **kw):
        """Structured singular value of ``F_l(P, K_P)`` on ``omega`` (rad/s), ``mussv`` result."""
        from .mu import mussv

        return mussv(self.closed_loop(K), self.blocks, omega, **kw)

    def to_dict(self) -> dict:
        """JSON-ready description (no matrices)."""
        return {"inputs": list(self.P.input_labels), "outputs": list(self.P.output_labels),
                "states": int(self.P.nstates), "blocks": [list(b) for b in self.blocks],
                "nmeas": self.nmeas, "ncon": self.ncon, "d_e_m": self.d_e, "d_u_a": self.d_u,
                "parameters": [p.to_dict() for p in self.parameters]}


def _abcd(K) -> tuple[np.ndarray, ...]:
    if isinstance(K, (tuple, list)):
        return tuple(np.asarray(m, float) for m in K)
    return tuple(np.asarray(getattr(K, m), float) for m in ("A", "B", "C", "D"))


def physical_matrices(K_P, d_e: float, d_u: float) -> tuple[np.ndarray, ...]:
    """``(A_K, B_K, C_K, D_K)`` of ``K = −(D_u/D_e) K_P`` (P5 §3.1.4; module docstring).

    The one conversion of a synthesised controller (scaled error → scaled current,
    positive feedback ``u = K_P y``) to the project's physical one (m → A, negative
    feedback ``i = −K y``).

    Parameters
    ----------
    K_P : control.StateSpace or (A, B, C, D)
        Controller in synthesis units.
    d_e, d_u : float
        Scalings of displacement error (m) and current (A).

    Returns
    -------
    tuple of ndarray
        ``A_K``, ``B_K`` unchanged; ``C_K``, ``D_K`` times ``−d_u/d_e``.
    """
    A, B, C, D = _abcd(K_P)
    g = -float(d_u) / float(d_e)
    return A, B, g * C, g * D


def physical_controller(K_P, d_e: float, d_u: float, channels, name: str = "K"):
    """``K = −(D_u/D_e) K_P`` as a named ``control.StateSpace`` (:func:`physical_matrices`).

    Parameters
    ----------
    K_P : control.StateSpace or (A, B, C, D)
        Controller in synthesis units, ``len(channels)`` inputs and outputs.
    d_e, d_u : float
        Scalings (m, A).
    channels : sequence of str
        Actuator axis names: inputs ``y_<axis>`` (m), outputs ``u_<axis>`` (A).
    name : str
        System name.

    Returns
    -------
    control.StateSpace
        Physical controller, used as ``i = −K y``.
    """
    import control

    A, B, C, D = physical_matrices(K_P, d_e, d_u)
    return control.ss(A, B, C, D, inputs=[f"y_{c}" for c in channels],
                      outputs=[f"u_{c}" for c in channels],
                      states=[f"xK{i}" for i in range(A.shape[0])], name=name)


def _series(sA, sB, sC, sD, cols: slice, W):
    """Put the (block-diagonal) weight W in series with the input columns ``cols``."""
    A1, B1, C1, D1 = (np.asarray(m, float) for m in (W.A, W.B, W.C, W.D))
    k = cols.stop - cols.start
    n1, N = A1.shape[0], sA.shape[0]
    B1 = B1.reshape(n1, k); C1 = C1.reshape(k, n1)
    Bi, Di = sB[:, cols].copy(), sD[:, cols].copy()
    if n1:  # balance the realisation against the plant's (large) actuator input gain
        t = np.sqrt(max(np.linalg.norm(B1), 1e-300)
                    / max(np.linalg.norm(np.vstack([Bi, Di]) @ C1), 1e-300))
        B1, C1 = B1 / t, C1 * t
    sA = np.block([[sA, Bi @ C1], [np.zeros((n1, N)), A1]])
    sB = np.vstack([sB, np.zeros((n1, sB.shape[1]))])
    sB[:N, cols] = Bi @ D1
    sB[N:, cols] = B1
    sC = np.hstack([sC, Di @ C1])
    sD = sD.copy()
    sD[:, cols] = Di @ D1
    return sA, sB, sC, sD, n1


def _ranges(plant, uncertainty: Mapping[str, Any]) -> tuple[UncertainParameter, ...]:
    out = []
    for name, spec in uncertainty.items():
        p = plant.parameter(name)  # ModelError for unknown names
        nom = float(p.nominal)
        if np.isscalar(spec):
            frac = float(spec)
            if not (np.isfinite(frac) and frac > 0):
                raise ConfigError(f"uncertainty[{name!r}]={spec!r}: a relative range must be a "
                                  "finite fraction > 0 (e.g. 1.0 for ±100 %)")
            if nom == 0:
                raise ConfigError(f"uncertainty[{name!r}]: the nominal value is 0, a relative "
                                  "range has zero width; give an absolute (low, high) range")
            lo, hi = nom - frac * abs(nom), nom + frac * abs(nom)
        else:
            try:
                lo, hi = (float(v) for v in spec)
            except (TypeError, ValueError):
                raise ConfigError(f"uncertainty[{name!r}]={spec!r}: expected a fraction or a "
                                  "(low, high) pair in SI units") from None
            if not (np.isfinite(lo) and np.isfinite(hi)):
                raise ConfigError(f"uncertainty[{name!r}]: range ({lo}, {hi}) is not finite")
            if not hi > lo:
                raise ConfigError(f"uncertainty[{name!r}]: range ({lo}, {hi}) has zero or "
                                  "negative width; need low < high")
        out.append(UncertainParameter(name, nom, lo, hi, int(p.repeats), p.unit))
    return tuple(out)


def generalized_plant(
    source,
    Wp,
    Wu,
    *,
    uncertainty: Mapping[str, Any] | None = None,
    pressure_bar: float | None = None,
    reduced: bool = True,
    states: int | None = None,
    d_e: float = 20e-6,
    d_u: float = 1.0,
    input_disturbance: Any = 1.0,
    output_disturbance: float = 1.0,
    force_disturbance: Any = None,
    force_positions: tuple = (),
) -> GeneralizedPlant:
    """Build the generalised plant of P5 Figs. 8–9 from a rig or a plant.

    Parameters
    ----------
    source : RigConfig or ambseal.model.lft.Plant
        A rig (the plant is built with :func:`ambseal.model.rig.build_plant`, actuator in
        series) or an already built plant whose first inputs are the coil currents and whose
        outputs are the displacements (extra force inputs are dropped).
    Wp, Wu : control.TransferFunction or StateSpace or float
        SISO weights, put on every error / current channel (see
        :mod:`ambseal.control.weights`). ``Wu`` must be biproper.
    uncertainty : mapping, optional
        ``{parameter: spec}`` with spec a fraction (±fraction of the nominal value, e.g.
        ``{"seal.k": 1.0}`` for ±100 %, P5 §4.1) or an absolute ``(low, high)`` range (SI).
        Empty or None: no Δ channels (``P`` equals ``P_nominal``).
    pressure_bar : float, optional
        Seal pressure drop (bar) when building from a rig; ``[operating]`` if omitted.
    reduced : bool
        Build the modal reduction (rigid-body design model, P5 §3.1.4) from a rig.
    states : int, optional
        Number of reduced mechanical states (default from the rig's ``[reduction]``).
    d_e, d_u : float
        Scalings: displacement error (m) and current (A), P5 §3.1.4.
    input_disturbance : float or SISO weight
        W_1 on ``d_i`` (in units of D_u), the same on every channel: a larger W_1 asks for a
        smaller ``S_o G`` (the compliance, hence the unbalance orbit). A band-pass W_1 puts
        that demand where unbalance forces act without asking for it at DC.
    output_disturbance : float
        Constant W_2 (> 0) on ``d_o`` (in units of D_e).
    force_disturbance : float or SISO weight, optional
        W_f on extra force inputs ``d_f`` (N) of the plant, e.g. an unbalance-force shape
        ``m G s`` rolled off above the speed range: then ``W_p S_o G_f W_f`` is part of the
        performance channel (the compliance of P5 §4.4.1). Roll W_f off well below a
        lightly damped bending mode the force excites (the test rig's 557 Hz mode with the
        force at the seal): there the compliance cannot be made small and μ is lost to it.
        Note W_p multiplies this channel; divide W_f by W_p for a plain orbit bound (see
        :meth:`ambseal.control.weights.Weights.Wf`). The inputs ``d_f`` come after
        ``d_o``. Needs force inputs: ``force_positions`` from a rig, or a plant built with them.
    force_positions : tuple of float
        Positions (m) of force inputs when building from a rig.

    Returns
    -------
    GeneralizedPlant

    Raises
    ------
    ConfigError
        Improper/unstable weights (named), non-positive scalings, a zero-width range.
    ModelError
        Unknown parameter names, a plant without current inputs.

    Examples
    --------
    >>> from ambseal.config import load_rig
    >>> from ambseal.control.weights import performance_weight, control_weight
    >>> gp = generalized_plant(load_rig(), performance_weight(2.5, 60.0), control_weight(1.0),
    ...                        uncertainty={"seal.k": 1.0})
    >>> gp.blocks
    ((-2, 0), (8, 8))
    """
    import control

    from ..model.lft import Plant

    for nm, v in (("d_e", d_e), ("d_u", d_u), ("output_disturbance", output_disturbance)):
        if not (np.isfinite(v) and v > 0):
            raise ConfigError(f"generalized_plant: {nm}={v!r} must be finite and > 0")
    if isinstance(source, Plant):
        plant = source
    else:
        from ..model.rig import build_plant

        plant = build_plant(source, reduced=reduced, pressure_bar=pressure_bar, states=states,
                            force_positions=tuple(force_positions))
    ny = len(plant.output_names)
    cur = [i for i, n in enumerate(plant.input_names) if n in plant.output_names]
    if not cur or ny == 0:
        raise ModelError("generalized_plant: the plant needs current inputs named like its "
                         "displacement outputs (e.g. A_zeta)")
    full = plant
    plant = plant.select_inputs([plant.input_names[i] for i in cur])
    channels = tuple(plant.input_names)
    nu = len(channels)
    Wp_d = diagonal_weight(Wp, ny, "W_p")
    Wu_d = diagonal_weight(Wu, nu, "W_u", biproper=True)

    params = _ranges(plant, uncertainty or {})
    design = plant.with_values({p.name: p.centre for p in params}) if params else plant
    A, B, C, D = design.A, design.B, design.C, design.D
    n = A.shape[0]
    Bd_l, Cd_l, Dd_l, zscale = [], [], [], []
    for p in params:
        q = design.parameter(p.name)
        h = p.half_width
        # w_θ = h δ z_θ; split h and balance the channel norms for conditioning
        nb = max(np.linalg.norm(q.B), 1e-300)
        nc = max(np.linalg.norm(np.hstack([q.C, q.D * d_u])), 1e-300)
        a = np.sqrt(h * nc / nb)
        Bd_l.append(q.B * a)
        Cd_l.append(q.C * (h / a))
        Dd_l.append(q.D * (h / a))
        zscale.append(h / a)
    nd = sum(p.repeats for p in params)
    Bd = np.hstack(Bd_l) if params else np.zeros((n, 0))
    Cd = np.vstack(Cd_l) if params else np.zeros((0, n))
    Dd = np.vstack(Dd_l) if params else np.zeros((0, nu))

    Ap, Bp, Cp, Dp = (np.asarray(m, float) for m in (Wp_d.A, Wp_d.B, Wp_d.C, Wp_d.D))
    Au, Bu, Cu, Du = (np.asarray(m, float) for m in (Wu_d.A, Wu_d.B, Wu_d.C, Wu_d.D))
    npw, nuw = Ap.shape[0], Au.shape[0]
    Bp = Bp.reshape(npw, ny); Cp = Cp.reshape(ny, npw)
    Bu = Bu.reshape(nuw, nu); Cu = Cu.reshape(nu, nuw)
    N = n + npw + nuw
    nin = nd + nu + ny + nu
    nout = nd + ny + nu + ny
    sA = np.zeros((N, N)); sB = np.zeros((N, nin)); sC = np.zeros((nout, N)); sD = np.zeros((nout, nin))
    iw, idi, ido, iu = 0, nd, nd + nu, nd + nu + ny
    oz, op, ou, oy = 0, nd, nd + ny, nd + ny + nu
    xs, xp, xu = slice(0, n), slice(n, n + npw), slice(n + npw, N)
    # e = (C x + D D_u (u + d_i))/D_e + d_o
    Ce = C / d_e
    De_i = D * d_u / d_e
    sA[xs, xs] = A
    sA[xp, xs] = Bp @ Ce
    sA[xp, xp] = Ap
    sA[xu, xu] = Au
    sB[xs, iw:iw + nd] = Bd
    sB[xs, idi:idi + nu] = B * d_u
    sB[xs, iu:iu + nu] = B * d_u
    sB[xp, idi:idi + nu] = Bp @ De_i
    sB[xp, iu:iu + nu] = Bp @ De_i
    sB[xp, ido:ido + ny] = Bp
    sB[xu, iu:iu + nu] = Bu
    # z_Δ
    sC[oz:oz + nd, xs] = Cd
    sD[oz:oz + nd, idi:idi + nu] = Dd * d_u
    sD[oz:oz + nd, iu:iu + nu] = Dd * d_u
    # z_p = Wp e
    sC[op:op + ny, xs] = Dp @ Ce
    sC[op:op + ny, xp] = Cp
    sD[op:op + ny, idi:idi + nu] = Dp @ De_i
    sD[op:op + ny, iu:iu + nu] = Dp @ De_i
    sD[op:op + ny, ido:ido + ny] = Dp
    # z_u = Wu u
    sC[ou:ou + nu, xu] = Cu
    sD[ou:ou + nu, iu:iu + nu] = Du
    # y = e
    sC[oy:oy + ny, xs] = Ce
    sD[oy:oy + ny, idi:idi + nu] = De_i
    sD[oy:oy + ny, iu:iu + nu] = De_i
    sD[oy:oy + ny, ido:ido + ny] = np.eye(ny)

    sB[:, ido:ido + ny] *= output_disturbance
    sD[:, ido:ido + ny] *= output_disturbance
    tags = [f"{p.name.replace('.', '_')}_{j}" for p in params for j in range(p.repeats)]
    inputs = ([f"wD_{t}" for t in tags] + [f"di_{c}" for c in channels]
              + [f"do_{c}" for c in design.output_names] + [f"u_{c}" for c in channels])
    outputs = ([f"zD_{t}" for t in tags] + [f"zp_{c}" for c in design.output_names]
               + [f"zu_{c}" for c in channels] + [f"y_{c}" for c in design.output_names])
    snames = (list(design.state_names) + [f"Wp{i}" for i in range(npw)]
              + [f"Wu{i}" for i in range(nuw)])
    W1 = diagonal_weight(input_disturbance, nu, "W_1")
    if W1.nstates or not np.allclose(np.asarray(W1.D), np.eye(nu)):
        sA, sB, sC, sD, n1 = _series(sA, sB, sC, sD, slice(idi, idi + nu), W1)
        snames = snames + [f"W1_{i}" for i in range(n1)]
    nf = 0
    if force_disturbance is not None:
        # unbalance-like forces (N) at the plant's force inputs, weighted by W_f
        fcols = [i for i, nm in enumerate(full.input_names) if nm not in full.output_names]
        if not fcols:
            raise ModelError("generalized_plant: force_disturbance needs force inputs; build "
                             "the plant with force_positions (e.g. the seal's position)")
        fp = full.with_values({q.name: q.centre for q in params}) if params else full
        nf = len(fcols)
        Bf, Df = fp.B[:, fcols], fp.D[:, fcols]
        colB = np.zeros((sA.shape[0], nf)); colD = np.zeros((nout, nf))
        colB[xs] = Bf
        colB[xp] = Bp @ (Df / d_e)
        if nd:
            colD[oz:oz + nd] = np.vstack([fp.parameter(q.name).D[:, fcols] * g
                                          for q, g in zip(params, zscale)])
        colD[op:op + ny] = Dp @ (Df / d_e)
        colD[oy:oy + ny] = Df / d_e
        sB = np.hstack([sB[:, :iu], colB, sB[:, iu:]])
        sD = np.hstack([sD[:, :iu], colD, sD[:, iu:]])
        Wf = diagonal_weight(force_disturbance, nf, "W_f")
        sA, sB, sC, sD, n2 = _series(sA, sB, sC, sD, slice(iu, iu + nf), Wf)
        snames = snames + [f"Wf_{i}" for i in range(n2)]
        inputs = inputs[:iu] + [f"df_{full.input_names[i]}" for i in fcols] + inputs[iu:]
        nin += nf
    P = control.ss(sA, sB, sC, sD, inputs=inputs, outputs=outputs, states=snames, name="P")
    keep_in = list(range(nd, nin))
    keep_out = list(range(nd, nout))
    P_nom = control.ss(sA, sB[:, keep_in], sC[keep_out], sD[np.ix_(keep_out, keep_in)],
                       inputs=inputs[nd:], outputs=outputs[nd:], states=snames, name="P_nominal")
    nw, nz = nu + ny + nf, ny + nu
    blocks = tuple((-p.repeats, 0) for p in params) + ((nw, nz),)
    return GeneralizedPlant(P=P, P_nominal=P_nom, blocks=blocks, nominal_blocks=((nw, nz),),
                            nmeas=ny, ncon=nu, parameters=params, design_plant=design,
                            Wp=control.ss(Wp) if not np.isscalar(Wp) else control.ss([], [], [], [[Wp]]),
                            Wu=control.ss(Wu) if not np.isscalar(Wu) else control.ss([], [], [], [[Wu]]),
                            d_e=float(d_e), d_u=float(d_u), channels=channels)

"""The generalised plant P of the robust designs (thesis P5 §4.3, Figs. 8–9; P3 Fig. 6).

Interconnection (all signals scaled, P5 §3.1.4: ``D_e^{-1} G_f D_u`` with D_e = 20 µm the
largest allowed displacement error and D_u = 1 A the largest allowed current change)::

    plant current    i   = D_u (L u + W_1 d_i)                  (A; actuator G_act inside G)
    force            f   = W_f d_f                              (N, optional force inputs)
    perturbed plant  ẋ   = A_c x + B_Δ w_Δ + B i + B_f f         (G_fi, P5 Eq. 5)
                     z_Δ = C_Δ x + D_Δ i + D_Δf f,   w_Δ = Δ z_Δ
    error            e   = (C x + D i + D_f f) / D_e + W_2 d_o   (-, displacement / D_e)
    performance      z_p = W_p e,   z_u = W_u u
    measurement      y   = e

L is the controller's hold + computation delay (a Padé system,
:mod:`ambseal.robust.delay`) when ``actuator_delay`` is given, else 1: the design then
pays the phase the sampled loop loses; the disturbance ``d_i`` enters after it.

P is built by connecting named signals (``control.interconnect``): the plant ``G`` with its
Δ channels, ``E`` (error), ``I`` (current), and the weights, each a ``control.StateSpace``
whose inputs and outputs are named after the signals above (:func:`_parts`); python-control
refuses '.' in signal names, so a parameter ``seal.k`` becomes ``seal__k`` inside (the
labels of P keep the form ``wD_seal_k_0``). The result equals the former hand-indexed
assembly to 1 ulp (measured on the test rig's H∞/μ plants and the turboexpander's).

Inputs ``[w_Δ, d_i, d_o, d_f, u]`` and outputs ``[z_Δ, z_p, z_u, y]``, i.e. the
``[w_Δ, w, u] / [z_Δ, z, y]`` order of :func:`ambseal.robust.hinf.hinfsyn` and
:func:`ambseal.robust.dk.musyn`. ``W_p`` shapes ``S_o`` (from ``d_o``) and ``S_o G``
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

from dataclasses import dataclass, field, replace
from typing import Any, Mapping

import control
import numpy as np

from ambseal.design.modal_bands import LIGHT_DAMPING, with_modal_frequencies
from ambseal.design.speed_lft import with_speed
from ambseal.design.weights import diagonal_weight
from ambseal.errors import ConfigError, ModelError
from ambseal.lti import picklable
from ambseal.model import Plant, build_plant
from ambseal.robust import lft_lower, mussv

__all__ = ["UncertainParameter", "GeneralizedPlant", "generalized_plant",
           "physical_controller", "physical_matrices", "less_damped"]

#: A margin applies to the design model's modes within this factor of its frequency: the
#: lost closed-loop mode sits between the open-loop pair it came from (the forward and
#: backward whirls, the ζ and η planes).
MARGIN_BAND = 1.15


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
        Structure of ``diag(Δ, Δ_P)`` for :func:`~ambseal.robust.mu.mussv` and
        :func:`~ambseal.robust.dk.musyn` on ``F_l(P, K_P)``.
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

        return control.ss(*physical_matrices(_abcd(K), self.d_u, self.d_e))

    def closed_loop(self, K, *, nominal: bool = False):
        """``F_l(P, K_P)`` for a physical controller ``K`` (m → A, negative feedback)."""

        P = self.P_nominal if nominal else self.P
        return lft_lower(P, self.synthesis_controller(K), self.nmeas, self.ncon)

    def mu(self, K, omega, **kw):
        """Structured singular value of ``F_l(P, K_P)`` on ``omega`` (rad/s), ``mussv`` result."""

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
        Actuator axis names: inputs ``y_<axis>`` (m), outputs ``i_<axis>`` (A), the
        reverse of the plant's (:class:`ambseal.model.lft.Plant`).
    name : str
        System name.

    Returns
    -------
    control.StateSpace
        Physical controller, used as ``i = −K y``.
    """

    picklable()
    A, B, C, D = physical_matrices(K_P, d_e, d_u)
    return control.ss(A, B, C, D, inputs=[f"y_{c}" for c in channels],
                      outputs=[f"i_{c}" for c in channels],
                      states=[f"xK{i}" for i in range(A.shape[0])], name=name)


def uncertainty_at(cfg, uncertainty: Mapping[str, Any], pressure_bar: float,
                   made_at_bar: float) -> dict:
    """An uncertainty specification for a design at another pressure than the one it was
    made at: a relative range of a parameter whose nominal value is 0 at ``pressure_bar``
    (a seal's k at 0 bar, where ± a fraction has no width) becomes the absolute range it
    spans at ``made_at_bar``; every other entry is kept as given.

    Parameters
    ----------
    cfg : RigConfig
        The rig designed on.
    uncertainty : mapping
        ``{parameter: fraction or (low, high)}`` (SI), as :func:`generalized_plant` takes
        it.
    pressure_bar, made_at_bar : float
        The design's pressure drop and the one the specification was made at (bar).

    Returns
    -------
    dict
        The specification for the design at ``pressure_bar``.

    Raises
    ------
    ConfigError, ModelError
        As :func:`generalized_plant`: a bad range or an unknown parameter.
    """
    out = dict(uncertainty)
    at = build_plant(cfg, pressure_bar=pressure_bar)
    zero = {n: r for n, r in out.items() if np.isscalar(r) and at.parameter(n).nominal == 0}
    if zero:
        made = _ranges(build_plant(cfg, pressure_bar=made_at_bar), zero)
        out.update({q.name: (q.low, q.high) for q in made})
    return out


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
    actuator_delay: Any = None,
    gain_weight: Any = None,
    damping_margins: tuple = (),
    modal_bands: tuple = (),
    speed_range_hz: tuple | None = None,
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
        :mod:`ambseal.design.weights`). ``Wu`` must be biproper.
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
        :meth:`ambseal.design.weights.Weights.Wf`). The inputs ``d_f`` come after
        ``d_o``. Needs force inputs: ``force_positions`` from a rig, or a plant built with them.
    force_positions : tuple of float
        Positions (m) of force inputs when building from a rig.
    actuator_delay : control.StateSpace, optional
        SISO stable approximation L of the controller's delay, put on every control channel
        between ``u`` and the current (``DesignDelay.system`` of
        :func:`ambseal.robust.delay.design_delay`); its states join P after the weights'.
    gain_weight : SISO weight, optional
        W_K on every control channel, an extra performance output ``z_K = W_K u`` after
        ``z_u`` (μ's gain demand, :meth:`ambseal.design.weights.Weights.Wk`); its states
        join P last.
    damping_margins : tuple of (float, float)
        ``(f_hz, Δζ)`` pairs: every lightly damped mode of the design model within a
        factor 1.15 of f_hz is made Δζ less damped (:func:`less_damped`), so the
        controller must add that damping of its own.
    modal_bands : tuple of ModeBand
        Modes whose damped frequency is uncertain over the band it sweeps with speed
        (:func:`ambseal.design.modal_bands.with_modal_frequencies`): each a real scalar
        block after those of ``uncertainty``.
    speed_range_hz : (float, float), optional
        The spin speed uncertain over this range (Hz): a real parameter
        (:data:`ambseal.design.speed_lft.SPEED`, rad/s) repeated as often as the
        gyroscopic term's rank (:func:`ambseal.design.speed_lft.with_speed`), its block
        after those of ``uncertainty``. From a rig only; the design model is the one at the
        rig's ``[operating] speed_rpm``, and its centre that of the range.

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
    >>> from ambseal.design.weights import performance_weight, control_weight
    >>> gp = generalized_plant(load_rig(), performance_weight(2.5, 60.0), control_weight(1.0),
    ...                        uncertainty={"seal.k": 1.0})
    >>> gp.blocks
    ((-2, 0), (8, 8))
    """
    picklable()
    for nm, v in (("d_e", d_e), ("d_u", d_u), ("output_disturbance", output_disturbance)):
        if not (np.isfinite(v) and v > 0):
            raise ConfigError(f"generalized_plant: {nm}={v!r} must be finite and > 0")
    full, cur, fcols = _source_plant(source, reduced, pressure_bar, states, force_positions,
                                     force_disturbance is not None)
    uncertainty = dict(uncertainty or {})
    if speed_range_hz is not None:
        if isinstance(source, Plant) or not reduced:
            raise ConfigError("generalized_plant: speed_range_hz needs a rig and its reduced "
                              "design model")
        full, ranges = with_speed(
            full, source, range_hz=speed_range_hz, states=states,
            pressure_bar=(source.operating.pressure_bar if pressure_bar is None
                          else pressure_bar), force_positions=tuple(force_positions))
        uncertainty.update(ranges)
    if damping_margins:
        full = less_damped(full, damping_margins)
    if modal_bands:
        full, ranges = with_modal_frequencies(full, modal_bands)
        uncertainty.update(ranges)
    params = _ranges(full.select_inputs([full.input_names[i] for i in cur]), uncertainty)
    centre = full.with_values({q.name: q.centre for q in params}) if params else full
    parts = _parts(centre, params, cur, fcols, Wp, Wu, input_disturbance, output_disturbance,
                   force_disturbance, d_e, d_u, actuator_delay, gain_weight)
    if parts.W1.nstates or (parts.Wf is not None and parts.Wf.nstates):
        parts = _balance(parts)
    P = _connect(parts)
    return _result(P, parts, params, centre, cur, Wp, Wu, d_e, d_u)


@dataclass(frozen=True, eq=False)
class _Parts:
    """The subsystems of the generalised plant with internal ('.'-free) signal names, and
    the public labels of P's channels."""

    G: Any
    Wp: Any
    Wu: Any
    W1: Any
    Wf: Any
    Wk: Any
    statics: tuple
    delay: Any
    inputs: tuple   # internal names of P's inputs, in order
    outputs: tuple  # internal names of P's outputs, in order
    labels_in: tuple
    labels_out: tuple
    state_names: tuple
    nd: int


def less_damped(plant: Plant, margins) -> Plant:
    """The plant with the damping of its lightly damped modes lowered: a design-model margin.

    Each complex mode λ with 0 < ζ = −Re λ/|λ| < :data:`LIGHT_DAMPING` whose |λ|/2π lies
    within a factor :data:`MARGIN_BAND` of a margin's frequency moves to
    λ + Δζ·|λ| (its damping ratio drops by Δζ, to below zero when Δζ > ζ), the other
    modes staying where they are: ``A + Re(V diag(δλ) W)`` with V, W the right and
    (biorthonormal) left eigenvectors. A controller that holds this model adds at least
    Δζ of damping of its own to those modes, the margin the truncated modes and the
    sampling may take from the full-order loop: a floor on the closed-loop damping ratio
    of those modes, as regional pole placement asks of every pole (Chilali & Gahinet,
    IEEE TAC 41(3), 1996).

    Parameters
    ----------
    plant : Plant
        Design model (states n, small: a dense eigendecomposition).
    margins : iterable of (float, float)
        ``(f_hz, Δζ)``: mode frequency (Hz, > 0) and damping-ratio margin (> 0).

    Returns
    -------
    Plant
        The same channels and parameters; only A changes.

    Raises
    ------
    ModelError
        A margin with a non-positive frequency or Δζ.
    """
    margins = [(float(f), float(dz)) for f, dz in margins]
    if any(not (f > 0 and dz > 0) for f, dz in margins):
        raise ModelError(f"less_damped: margins {margins}: expected (f_hz > 0, Δζ > 0) pairs")
    A = np.asarray(plant.A, float)
    lam, V = np.linalg.eig(A)
    W = np.linalg.inv(V)
    mag = np.abs(lam)
    zeta = -lam.real / np.maximum(mag, 1e-300)
    light = (np.abs(lam.imag) > 1e-9 * mag) & (zeta > 0) & (zeta < LIGHT_DAMPING)
    shift = np.zeros(lam.size)
    for f, dz in margins:
        near = light & (mag < MARGIN_BAND * 2 * np.pi * f) & (mag > 2 * np.pi * f / MARGIN_BAND)
        shift = np.where(near, np.maximum(shift, dz * mag), shift)
    if not shift.any():
        return plant
    return replace(plant, A=A + np.real((V * shift) @ W))


def _sig(prefix: str, names) -> list[str]:
    """Signal names for python-control's interconnect, which refuses '.': 'seal.k' → 'seal__k'."""
    return [f"{prefix}_{str(n).replace('.', '__')}" for n in names]


def _source_plant(source, reduced, pressure_bar, states, force_positions, forces: bool):
    """The plant (current inputs, then force inputs), and the indices of both."""

    if isinstance(source, Plant):
        full = source
    else:
        full = build_plant(source, reduced=reduced, pressure_bar=pressure_bar, states=states,
                           force_positions=tuple(force_positions))
    cur = full.current_inputs()
    if not cur or not full.output_names:
        raise ModelError("generalized_plant: the plant needs current inputs i_<axis> with "
                         "displacement outputs y_<axis> (e.g. i_A_zeta, y_A_zeta)")
    fcols = [i for i in range(len(full.input_names)) if i not in cur]
    if forces and not fcols:
        raise ModelError("generalized_plant: force_disturbance needs force inputs; build "
                         "the plant with force_positions (e.g. the seal's position)")
    return full, cur, (fcols if forces else [])


def _parts(centre, params, cur, fcols, Wp, Wu, W1, W2, Wf, d_e, d_u, L=None, Wk=None) -> _Parts:
    """The named subsystems of P5 Figs. 8–9 (module docstring):

    * ``G`` — the plant at the centre of the ranges with its Δ channels, inputs
      ``[w_Δ, i, f]``, outputs ``[z_Δ, y_m]`` (A, N → m); each channel w_θ = h δ z_θ with
      h split between B_θ and C_θ, D_θ so that both have similar norms (conditioning);
    * ``E`` — ``e = y_m/D_e + W_2 d_o``; ``I`` — ``i = D_u (L u + W_1 d_i)``;
    * the weights ``W_p`` (e → z_p), ``W_u`` (u → z_u), ``W_1`` (d_i), ``W_f`` (d_f → f).
    """

    chans = list(centre.axes)
    outs = [n.removeprefix("y_") for n in centre.output_names]
    forces = [centre.input_names[i] for i in fcols]
    ny, nu, nf = len(outs), len(chans), len(fcols)
    Bd, Cd, Di, Df = _delta_channels(centre, params, cur, fcols, d_u)
    nd = sum(p.repeats for p in params)
    tags = [f"{p.name.replace('.', '_')}_{j}" for p in params for j in range(p.repeats)]
    wD, zD = _sig("wD", tags), _sig("zD", tags)
    i_, f_, ym = _sig("i", chans), _sig("f", forces), _sig("ym", outs)
    u, di, diw = _sig("u", chans), _sig("di", chans), _sig("diw", chans)
    do, df, e = _sig("do", outs), _sig("df", forces), _sig("e", outs)
    zp, zu = _sig("zp", outs), _sig("zu", chans)
    A, B, C, D = (np.asarray(m, float) for m in (centre.A, centre.B, centre.C, centre.D))
    G = control.ss(A, np.hstack([Bd, B[:, cur], B[:, fcols]]), np.vstack([Cd, C]),
                   np.block([[np.zeros((nd, nd)), Di, Df],
                             [np.zeros((ny, nd)), D[:, cur], D[:, fcols]]]),
                   inputs=wD + i_ + f_, outputs=zD + ym, name="G")
    E = control.ss([], [], [], np.hstack([np.eye(ny) / d_e, W2 * np.eye(ny)]),
                   inputs=ym + do, outputs=e, name="E")
    ud = _sig("ud", chans) if L is not None else u
    I = control.ss([], [], [], np.hstack([d_u * np.eye(nu), d_u * np.eye(nu)]),
                   inputs=ud + diw, outputs=i_, name="I")
    L_d = _named(diagonal_weight(L, nu, "actuator_delay"), u, ud, "L") if L is not None else None
    Wp_d = _named(diagonal_weight(Wp, ny, "W_p"), e, zp, "Wp")
    Wu_d = _named(diagonal_weight(Wu, nu, "W_u", biproper=True), u, zu, "Wu")
    W1_d = _named(diagonal_weight(W1, nu, "W_1"), di, diw, "W1")
    Wf_d = _named(diagonal_weight(Wf, nf, "W_f"), df, f_, "Wf") if nf else None
    zk = _sig("zk", chans) if Wk is not None else []
    Wk_d = _named(diagonal_weight(Wk, nu, "W_K"), u, zk, "Wk") if Wk is not None else None
    ins = wD + di + do + df + u
    outputs = zD + zp + zu + zk + e
    lab_in = ([f"wD_{t}" for t in tags] + [f"di_{c}" for c in chans] + [f"do_{c}" for c in outs]
              + [f"df_{c}" for c in forces] + [f"u_{c}" for c in chans])
    lab_out = ([f"zD_{t}" for t in tags] + [f"zp_{c}" for c in outs] + [f"zu_{c}" for c in chans]
               + [f"zk_{c}" for c in chans if Wk is not None] + [f"y_{c}" for c in outs])
    snames = list(centre.state_names) + _weight_state_names(
        [("Wp", Wp_d), ("Wu", Wu_d), ("W1_", W1_d), ("Wf_", Wf_d), ("L", L_d), ("Wk", Wk_d)])
    return _Parts(G, Wp_d, Wu_d, W1_d, Wf_d, Wk_d, (E, I), L_d, tuple(ins), tuple(outputs),
                  tuple(lab_in), tuple(lab_out), tuple(snames), nd)


def _delta_channels(centre, params, cur, fcols, d_u) -> tuple[np.ndarray, ...]:
    """(B_Δ, C_Δ, D_Δi, D_Δf) of the parameters' LFT channels, each channel's half-width h
    split between its B and its C, D so that both have similar norms (conditioning)."""
    n, nu, nf = centre.A.shape[0], len(cur), len(fcols)
    if not params:
        return np.zeros((n, 0)), np.zeros((0, n)), np.zeros((0, nu)), np.zeros((0, nf))
    Bd, Cd, Di, Df = [], [], [], []
    for p in params:
        q = centre.parameter(p.name)
        h = p.half_width
        nb = max(np.linalg.norm(q.B), 1e-300)
        nc = max(np.linalg.norm(np.hstack([q.C, q.D[:, cur] * d_u])), 1e-300)
        a = np.sqrt(h * nc / nb)
        Bd.append(q.B * a)
        Cd.append(q.C * (h / a))
        Di.append(q.D[:, cur] * (h / a))
        Df.append(q.D[:, fcols] * (h / a))
    return np.hstack(Bd), np.vstack(Cd), np.vstack(Di), np.vstack(Df)


def _weight_state_names(weights) -> list[str]:
    """``prefix + index`` for each state of each (prefix, weight) given (None: none)."""
    return [f"{prefix}{i}" for prefix, W in weights if W is not None
            for i in range(W.nstates)]


def _named(W, inputs, outputs, name):
    return control.ss(W.A, W.B, W.C, W.D, inputs=list(inputs), outputs=list(outputs), name=name)


def _connect(parts: _Parts, W1=None, Wf=None):
    """P by named interconnection (``control.interconnect``) of the parts; ``W1``/``Wf``
    replace the parts' weights when given."""

    W1 = parts.W1 if W1 is None else W1
    Wf = parts.Wf if Wf is None else Wf
    syslist = [parts.G, parts.Wp, parts.Wu, W1] + ([Wf] if Wf is not None else []) \
        + ([parts.delay] if parts.delay is not None else []) \
        + ([parts.Wk] if parts.Wk is not None else []) + list(parts.statics)
    return control.interconnect(syslist, inplist=list(parts.inputs),
                                outlist=list(parts.outputs), inputs=list(parts.inputs),
                                outputs=list(parts.outputs), check_unused=False)


def _balance(parts: _Parts) -> _Parts:
    """The parts with the W_1 and W_f realisations balanced against the plant's (large)
    actuator input gain: their state scaled so that their input gain matches that of the
    columns of the unweighted P they feed (a similarity transformation: same weights)."""

    def identity(W):
        return _named(control.ss([], [], [], np.eye(W.ninputs)), W.input_labels,
                      W.output_labels, W.name)

    P0 = _connect(parts, identity(parts.W1), identity(parts.Wf) if parts.Wf is not None
                  else None)
    return replace(parts, W1=_balanced(parts.W1, P0, parts.W1.input_labels),
                   Wf=_balanced(parts.Wf, P0, parts.Wf.input_labels)
                   if parts.Wf is not None else None)


def _balanced(W, P0, cols):
    """W with its state scaled so that its input gain matches the gain of the plant
    columns ``cols`` of ``P0`` it feeds (a similarity transformation: same W)."""

    if not W.nstates:
        return W
    idx = [list(P0.input_labels).index(c) for c in cols]
    Bi, Di = np.asarray(P0.B, float)[:, idx], np.asarray(P0.D, float)[:, idx]
    A1, B1, C1, D1 = (np.asarray(m, float) for m in (W.A, W.B, W.C, W.D))
    t = np.sqrt(max(np.linalg.norm(B1), 1e-300)
                / max(np.linalg.norm(np.vstack([Bi, Di]) @ C1), 1e-300))
    return control.ss(A1, B1 / t, C1 * t, D1, inputs=list(W.input_labels),
                      outputs=list(W.output_labels), name=W.name)


def _result(P, parts: _Parts, params, centre, cur, Wp, Wu, d_e, d_u) -> GeneralizedPlant:
    """The :class:`GeneralizedPlant` of the interconnected P (public channel labels)."""

    sA, sB, sC, sD = (np.asarray(m, float) for m in (P.A, P.B, P.C, P.D))
    nd = parts.nd
    Pn = control.ss(sA, sB, sC, sD, inputs=list(parts.labels_in),
                    outputs=list(parts.labels_out), states=list(parts.state_names), name="P")
    P_nom = control.ss(sA, sB[:, nd:], sC[nd:], sD[nd:, nd:], inputs=list(parts.labels_in[nd:]),
                       outputs=list(parts.labels_out[nd:]), states=list(parts.state_names),
                       name="P_nominal")
    chans = centre.axes
    ny, nu = len(centre.output_names), len(chans)
    nw, nz = sB.shape[1] - nd - nu, sC.shape[0] - nd - ny
    blocks = tuple((-p.repeats, 0) for p in params) + ((nw, nz),)
    design = centre.select_inputs([centre.input_names[i] for i in cur])
    return GeneralizedPlant(P=Pn, P_nominal=P_nom, blocks=blocks, nominal_blocks=((nw, nz),),
                            nmeas=ny, ncon=nu, parameters=params, design_plant=design,
                            Wp=_ss_weight(Wp), Wu=_ss_weight(Wu), d_e=float(d_e),
                            d_u=float(d_u), channels=chans)


def _ss_weight(W):
    return control.ss([], [], [], [[W]]) if np.isscalar(W) else control.ss(W)

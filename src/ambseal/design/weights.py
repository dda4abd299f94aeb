"""Weighting functions for the H∞ / μ designs (thesis P3 Eq. 11, P5 Eq. 7, §4.3).

* Performance weight on the (scaled) displacement error, Skogestad & Postlethwaite (2005)
  Eq. 2.105 with n = 1::

      W_p(s) = (s/M + ω_B) / (s + ω_B A)

  ``|W_p(0)| = 1/A`` (steady-state error A, integral action; thesis: A = 1/1000),
  ``|W_p(j∞)| = 1/M`` (sensitivity peak M; thesis: M chosen for a peak below 3, ISO 14839-3
  zone A), crossover of ``1/|W_p|`` through 1 near ω_B (the closed-loop bandwidth).
  Requiring ``‖W_p S‖∞ < 1`` bounds ``|S(jω)| < 1/|W_p(jω)|``.
* Control weight on the (scaled) current: a constant (P5 §4.3) or a first-order high-pass
  (P3 §3.3: crossover 1.4 kHz) that rolls the controller off above the rigid-body band::

      W_u(s) = k (1 + s/ω_z) / (1 + s/ω_p),   ω_p > ω_z,

  low-frequency gain ``k``, high-frequency gain ``k ω_p/ω_z``. It must be biproper so that
  ``D12`` of the generalised plant has full column rank.
* Synchronous peak on the control weight (:func:`peak_weight`), where the amplifier cannot
  hold the unbalance at a speed Ω₀: a biproper second-order band weight, 1 away from Ω₀
  and ``h`` at it, multiplies W_u, so that the design bounds ``|K S_o(jΩ₀)|`` h times
  tighter there, and with it the synchronous current ``K S_o G_f F_u`` (Schweitzer &
  Maslen, *Magnetic Bearings*, 2009, ch. 15)::

      W_Ω(s) = (s² + 2 h ζ Ω₀ s + Ω₀²) / (s² + 2 ζ Ω₀ s + Ω₀²)

  On W_1 instead (the unbalance as a current F_u/Ki entering at a bearing) the same peak
  also weights the compliance ``S_o G`` at Ω₀, which no controller changes on a
  supercritical rotor (it is the mass line): on a rigid gyroscopic rotor γ rose 14-fold
  and ``|T_i(jΩ₀)|`` grew, where on W_u a peak of 8 cut ``|K S_o(jΩ₀)|`` 6.5-fold at γ
  0.73 against 0.65 (benchmarks/README.md, "The amplifier's limit inside the design").

All frequencies in rad/s unless the name says ``_hz``.

:class:`Weights` holds one design's tuning (W_p, W_u, W_1, W_f and the scalings D_e, D_u)
for every synthesis of the package: the PID/H∞/μ designs of
:mod:`ambseal.design.recipes` and the speed-scheduled designs of
:mod:`ambseal.design.lpv_design`; :func:`default_weights` gives the tuned sets.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import control
import numpy as np
from scipy.signal import butter

from ambseal.errors import ConfigError
from ambseal.robust import is_stable

#: the ISO 14839-3 zone-A bound on |S_o| by which μ's gain demand on ``K S_o`` exceeds the one
#: on K (:meth:`Weights.Wk`)
GAIN_SENSITIVITY = 3.0

__all__ = ["Weights", "default_weights", "performance_weight", "control_weight",
           "peak_weight", "check_weight", "diagonal_weight", "wp_gain"]

#: Damping ζ of :func:`peak_weight`'s poles: the weight stays above about h/√2 within ±ζ of
#: Ω₀ (for h ≫ 1), so ±10 % covers the judged speeds next to the worst one (the top
#: continuous speed and a trip speed 5 % above it) and leaves the loop's gain free an
#: octave away, where the rigid-body crossover and the bending modes need it.
PEAK_DAMPING = 0.1


def performance_weight(M: float, omega_b: float, A: float = 1e-3):
    """Performance weight ``W_p = (s/M + ω_B)/(s + ω_B A)`` (thesis P3 Eq. 11, P5 Eq. 7).

    Parameters
    ----------
    M : float
        Allowed high-frequency sensitivity bound, ``1/|W_p(j∞)|`` (-), > 1 in practice
        (thesis: tuned so that the σ̄(S_o) peak stays below 3).
    omega_b : float
        Bandwidth ω_B (rad/s), > 0.
    A : float
        Steady-state error, ``1/|W_p(0)|`` (-); thesis value 1/1000. ``0 < A < 1``.

    Returns
    -------
    control.TransferFunction
        SISO, first order, stable, biproper.

    Raises
    ------
    ConfigError
        If a parameter is non-finite or out of range (named in the message).

    Examples
    --------
    >>> W = performance_weight(2.0, 200.0)
    >>> round(float(abs(W(0))), 3), round(float(abs(W(1e9j))), 3)
    (1000.0, 0.5)
    """

    for name, v in (("M", M), ("omega_b", omega_b), ("A", A)):
        if not (np.isfinite(v) and v > 0):
            raise ConfigError(f"performance_weight: {name}={v!r} must be finite and > 0")
    if not A < 1:
        raise ConfigError(f"performance_weight: A={A!r} (steady-state error) must be < 1")
    return control.tf([1.0 / M, omega_b], [1.0, omega_b * A])


def wp_gain(omega, M: float, omega_b: float, A: float = 1e-3) -> np.ndarray:
    """Closed form ``|W_p(jω)| = √((ω/M)² + ω_B²) / √(ω² + (ω_B A)²)`` (-), any array shape."""
    w = np.asarray(omega, float)
    return np.sqrt((w / M) ** 2 + omega_b**2) / np.sqrt(w**2 + (omega_b * A) ** 2)


def control_weight(gain: float, *, corner_hz: float | None = None,
                   hf_gain: float | None = None):
    """Control-effort weight ``W_u``: a constant, or a biproper first-order high-pass.

    Parameters
    ----------
    gain : float
        Low-frequency gain k (-, on the scaled current u/D_u), > 0.
    corner_hz : float, optional
        Frequency (Hz) where ``|W_u|`` has risen to about √2·k (the zero ω_z = 2π·corner).
        Without it ``W_u = k``.
    hf_gain : float, optional
        High-frequency gain ``k ω_p/ω_z`` (> ``gain``); required with ``corner_hz``.

    Returns
    -------
    control.TransferFunction
        SISO, stable, biproper (a static gain when ``corner_hz`` is None).

    Raises
    ------
    ConfigError
        Non-positive gains or corner, ``hf_gain <= gain``, or ``hf_gain`` without corner.

    Examples
    --------
    >>> W = control_weight(0.5, corner_hz=100.0, hf_gain=5.0)
    >>> round(float(abs(W(0))), 3), round(float(abs(W(1e9j))), 3)
    (0.5, 5.0)
    """

    if not (np.isfinite(gain) and gain > 0):
        raise ConfigError(f"control_weight: gain={gain!r} must be finite and > 0")
    if corner_hz is None:
        if hf_gain is not None:
            raise ConfigError("control_weight: hf_gain needs corner_hz")
        return control.tf([float(gain)], [1.0])
    if not (np.isfinite(corner_hz) and corner_hz > 0):
        raise ConfigError(f"control_weight: corner_hz={corner_hz!r} must be finite and > 0")
    if hf_gain is None or not (np.isfinite(hf_gain) and hf_gain > gain):
        raise ConfigError(f"control_weight: hf_gain={hf_gain!r} must be finite and > gain={gain}")
    wz = 2 * np.pi * corner_hz
    wp = wz * hf_gain / gain
    return control.tf([gain / wz, gain], [1.0 / wp, 1.0])


def peak_weight(peak_hz: float, gain: float, damping: float = PEAK_DAMPING):
    """The synchronous peak ``W_Ω`` on the control weight (module docstring).

    Parameters
    ----------
    peak_hz : float
        Ω₀/2π (Hz), > 0: where the amplifier needs its current back.
    gain : float
        The height h = ``|W_Ω(jΩ₀)|`` (-), ≥ 1; 1 is no peak.
    damping : float
        ζ of the poles (-), > 0 (:data:`PEAK_DAMPING`).

    Returns
    -------
    control.TransferFunction
        SISO, second order, stable and minimum phase, biproper: 1 at DC and at high
        frequency.

    Raises
    ------
    ConfigError
        A non-positive or non-finite frequency or damping, or a height below 1.

    Examples
    --------
    >>> W = peak_weight(100.0, 4.0)
    >>> round(float(abs(W(2j * np.pi * 100.0))), 6), round(float(abs(W(0))), 6)
    (4.0, 1.0)
    """
    for name, v in (("peak_hz", peak_hz), ("damping", damping)):
        if not (np.isfinite(v) and v > 0):
            raise ConfigError(f"peak_weight: {name}={v!r} must be finite and > 0")
    if not (np.isfinite(gain) and gain >= 1):
        raise ConfigError(f"peak_weight: gain={gain!r} must be finite and >= 1")
    w0 = 2 * np.pi * peak_hz
    return control.tf([1.0, 2 * gain * damping * w0, w0**2], [1.0, 2 * damping * w0, w0**2])


def check_weight(W, name: str, *, biproper: bool = False):
    """Validate a SISO weight and return it as a ``control.StateSpace``.

    Parameters
    ----------
    W : control.TransferFunction, control.StateSpace or float
        The weight.
    name : str
        Its name for the message (``"W_p"``, ``"W_u"``).
    biproper : bool
        Also require a non-zero direct term (needed for ``W_u``: ``D12`` full rank).

    Returns
    -------
    control.StateSpace
        The weight, 1 input, 1 output.

    Raises
    ------
    ConfigError
        If the weight is not SISO, not proper (more zeros than poles), discrete-time, has
        a pole with ``Re ≥ 0``, non-finite coefficients, or (``biproper``) ``D = 0``.
    """

    if np.isscalar(W):
        if not (np.isfinite(W) and W != 0):
            raise ConfigError(f"weight {name}: a constant weight must be finite and non-zero, got {W!r}")
        return control.ss([], [], [], [[float(W)]])
    if isinstance(W, control.TransferFunction):
        if W.ninputs != 1 or W.noutputs != 1:
            raise ConfigError(f"weight {name}: must be SISO, got {W.noutputs}×{W.ninputs}")
        num = np.trim_zeros(np.atleast_1d(np.asarray(W.num[0][0], float)), "f")
        den = np.trim_zeros(np.atleast_1d(np.asarray(W.den[0][0], float)), "f")
        if num.size > den.size:
            raise ConfigError(
                f"weight {name} is not proper: numerator degree {num.size - 1} > denominator "
                f"degree {den.size - 1}; add a high-frequency pole")
    elif not isinstance(W, control.StateSpace):
        raise ConfigError(f"weight {name}: expected a TransferFunction, StateSpace or number, "
                          f"got {type(W).__name__}")
    if W.isdtime(strict=True):
        raise ConfigError(f"weight {name}: must be continuous-time")
    try:
        S = control.ss(W)
    except (np.linalg.LinAlgError, ValueError, OverflowError, ZeroDivisionError):
        # coefficients so far apart (1/M = 1e-308 beside ω_B) that the realisation overflows
        raise ConfigError(f"weight {name}: no state-space realisation of its coefficients "
                          "(non-finite, or too many orders of magnitude apart)") from None
    if S.ninputs != 1 or S.noutputs != 1:
        raise ConfigError(f"weight {name}: must be SISO, got {S.noutputs}×{S.ninputs}")
    mats = [np.asarray(m, float) for m in (S.A, S.B, S.C, S.D)]
    if not all(np.all(np.isfinite(m)) for m in mats):
        raise ConfigError(f"weight {name}: non-finite coefficients")
    if not is_stable(np.linalg.eigvals(mats[0])):
        raise ConfigError(f"weight {name}: has a pole that is not stable (Re ≥ 0); weights "
                          "must be stable")
    if biproper and abs(float(mats[3][0, 0])) == 0.0:
        raise ConfigError(f"weight {name}: must be biproper (non-zero gain at high frequency)")
    return S


def diagonal_weight(W, n: int, name: str, *, biproper: bool = False):
    """``diag(W, …, W)`` (n copies) of a SISO weight as a ``control.StateSpace``.

    Raises ConfigError as :func:`check_weight`.
    """

    S = check_weight(W, name, biproper=biproper)
    eye = np.eye(n)
    A, B, C, D = (np.kron(eye, np.asarray(m, float).reshape(np.shape(m) or (1, 1)))
                  for m in (S.A, S.B, S.C, S.D))
    if S.nstates == 0:
        A, B, C = np.zeros((0, 0)), np.zeros((0, n)), np.zeros((n, 0))
    return control.ss(A, B, C, D)


@dataclass(frozen=True)
class Weights:
    """Tuning of one design: weights and scalings (P5 Eq. 7, §3.1.4, §4.3; P3 Eq. 11, §3.3).

    One class for every synthesis: the nominal H∞ and μ designs of a rig
    (:func:`ambseal.design.recipes.design`) and the speed-scheduled LPV and frozen-speed
    designs (:mod:`ambseal.design.lpv_design`). :func:`default_weights` gives the tuned
    sets; the defaults below are those of the nominal H∞ design.

    Attributes
    ----------
    M : float
        W_p high-frequency sensitivity bound (-).
    omega_b : float
        W_p bandwidth ω_B (rad/s).
    A : float
        W_p steady-state error (-), thesis 1/1000 (1e-2 for the LPV LMIs, see
        :func:`default_weights`).
    wu_gain : float
        W_u low-frequency gain on the scaled current (-).
    wu_corner_hz, wu_hf_gain : float or None
        Optional high-pass W_u (:func:`control_weight`): corner (Hz) and high-frequency
        gain (-).
    wu_peak_hz, wu_peak_gain : float or None
        Optional synchronous peak on W_u (:func:`peak_weight`): where (Hz) and its height
        (-); ``ambseal run`` sets them where a design's unbalance current exceeds the
        amplifier (:func:`ambseal.app.remedies.within_the_amplifier`).
    w1_gain : float
        High-frequency gain of the input-disturbance weight W_1 (-).
    w1_corner_hz : float or None
        W_1 = w1_gain·s/(s + 2π·corner) when given (a high-pass: the compliance demand
        where unbalance forces act, not at DC); a constant ``w1_gain`` otherwise.
    orbit_um : float or None
        Unbalance-orbit demand (µm): adds force inputs at ``force_positions_m`` weighted by
        :meth:`Wf`, so that ``‖W_p S_o G_f W_f / D_e‖∞ ≤ 1`` reads "worst-case orbit
        σ̄(S_o G_f)·F_u(Ω) ≤ orbit_um" below the roll-off (P5 §4.4.1). None: no force channel.
    unbalance_mass_kg : float or None
        Mass m (kg) of the force law, needed with ``orbit_um``; the design specification
        sets the rotor's assembled mass (:mod:`ambseal.design.specs`).
    unbalance_grade_mm_s : float
        ISO 21940-11 balance grade G (mm/s), default G2.5 (precision machines).
    unbalance_law : str
        The force law of :func:`ambseal.analysis.unbalance.unbalance_force`:
        ``"iso21940"`` (``F_u = m G Ω²/Ω_max``) or ``"constant_velocity"`` (``m G Ω``).
    max_speed_rad_s : float or None
        Ω_max (rad/s) of the ``"iso21940"`` law, needed with it and ``orbit_um``.
    wf_rolloff_hz : float or None
        Corner (Hz) of the 4th-order Butterworth roll-off of W_f, needed with ``orbit_um``:
        above the speed range and well below the first bending mode, where a force excites
        a resonance no controller can make compliant — a W_f still large there makes μ
        unreachable and wrecks the design (the rule is in :mod:`ambseal.design.specs`).
    force_positions_m : tuple of float or None
        Axial positions (m) of the force inputs; the specification's (the bearings) if None.
    gain_factor : float or None
        μ's gain demand (P5 Fig. 10: the direct gains within 2× the reference PID's up to
        200 Hz): adds the output ``z_K = W_K u`` of :meth:`Wk`. None or 0: no such output.
    gain_band_hz : (float, float) or None
        The band (Hz) of that demand: W_K's 2nd-order high-pass and 4th-order low-pass
        Butterworth corners.
    pid_reference : (float, float, float, float) or None
        The reference PID (P5 Eq. 6) ``(Kp (A/m), T_i (s), T_d (s), ε (-))`` of W_K.
    d_e, d_u : float
        Scalings of displacement error (m) and current (A), P5 §3.1.4: 20 µm and 1 A.
    """

    M: float = 2.5
    omega_b: float = 60.0
    A: float = 1e-3
    wu_gain: float = 0.3
    wu_corner_hz: float | None = None
    wu_hf_gain: float | None = None
    wu_peak_hz: float | None = None
    wu_peak_gain: float | None = None
    w1_gain: float = 1.0
    w1_corner_hz: float | None = None
    orbit_um: float | None = None
    unbalance_mass_kg: float | None = None
    unbalance_grade_mm_s: float = 2.5
    unbalance_law: str = "iso21940"
    max_speed_rad_s: float | None = None
    wf_rolloff_hz: float | None = None
    force_positions_m: tuple | None = None
    gain_factor: float | None = None
    gain_band_hz: tuple | None = None
    pid_reference: tuple | None = None
    d_e: float = 20e-6
    d_u: float = 1.0

    def Wp(self):
        """W_p as a ``control.TransferFunction`` (:func:`performance_weight`)."""
        return performance_weight(self.M, self.omega_b, self.A)

    def Wu(self):
        """W_u as a ``control.TransferFunction`` (:func:`control_weight`), times the
        synchronous peak :func:`peak_weight` where ``wu_peak_hz`` is given."""
        W = control_weight(self.wu_gain, corner_hz=self.wu_corner_hz, hf_gain=self.wu_hf_gain)
        if self.wu_peak_hz is None:
            return W
        return W * peak_weight(self.wu_peak_hz, self.wu_peak_gain or 1.0)

    def Wk(self):
        """W_K on the current, the gain demand, or None without ``gain_factor``.

        ``W_K(s) = D_u / (c S_K D_e K_PID(s)) · H_2(s) · B_4(s)``, c = ``gain_factor``,
        ``S_K`` = :data:`GAIN_SENSITIVITY`, ``K_PID`` the reference PID (P5 Eq. 6),
        ``H_2`` and ``B_4`` the Butterworth high- and low-pass at ``gain_band_hz``. On the
        channel from the output disturbance it reads ``|K S_o| ≤ c S_K |K_PID|`` in the
        band: where ``|S_o|`` is near its ISO 14839-3 zone-A bound S_K = 3 (the top of the
        speed range, past the crossover) that is ``|K| ≲ c |K_PID|``; the band leaves the
        phase lead above it free. Returned in a balanced realisation (with the plain
        transfer-function realisation of the 8th-order product, slycot's H∞ norm AB13DD
        failed to converge in the controller reduction of one trial design).

        Raises
        ------
        ConfigError
            A non-positive factor, Kp, T_i or ε, a negative T_d, or a band not
            ``0 < low < high``.
        """

        if not self.gain_factor:
            return None
        if self.pid_reference is None or self.gain_band_hz is None:
            raise ConfigError("W_K: gain_factor needs pid_reference and gain_band_hz")
        kp, ti, td, eps = (float(x) for x in self.pid_reference)
        lo, hi = (float(x) for x in self.gain_band_hz)
        if not (self.gain_factor > 0 and min(kp, ti, eps) > 0 and td >= 0 and 0 < lo < hi):
            raise ConfigError(f"W_K: gain_factor {self.gain_factor}, PID {self.pid_reference} "
                              f"and band {self.gain_band_hz} Hz must be > 0 with low < high")
        # 1/K_PID, K_PID = Kp (1 + 1/(T_i s) + T_d s/(ε T_d s + 1))
        inv = control.tf([ti * eps * td, ti, 0.0],
                         [kp * ti * td * (1 + eps), kp * (ti + eps * td), kp])
        bh, ah = butter(2, 2 * np.pi * lo, btype="high", analog=True)
        bl, al = butter(4, 2 * np.pi * hi, analog=True)
        W = (self.d_u / (self.gain_factor * GAIN_SENSITIVITY * self.d_e)) * inv \
            * control.tf(bh, ah) * control.tf(bl, al)
        W = control.ss(W)
        return control.balred(W, W.nstates, method="truncate")

    def W1(self):
        """W_1 (input disturbance) as a ``control.TransferFunction`` or a float.

        Raises
        ------
        ConfigError
            A high-pass W_1 with a non-positive gain or corner.
        """

        if self.w1_corner_hz is None:
            return float(self.w1_gain)
        if not (self.w1_gain > 0 and self.w1_corner_hz > 0):
            raise ConfigError(f"W_1: gain {self.w1_gain} and corner {self.w1_corner_hz} Hz "
                              "must be > 0")
        return control.tf([self.w1_gain, 0.0], [1.0, 2 * np.pi * self.w1_corner_hz])

    def Wf(self):
        """W_f on the unbalance-force inputs (N per unit), or None without ``orbit_um``.

        ``W_f = (m G D_e / (orbit Ω_max)) · s² · B_4(s) / W_p(s)`` (ISO 21940-11 law) or
        ``(m G D_e / orbit) · s · B_4(s) / W_p(s)`` (constant-velocity law), with ``B_4`` the
        4th-order Butterworth low-pass at ``wf_rolloff_hz``: the product ``W_p W_f / D_e``
        on the force → performance channel is ``|F_u(Ω)| B_4 / orbit`` — the unbalance force
        of :func:`ambseal.analysis.unbalance.unbalance_force` over the allowed orbit. The
        1/W_p factor undoes the performance weight, which would otherwise turn the demand
        into an orbit bound of ``M·D_e/orbit`` ≈ 6× too loose above ω_B and a needless one
        at DC.

        Raises
        ------
        ConfigError
            A non-positive or non-finite orbit, mass, grade, maximum speed or roll-off, or
            an unknown law.
        """

        if self.orbit_um is None:
            return None
        for nm, v in (("orbit_um", self.orbit_um), ("unbalance_mass_kg", self.unbalance_mass_kg),
                      ("unbalance_grade_mm_s", self.unbalance_grade_mm_s),
                      ("wf_rolloff_hz", self.wf_rolloff_hz)):
            if v is None or not (np.isfinite(v) and v > 0):
                raise ConfigError(f"W_f: {nm}={v!r} must be finite and > 0")
        c = (self.unbalance_mass_kg * self.unbalance_grade_mm_s * 1e-3 * self.d_e
             / (self.orbit_um * 1e-6))
        if self.unbalance_law == "iso21940":
            wmax = self.max_speed_rad_s
            if wmax is None or not (np.isfinite(wmax) and wmax > 0):
                raise ConfigError(f"W_f: max_speed_rad_s={wmax!r} must be finite and > 0 "
                                  "(the iso21940 law's maximum service speed)")
            law = control.tf([c / wmax, 0.0, 0.0], [1.0])
        elif self.unbalance_law == "constant_velocity":
            law = control.tf([c, 0.0], [1.0])
        else:
            raise ConfigError(f"W_f: unbalance_law {self.unbalance_law!r} unknown (expected "
                              "'iso21940' or 'constant_velocity')")
        wr = 2 * np.pi * self.wf_rolloff_hz
        # Butterworth: s⁴ + 2.613 s³ + 3.414 s² + 2.613 s + 1 (normalised)
        b4 = control.tf([wr**4], [1.0, 2.6131259 * wr, 3.4142136 * wr**2, 2.6131259 * wr**3,
                                  wr**4])
        Wp = self.Wp()
        return law * b4 * control.tf(Wp.den[0][0], Wp.num[0][0])

    def to_dict(self) -> dict:
        """JSON-ready fields, units in the keys."""
        d = asdict(self)
        d["omega_b_rad_s"] = d.pop("omega_b")
        d["d_e_m"] = d.pop("d_e")
        d["d_u_a"] = d.pop("d_u")
        return d


def default_weights(method: str) -> Weights:
    """The tuning of each method on the scaled plant (see the tests in ``tests/control``).

    These are the parts that do not depend on the machine; the scalings D_e, D_u, the
    unbalance mass, the orbit demand, W_f's roll-off and W_u's corner are derived from the
    rig by :func:`ambseal.design.specs.design_spec`, and every one can be set in the rig's
    ``[design.<method>]`` table.

    ``"hinf"`` (nominal design, P5 §4.4): W_p with M = 2.5, A = 1/1000; W_u = 0.2 constant;
    a small constant W_1 = 0.05 (the same as μ's, so that the two differ only by W_u and
    what μ adds, as P5 §4.1 objective 1 wants them comparable).

    ``"mu"`` (P5 §4.3–4.4): W_p with M = 3.45 (the peak is judged on the full-order plant
    with the controller's delay: σ̄(S_o) ≤ 2.73 on the test rig, ISO 14839-3 zone A),
    A = 1/1000; a constant W_u (P5 §4.3); W_1 = 0.05; and, from the specification, the
    unbalance force at the bearings as a weighted input (:meth:`Weights.Wf`, ISO 21940-11
    law, P5 §4.4.1) with an orbit demand and a 4th-order roll-off, and the gain demand
    :meth:`Weights.Wk` (P5 Fig. 10).

    ω_B of both, μ's W_u gain (0.095 here is the test rig's), W_K, the orbit demand, W_f's
    roll-off and the scalings are rules of :func:`ambseal.design.specs.design_spec`.
    The trials behind these values are in benchmarks/README.md ("Where the design
    defaults come from").

    ``"lpv"`` (LPV and frozen-speed designs, P3 Eq. 11, §3.3): M = 2, ω_B = 2π·50 rad/s,
    A = 1e-2 (the reasoning is in :mod:`ambseal.design.lpv_design`); W_u's gains and
    corner and the scalings here are placeholders: the specification derives them from the
    rig (:mod:`ambseal.design.specs`, "LPV weights").

    Parameters
    ----------
    method : {"hinf", "mu", "lpv"}
        The design method whose tuning is wanted.

    Returns
    -------
    Weights
        The method's machine-independent weights; the rest at their placeholders until
        :func:`ambseal.design.specs.design_spec` derives them from the rig.

    Raises
    ------
    ConfigError
        Unknown method.
    """
    if method == "hinf":
        return Weights(M=2.5, omega_b=5.0, wu_gain=0.2, w1_gain=0.05)
    if method == "mu":
        return Weights(M=3.45, omega_b=5.0, wu_gain=0.092, w1_gain=0.05)
    if method == "lpv":
        return Weights(M=2.0, omega_b=2 * np.pi * 50.0, A=1e-2, wu_gain=0.05,
                       wu_corner_hz=1400.0, wu_hf_gain=0.5)
    raise ConfigError(f"default_weights: no weights for method {method!r} "
                      "(expected 'hinf', 'mu' or 'lpv')")

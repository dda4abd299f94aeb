"""The decentralised PID reference controller (thesis P5 Eq. 6, §4.2)."""

from __future__ import annotations

import contextlib
from dataclasses import dataclass, field, replace
from typing import ClassVar

import control
import numpy as np
from pydantic import ValidationError

from ambseal.config import PidFilter
from ambseal.design.conditions import judged_conditions, stability_speeds
from ambseal.design.pid_filters import flexible_mode_filters
from ambseal.errors import ConfigError, DataError
from ambseal.identify import check_controller, sample_rate_of, state_space_from_metadata
from ambseal.lti import feedback_matrices, picklable, zoh
from ambseal.machine import SPEED, ScheduledController
from ambseal.model import amb_factors, assemble_rotor, build_plant, channel_names
from ambseal.robust import discrete_controller, discretize_as, is_stable, with_delay

__all__ = ["pid_controller", "pid_from_rig", "reference_pid", "reference_controller",
           "ScheduledPid", "scheduled_pid",
           "controller_from_metadata", "filter_matrices", "pid_description", "pid_of",
           "PID_CORNERS_PER_FS", "precession_rad_s", "gyroscopic_cancellation"]

#: the derived PID (no [controller.pid]): k_eq = K_EQ_PER_KS·Ks, ζ on the rigid-body modes,
#: Ti in rigid-body time constants (P5 Eq. 6, §4.2), set on the precession instead where
#: the gyroscopic moments take it below PRECESSION_DROP·ω_n, and the derivative filter's
#: corner as a fraction of the sample rate, chosen among PID_CORNERS_PER_FS
#: (:func:`pid_from_rig`)
K_EQ_PER_KS, PID_ZETA, TI_PER_OMEGA_N, PRECESSION_DROP = 0.5, 1.0, 50.0, 0.25
PID_CORNERS_PER_FS = (0.1, 0.07, 0.05, 0.035, 0.14, 0.2)
KEEP_OF_STRUCTURAL = 0.2
#: The derivative filter's corner and the flexible-mode filters are chosen on each judged
#: condition's plant reduced to its modes below this multiple of the sample rate (the run
#: judges the PID on the full order): a mode above f_s reaches the sampled loop through
#: the hold, whose gain falls to zero at f_s, after the actuator's roll-off below it.
#: Measured on the nine examples and seven generated compressors (benchmarks/README.md,
#: "The derived PID chosen on the modes below the sample rate"): the same corners and
#: filters, their frequencies within 5e-6, at 3–13× less CPU than on the full order.
CHOICE_MODES_PER_FS = 1.0


def pid_controller(
    kp: float, ti: float, td: float, eps: float, channels: list[str] | tuple[str, ...],
    filters=(), cross_kp: float = 0.0, cross_kd: float = 0.0,
):
    """Decentralised PID, the same on every actuator axis, with filters in series, and
    cross-axis gains between the two axes of each bearing.

    K_PID(s) = Kp (1 + 1/(Ti s) + Td s/(ε Td s + 1)) · Π F_k(s)   (thesis P5 Eq. 6)

    Cross feedback (Schweitzer & Maslen, *Magnetic Bearings*, 2009, on gyroscopic rotors;
    Brown et al., NASA/TM-2006-214027): on the two axes ζ, η of one AMB,
    i_ζ = −(K y_ζ + K_c y_η), i_η = −(K y_η − K_c y_ζ), with
    K_c(s) = (cross_kp + cross_kd s/(ε Td s + 1)) · Π F_k(s): in the complex coordinate
    r = ζ + jη, i = −(K − jK_c) r, a force that turns with the whirl (forward for
    K_c > 0 acting as a negative cross stiffness, −j K_i cross_kp) — what damps or
    stiffens a gyroscopic rotor's nutation and precession differently.

    The filters are the commissioning engineer's (Schweitzer & Maslen, *Magnetic
    Bearings*, 2009, on flexible rotors), with ω_c = 2π ``frequency_hz``:

    * notch: F = (s² + 2ζ_z ω_c s + ω_c²)/(s² + 2ζ_p ω_c s + ω_c²), ζ_p = ``width_hz``/(2
      ``frequency_hz``) (the −3 dB width of a deep notch), ζ_z = ζ_p·10^(−depth_db/20): the
      gain at ω_c is 10^(−depth_db/20), 1 far from it;
    * lead, lag: F = (1 + s/ω_z)/(1 + s/ω_p), ω_z = ω_c/√α, ω_p = ω_c·√α, with
      α = (1 + sin φ)/(1 − sin φ) for a lead of φ = ``phase_deg`` (α → 1/α for a lag): the
      largest phase change, ±φ, at ω_c; gain 1 at zero frequency, √α at ω_c (a lag: 1/√α);
    * lowpass: F = ω_c²/(s² + 2ζ ω_c s + ω_c²), ζ = ``damping``.

    Parameters
    ----------
    kp : float
        Proportional gain Kp (A/m).
    ti, td : float
        Integral and derivative times (s); ``td = 0`` drops the derivative.
    eps : float
        Derivative filter factor ε (-).
    channels : sequence of str
        Axis names, e.g. ``("A_zeta", "A_eta", "B_zeta", "B_eta")``: inputs are the
        displacements (m), outputs the current references (A) of the same axes.
    filters : sequence of PidFilter or dict, optional
        ``[[controller.filter]]`` entries (:class:`ambseal.config.rig.PidFilter`, or dicts
        of its keys), applied in order.
    cross_kp, cross_kd : float, optional
        Cross-axis gains (A/m, A·s/m) between the ``<amb>_zeta`` and ``<amb>_eta``
        channels of each AMB; the derivative through the derivative's filter (needs
        ``td > 0``).

    Returns
    -------
    control.StateSpace
        Controller with 2 states per axis (integrator, derivative filter) plus the
        filters' (2 per notch or lowpass, 1 per lead or lag), used in negative feedback
        u = −K y; diagonal without cross gains.

    Raises
    ------
    ConfigError
        ``cross_kd`` without a derivative (``td = 0``), or cross gains on channels that
        are not ζ/η pairs.
    """

    picklable()
    # one axis: x1 integrator of e, x2 derivative filter state
    if td > 0:
        tf = eps * td
        a = np.array([[0.0, 0.0], [0.0, -1.0 / tf]])
        b = np.array([[1.0], [1.0]])
        c = np.array([[kp / ti, -kp * td / tf**2]])
        d = np.array([[kp * (1 + td / tf)]])
    else:
        a, b = np.zeros((1, 1)), np.ones((1, 1))
        c, d = np.array([[kp / ti]]), np.array([[kp]])
    n_core = a.shape[0]
    # the filters alone, driven by the PID's output u: where a cross term enters
    fb, fd = np.zeros((0, 1)), np.ones((1, 1))
    for f in filters:
        a, b, c, d = _series((a, b, c, d), filter_matrices(f))
        _, fbk, _, fdk = filter_matrices(f)
        fb, fd = np.vstack([fb, fbk @ fd]), fdk @ fd
    n = len(channels)
    eye = np.eye(n)
    A, B, C, D = (np.kron(eye, m) for m in (a, b, c, d))
    ns = a.shape[0]
    if cross_kp or cross_kd:
        _add_cross(A, B, C, D, channels, ns, n_core, fb, fd, float(cross_kp),
                   float(cross_kd), eps * td)
    return control.ss(
        A, B, C, D,
        inputs=[f"y_{c}" for c in channels],
        outputs=[f"i_{c}" for c in channels],
        states=[f"pid_{c}_{k}" for c in channels for k in range(ns)], name="K_pid",
    )


def _add_cross(A, B, C, D, channels, ns: int, n_core: int, fb, fd, kcp: float, kcd: float,
               tau: float) -> None:
    """Add the cross-axis terms of :func:`pid_controller` in place: to the PID output u of
    axis ζ, Δu = K_c y_η (η: −K_c y_ζ), K_c y = kcp y + kcd s y/(τ s + 1) = (kcp + kcd/τ) y
    − (kcd/τ²) x_d with x_d = y/(s + 1/τ) the derivative filter's state of that axis
    (state 1 of its PID core); Δu enters the axis's filter states through ``fb`` and its
    output through ``fd`` (the filters' input column and feedthrough)."""
    if kcd and not tau > 0:
        raise ConfigError("controller.pid.cross_kd: a cross-axis derivative needs td > 0")
    if sum(c.endswith("_zeta") for c in channels) * 2 != len(channels):
        raise ConfigError("controller.pid.cross_kp/cross_kd: cross-axis gains need each "
                          f"AMB's ζ and η axes (no η axis to cross with), got channels "
                          f"{list(channels)}")
    index = {c: i for i, c in enumerate(channels)}
    for c in channels:
        if not c.endswith("_zeta"):
            continue
        j_eta = index.get(c[:-5] + "_eta")
        if j_eta is None:
            raise ConfigError(f"controller.pid.cross_kp/cross_kd: AMB axis {c!r} has no "
                              "η axis to cross with")
        for out, src, sign in ((index[c], j_eta, 1.0), (j_eta, index[c], -1.0)):
            dd = sign * (kcp + (kcd / tau if kcd else 0.0))  # per unit y of the source axis
            dc = -sign * kcd / tau**2 if kcd else 0.0  # per unit of its derivative state
            rows = slice(out * ns + n_core, (out + 1) * ns)  # the output axis's filters
            B[rows, src] += fb[:, 0] * dd
            D[out, src] += fd[0, 0] * dd
            if dc:
                col = src * ns + 1
                A[rows, col] += fb[:, 0] * dc
                C[out, col] += fd[0, 0] * dc


def filter_matrices(f) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(a, b, c, d) of one SISO filter of :func:`pid_controller` (its formulas), the
    second-order ones with states scaled by ω_c (entries of the size of ω_c, not ω_c²).

    Parameters
    ----------
    f : PidFilter or dict
        ``kind``, ``frequency_hz`` and the kind's keys (a dict is validated as a
        :class:`~ambseal.config.rig.PidFilter`).

    Returns
    -------
    tuple of numpy.ndarray
        Shapes (n, n), (n, 1), (1, n), (1, 1) with n = 2 (notch, lowpass) or 1 (lead, lag).
    """
    g = f if isinstance(f, PidFilter) else PidFilter.model_validate(f)
    w = 2 * np.pi * g.frequency_hz
    if g.kind in ("lead", "lag"):
        s = np.sin(np.radians(g.phase_deg))
        alpha = (1 + s) / (1 - s)
        alpha = alpha if g.kind == "lead" else 1 / alpha
        wz, wp = w / np.sqrt(alpha), w * np.sqrt(alpha)
        k = wp / wz
        return (np.array([[-wp]]), np.ones((1, 1)), np.array([[k * (wz - wp)]]),
                np.array([[k]]))
    if g.kind == "notch":
        zp = g.width_hz / (2 * g.frequency_hz)
        zz = zp * 10 ** (-g.depth_db / 20)
        zeta, c, d = zp, np.array([[0.0, 2 * w * (zz - zp)]]), np.ones((1, 1))
    else:  # lowpass: ω²/(s² + 2ζωs + ω²)
        zeta, c, d = g.damping, np.array([[w, 0.0]]), np.zeros((1, 1))
    # x1' = ω x2, x2' = −ω x1 − 2ζω x2 + u: x1 = ω U/(s² + 2ζωs + ω²), x2 = s U/(...)
    a = np.array([[0.0, w], [-w, -2 * zeta * w]])
    return a, np.array([[0.0], [1.0]]), c, d


def _series(first, second):
    """SISO ``second`` after ``first`` (state [x_first; x_second])."""
    a1, b1, c1, d1 = first
    a2, b2, c2, d2 = second
    n1, n2 = a1.shape[0], a2.shape[0]
    a = np.block([[a1, np.zeros((n1, n2))], [b2 @ c1, a2]])
    return a, np.vstack([b1, b2 @ d1]), np.hstack([d2 @ c1, c2]), d2 @ d1


_DERIVED: dict = {}  # pid_from_rig by the rig's JSON: the corner's check samples plants


def pid_from_rig(cfg) -> dict:
    """A decentralised PID (P5 Eq. 6) from the rig, for a rig without ``[controller.pid]``.

    One gain set on every axis, from the mean Ks/Ki over the AMB axes and half the rotor
    mass per bearing (a rigid rotor on two supports):

    * stiffness: k_eq = Ki·Kp − Ks = K_EQ_PER_KS·Ks, i.e. Kp = (1 + K_EQ_PER_KS)·Ks/Ki
      (Schweitzer & Maslen 2009 §7.2); with k_eq = Ks the seal's cross-coupling at 2.04 bar
      destabilised the test rig's rigid-body mode;
    * damping: the rigid-body mode ω_n = √(k_eq/m_b) gets the damping ratio PID_ZETA
      (Ki·Kp·Td = 2ζ√(k_eq m_b)); ζ ≤ 0.5 left the test rig unstable at 2.04 bar;
    * integral: Ti = TI_PER_OMEGA_N/ω_n, well below the rigid-body mode; on a gyroscopic
      rotor the backward conical mode (the precession) falls with speed, towards
      k_eq·l²/(Ω I_p), and an integral corner it reaches gives it negative damping (the
      flywheel of ``examples/flywheel.toml``, Ti = 50/ω_n: lost at 333 Hz, where
      1/Ti is ω_p/4.7). So where the precession ω_p of the rigid rotor on k_eq at the
      AMBs at the top speed (:func:`precession_rad_s`) is below PRECESSION_DROP·ω_n,
      Ti = TI_PER_OMEGA_N/ω_p: the same factor below the lowest rigid-body mode at every
      speed; elsewhere that factor stays above TI_PER_OMEGA_N·PRECESSION_DROP = 12.5, and
      Ti is as P5 (the turboexpander's precession, 0.49 ω_n at 300 Hz, keeps it);
    * cross-axis gains: none derived, on any rotor. The field's cross feedback on a
      gyroscopic rotor (Brown, Kascak, Jansen, Dever & Duffy, NASA/TM-2006-214027; Ahrens
      et al. 1996), a cross-axis derivative on each bearing scheduled ∝ Ω at a fraction of
      the gyroscopic cancellation Ω I_p/(K_i Σ l²) (:func:`gyroscopic_cancellation`),
      damps the nutation as it runs, but through the derivative filter it shares with the
      PID it takes the first bending modes' damping: on the flywheel of
      ``examples/flywheel.toml`` a tenth of it takes the 1.7 kHz pair at 1 000 Hz from
      ζ −0.017 to −0.055 as it runs, on a stiff-shaft variant the 3.5 kHz pair from
      +0.0027 to +0.0011, and with this PID the nutation is not the mode that limits it
      (benchmarks/README.md). Where the precession falls below PRECESSION_DROP·ω_n the
      rule states the full cancellation at the top speed, the scale of the
      ``[controller.pid]`` keys ``cross_kd`` and ``cross_speed_rpm`` that give them;
    * derivative filter (the roll-off) for the target: its corner f_d = 1/(2π ε Td) at a
      fraction of the sample rate f_s, at most f_s/5 (two fifths of Nyquist, where Tustin
      warps it by 13 %); the loop as it runs loses (delay_samples + ½)·360°·f/f_s to the
      hold and the computation delay (54° at f_s/10 with one sample), and whether that
      lag, added to the filter's, damps or drives the first bending modes depends on the
      mode shapes, not on a ratio alone. So each corner of PID_CORNERS_PER_FS (f_s/10
      first) is tried on the plants of the judged conditions (their modes below the
      sample rate, CHOICE_MODES_PER_FS), sampled exactly
      (ZOH) with the controller by Tustin and its delay; the first kept that leaves the
      least-damped pole as it runs at least KEEP_OF_STRUCTURAL of the rotor's structural
      damping ``rotor.modal_damping`` at every condition where the continuous loop is
      stable, else the one stable as it runs at the most conditions, then holding the
      continuous loop at the most, then the best damped. The order favours the higher
      corner: a low corner costs phase at the rigid-body modes and raises σ̄(S_o) (test
      rig: 5.9 at f_s/10, 16 at f_s/20). P5's ε = 0.1 puts the corner at 10/(2π Td)
      whatever the rate: on
      the blower (20 kHz) and the pump (10 kHz) that corner (0.50 and 0.43 kHz) left the
      sampled loop unstable at their bending modes. Chosen: blower f_s/20 (none
      keeps the floor there: ζ 0.0006 at 1.6 kHz), pump f_s/10, test rig f_s/14,
      turboexpander f_s/10; the phase lost at ω_n (1–2°) is
      stated in ``rule``. Raising Td to win that phase back was tried and made the test
      rig's loop unstable at 2.04 bar (more gain at the bending mode);
    * filters (``[[controller.filter]]`` left out of the rig file): where no corner keeps
      that floor at every judged condition, a lead, lag or notch per flexible mode the
      loop leaves under-damped as it runs, chosen from the mode's band over the judged
      pressures at standstill, the judged speeds and the top speed, its collocation and
      the phase it needs (:mod:`ambseal.design.pid_filters`); the modes, the filters and
      a mode that defeats them all are stated in ``rule``. The test rig, the pump and the
      turboexpander need none (their corner keeps the floor where the PID holds its
      rigid-body modes).

    On the test rig (10 kHz, 1 sample): Kp 1.8e4 A/m, Td 3.3 ms, Ti 0.25 s (the thesis's
    hand tuning: 1.6e4, 3.5 ms, 0.2 s).

    Returns
    -------
    dict
        ``kp`` (A/m), ``ti``, ``td`` (s), ``eps`` (-), ``corner_hz`` (Hz), ``filters``
        (``[[controller.filter]]`` dicts) and ``rule``.
    """

    key = cfg.model_dump_json()
    if key in _DERIVED:
        return dict(_DERIVED[key])
    ratio = [ks / ki for a in cfg.amb for ki, ks in zip(*amb_factors(a))]
    ks_over_ki = float(np.mean(ratio)) if ratio else 0.0
    if not ks_over_ki > 0:  # the rule scales every gain with Ks
        raise ConfigError("controller.pid: cannot be derived (the rule scales with the AMBs' "
                          "Ks, and the rig has no AMB with Ks > 0); set [controller.pid]")
    ki = float(np.mean([k for a in cfg.amb for k in amb_factors(a)[0]]))
    ks = ks_over_ki * ki
    m_b = assemble_rotor(cfg).mass / 2
    k_eq = K_EQ_PER_KS * ks
    kp = (1 + K_EQ_PER_KS) * ks_over_ki
    w_n = np.sqrt(k_eq / m_b)
    td = float(2 * PID_ZETA * np.sqrt(k_eq * m_b) / (ki * kp))
    top_hz = max(stability_speeds(cfg)[0])
    w_p = precession_rad_s(cfg, k_eq, 2 * np.pi * top_hz)
    slow = w_p < PRECESSION_DROP * w_n
    ti = float(TI_PER_OMEGA_N / (w_p if slow else w_n))
    fs = cfg.controller.sample_rate_hz
    frac, kept = _corner_for_target(cfg, kp, ti, td)
    eps = float(1 / (2 * np.pi * frac * fs * td))
    lost = np.degrees((cfg.controller.delay_samples + 0.5) * w_n / fs)
    below = "f_s" if CHOICE_MODES_PER_FS == 1 else f"{CHOICE_MODES_PER_FS:g} f_s"
    out = {"kp": float(kp), "ti": ti, "td": td, "eps": eps, "corner_hz": frac * fs,
           "rule": f"k_eq = {K_EQ_PER_KS:g} Ks, ζ = {PID_ZETA:g} on the rigid-body modes "
                   f"({w_n / (2 * np.pi):.3g} Hz), Ti = {TI_PER_OMEGA_N:g}/"
                   + (f"ω_p (the precession, {w_p / (2 * np.pi):.3g} Hz at "
                      f"{top_hz:.4g} Hz, below {PRECESSION_DROP:g} ω_n)" if slow else "ω_n")
                   + f", derivative "
                   f"filter at f_s/{1 / frac:.3g} = {frac * fs:.4g} Hz (ε = {eps:.2g}; the "
                   f"first of f_s/"
                   f"{', f_s/'.join(f'{1 / c:.3g}' for c in PID_CORNERS_PER_FS)} that "
                   f"keeps {KEEP_OF_STRUCTURAL:g} of the structural damping as it runs on "
                   f"the modes below {below}, else the best); sampling and delay cost "
                   f"{lost:.1f}° at ω_n"}
    if slow:
        with contextlib.suppress(ConfigError):  # a note only: no lever arm, no note
            full = 2 * np.pi * top_hz * gyroscopic_cancellation(cfg)
            out["rule"] += (f"; no cross-axis gains (the gyroscopic cancellation Ω I_p/"
                            f"(K_i Σ l²) is {full:.4g} A·s/m at {top_hz:.4g} Hz: the scale "
                            f"of [controller.pid] cross_kd with cross_speed_rpm)")
    fd = None if kept else _filters_for_target(cfg, kp, ti, td, eps, w_n / (2 * np.pi))
    out["filters"] = [dict(f) for f in fd.filters] if fd else []
    if fd and fd.modes:
        # the damping ratios are those of the plants the choice is made on, not the run's
        # full-order judgement of the PID: the rule says so
        out["rule"] += (f"; flexible modes as it runs on the modes below {below} = "
                        f"{CHOICE_MODES_PER_FS * fs:.5g} Hz: "
                        + "; ".join(m.text() for m in fd.modes))
        if not fd.kept:
            out["rule"] += (f" — as it runs the PID leaves a flexible mode below "
                            f"{KEEP_OF_STRUCTURAL:g} of the structural damping (least ζ "
                            f"{fd.least_zeta:.2g})")
    _DERIVED[key] = out
    return dict(out)


def gyroscopic_cancellation(cfg) -> float:
    """The cross-axis derivative gain per unit speed that would cancel a rigid rotor's
    gyroscopic moments of tilt, decentralised on its AMBs: I_p/(K_i Σ l²), with I_p the
    rotor's polar moment of inertia, K_i the AMBs' mean current stiffness and l each AMB's
    distance from the centre of mass (Brown et al., NASA/TM-2006-214027: the bearing
    pair's cross forces k_c·Ω·(l_A² + l_B²)·θ̇ against the moment Ω I_p θ̇).

    Parameters
    ----------
    cfg : RigConfig
        The rig (its rotor and AMBs).

    Returns
    -------
    float
        A·s/m per rad/s of speed, ≥ 0.

    Raises
    ------
    ConfigError
        A rig whose AMBs all sit at the centre of mass (no lever arm).
    """
    rotor = assemble_rotor(cfg)
    M, G, _ = rotor.rigid()
    z_g = float(M[0, 2] / M[0, 0])  # tilts about the left end: M_r[0, 2] = m z_G
    l2 = sum((float(rotor.mesh.z[rotor.mesh.node_at(a.position)]) - z_g) ** 2
             for a in cfg.amb)
    ki = float(np.mean([k for a in cfg.amb for k in amb_factors(a)[0]]))
    if not l2 > 0 or not ki > 0:
        raise ConfigError("controller.pid: the cross-axis gains' rule needs AMBs away from "
                          "the centre of mass with Ki > 0")
    return float(abs(G[2, 3]) / (ki * l2))


def precession_rad_s(cfg, k_eq: float, speed_rad_s: float) -> float:
    """The lowest natural frequency of the rotor as a rigid body
    (:meth:`~ambseal.model.rotor.RotorMatrices.rigid`) on an isotropic spring ``k_eq`` at
    each AMB's actuator, spinning at Ω: on a gyroscopic rotor at speed, the backward
    conical mode, the precession (Genta, *Dynamics of Rotating Systems*, 2005, §4.6).

    Parameters
    ----------
    cfg : RigConfig
        The rig (its rotor and AMB positions).
    k_eq : float
        Each AMB's stiffness per axis (N/m), > 0.
    speed_rad_s : float
        Ω (rad/s).

    Returns
    -------
    float
        The undamped natural frequency (rad/s), > 0.
    """
    rotor = assemble_rotor(cfg)
    M, G, _ = rotor.rigid()
    K = np.zeros((4, 4))
    for a in cfg.amb:
        z = float(rotor.mesh.z[rotor.mesh.node_at(a.position)])
        for e in (np.array([1.0, 0.0, z, 0.0]), np.array([0.0, 1.0, 0.0, z])):
            K += k_eq * np.outer(e, e)
    A = np.block([[np.zeros((4, 4)), np.eye(4)],
                  [-np.linalg.solve(M, K), -speed_rad_s * np.linalg.solve(M, G)]])
    w = np.abs(np.linalg.eigvals(A).imag)
    return float(w[w > 0].min())


def _choice_plant(cfg, pressure_bar: float, speed_hz: float) -> tuple:
    """(A, B, C, D) from the current references to the displacements at one judged
    condition, reduced to the modes below :data:`CHOICE_MODES_PER_FS` times the sample
    rate: the plant the PID's corner and filters are chosen on."""
    pl = build_plant(cfg, pressure_bar=pressure_bar, speed_rpm=60.0 * speed_hz, reduced=True,
                     cutoff_hz=CHOICE_MODES_PER_FS * cfg.controller.sample_rate_hz)
    cur = pl.current_inputs()
    return tuple(np.asarray(X, float) for X in (pl.A, pl.B[:, cur], pl.C, pl.D[:, cur]))


def _filters_for_target(cfg, kp, ti, td, eps, rigid_hz: float):
    """The derived PID's filters (:mod:`ambseal.design.pid_filters`) on the rig's plants
    (:func:`_choice_plant`) at every judged pressure, at the judged speeds, at standstill
    and at the top speed: the gyroscopic moments move each mode monotonically with speed,
    so these ends bound the band it sweeps from standstill to the top speed."""
    pressures, judged = judged_conditions(cfg)
    speeds = sorted({0.0, *judged, max(stability_speeds(cfg)[0])})
    fs = cfg.controller.sample_rate_hz
    plants = [_choice_plant(cfg, p, f) for p in pressures for f in speeds]
    axes = channel_names(cfg)

    def matrices(filters):
        K = pid_controller(kp, ti, td, eps, axes, filters)
        return tuple(np.asarray(X, float) for X in (K.A, K.B, K.C, K.D))

    return flexible_mode_filters(plants, matrices, fs, cfg.controller.delay_samples,
                                 KEEP_OF_STRUCTURAL * cfg.rotor.modal_damping, rigid_hz)


def _zeta_z(z: np.ndarray) -> np.ndarray:
    """Damping ratios of discrete poles z (of s = ln z / T); z ≈ 0 counts as ζ = 1."""
    r = np.log(np.maximum(np.abs(z), 1e-300))
    return -r / np.maximum(np.hypot(r, np.angle(z)), 1e-300)


def _corner_for_target(cfg, kp: float, ti: float, td: float) -> float:
    """The derivative filter's corner (fraction of f_s) of :func:`pid_from_rig`, and
    whether it keeps the floor at every judged condition (the continuous loop stable at
    each)."""

    pressures, speeds = judged_conditions(cfg)
    fs, delay = cfg.controller.sample_rate_hz, cfg.controller.delay_samples
    plants = []
    for p in pressures:
        for f in speeds:
            G = _choice_plant(cfg, p, f)
            plants.append((G, (*zoh(G[0], G[1], 1 / fs), G[2], G[3])))
    floor = KEEP_OF_STRUCTURAL * cfg.rotor.modal_damping
    best = None
    for frac in PID_CORNERS_PER_FS:
        K = pid_controller(kp, ti, td, 1 / (2 * np.pi * frac * fs * td), channel_names(cfg))
        mats = tuple(np.asarray(X, float) for X in (K.A, K.B, K.C, K.D))
        Kd = with_delay(discretize_as(mats, 1 / fs, "tustin"), delay)
        n_ok, n_held, zeta = 0, 0, np.inf
        for G, Gd in plants:
            if not is_stable(np.linalg.eigvals(feedback_matrices(G, mats)[0])):
                continue  # unstable as designed: nothing to keep as it runs
            z = _zeta_z(np.linalg.eigvals(feedback_matrices(Gd, Kd)[0])).min()
            n_ok, n_held, zeta = n_ok + (z > 0), n_held + 1, min(zeta, z)
        held = n_held == len(plants)
        if n_held and zeta >= floor and zeta > 0:
            return frac, held
        # a corner whose loop is unstable as designed counts nothing as it runs: it ranks
        # below one that holds it (the flywheel: f_s/14 lost its bending modes designed)
        if best is None or (n_ok, n_held, zeta) > best[0]:
            best = ((n_ok, n_held, zeta), frac)
    return best[1], False


def reference_pid(cfg, speed_rpm: float | None = None) -> dict:
    """The rig's reference PID (P5 Eq. 6) as it acts at one speed: ``[controller.pid]`` as
    given, else derived from the rig by :func:`pid_from_rig` — the one rule by which the
    PID design, the weights of the design specification and the acquisition's controller
    find it.

    Parameters
    ----------
    cfg : RigConfig
        The rig (its ``[controller.pid]``, else what :func:`pid_from_rig` derives from).
    speed_rpm : float, optional
        The speed (rpm) of a PID whose cross gains are scheduled on speed
        (``cross_speed_rpm``, :class:`ScheduledPid`); ``[operating] speed_rpm`` if omitted.

    Returns
    -------
    dict
        ``kp`` (A/m), ``ti``, ``td`` (s), ``eps`` (-), ``filters`` (the
        ``[[controller.filter]]`` entries as dicts, in series with the PID; left out of the
        rig file, none for a given PID), ``cross_kp`` (A/m) and ``cross_kd`` (A·s/m), the
        cross-axis gains at that speed (0 where the rig file gives none, and for a derived
        PID: :func:`pid_from_rig`); derived ones also carry its ``rule``.
    """
    ctrl = getattr(cfg, "controller", None)
    pid = getattr(ctrl, "pid", None)
    given = getattr(ctrl, "filter", None)
    if pid is not None:
        scale = 1.0
        if pid.cross_speed_rpm is not None:
            at = cfg.operating.speed_rpm if speed_rpm is None else float(speed_rpm)
            scale = at / pid.cross_speed_rpm
        out = {"kp": pid.kp, "ti": pid.ti, "td": pid.td, "eps": pid.eps, "filters": [],
               "cross_kp": pid.cross_kp * scale, "cross_kd": pid.cross_kd * scale}
    else:
        out = pid_from_rig(cfg)
        out.setdefault("filters", [])
    if given is not None:
        out["filters"] = [f.model_dump(exclude_none=True) for f in given]
    return out


@dataclass(frozen=True, eq=False)
class ScheduledPid(ScheduledController):
    """The reference PID with cross-axis gains scheduled on speed,
    K_c(Ω) = K_c,ref·Ω/Ω_ref (``[controller.pid] cross_speed_rpm``), ``i = −K(Ω) y``: the
    gyroscopic moments grow with Ω, and so does the cross feedback that answers them
    (Ahrens, Kučera & Larsonneur, IEEE Trans. Control Syst. Technol. 4(5), 1996;
    Schweitzer & Maslen, *Magnetic Bearings*, 2009, on gyroscopic rotors). Every matrix of
    :func:`pid_controller` is affine in the cross gains, so the table at standstill and
    the top speed, interpolated linearly, is this PID exactly at every speed between.

    Attributes
    ----------
    gains : dict
        A PID description (:func:`pid_description`) with the cross gains at ``speed_ref``.
    channels : tuple of str
        The AMB channels.
    speed_ref : float
        Ω_ref (rad/s), > 0.
    top : float
        The top of the schedule (rad/s): held above it.
    name : str
    """

    parameter: ClassVar[str] = SPEED
    gains: dict = field(repr=False)
    channels: tuple
    speed_ref: float
    top: float
    name: str = "K_pid"

    @property
    def schedule(self) -> tuple[float, float]:
        """(0, Ω_top) (rad/s)."""
        return (0.0, float(self.top))

    @property
    def table_theta(self) -> np.ndarray:
        """The speeds (rad/s) of an exact table: standstill and the top speed."""
        return np.array([0.0, float(self.top)])

    def gains_at(self, speed_rad_s: float) -> dict:
        """The PID description at Ω (rad/s), held at the schedule's ends outside it."""
        w = min(max(float(speed_rad_s), 0.0), float(self.top))
        g = dict(self.gains)
        for k in CROSS:
            g[k] = float(g.get(k) or 0.0) * w / self.speed_ref
        return g

    def at(self, speed_rad_s: float, name: str | None = None):
        """The frozen PID at Ω (rad/s): a ``control.StateSpace``, m → A, ``i = −K y``."""
        K = pid_of(self.gains_at(speed_rad_s), self.channels)
        return control.ss(K.A, K.B, K.C, K.D, inputs=K.input_labels,
                          outputs=K.output_labels, states=K.state_labels,
                          name=name or self.name)

    def matrices_at(self, speed_rad_s: float) -> tuple[np.ndarray, ...]:
        """Physical ``(A_K, B_K, C_K, D_K)`` at Ω (rad/s)."""
        K = pid_of(self.gains_at(speed_rad_s), self.channels)
        return tuple(np.asarray(X, float) for X in (K.A, K.B, K.C, K.D))


def scheduled_pid(cfg) -> ScheduledPid | None:
    """The rig's reference PID scheduled on speed, where its cross gains are
    (``[controller.pid] cross_speed_rpm``); None where it is one fixed controller.

    Parameters
    ----------
    cfg : RigConfig

    Returns
    -------
    ScheduledPid or None
        Scheduled from standstill to the top of the stability speeds
        (:func:`ambseal.design.conditions.stability_speeds`).
    """
    pid = getattr(getattr(cfg, "controller", None), "pid", None)
    if pid is None or pid.cross_speed_rpm is None:
        return None
    p = reference_pid(cfg, speed_rpm=pid.cross_speed_rpm)
    top = 2 * np.pi * max(max(stability_speeds(cfg)[0]), pid.cross_speed_rpm / 60.0)
    return ScheduledPid(gains=p, channels=tuple(channel_names(cfg)),
                        speed_ref=2 * np.pi * pid.cross_speed_rpm / 60.0, top=top)


def reference_controller(cfg, method: str = "tustin"):
    """The rig's reference PID (:func:`reference_pid`) discretised plainly at
    ``[controller] sample_rate_hz`` (Tustin by default), described by its parameters: the
    controller a record of a real rig names by its PID parameters. What ambseal runs on
    the target (``ambseal acquire``, ``ambseal run``) is the discretisation chosen and
    judged by :mod:`ambseal.robust.digital` (:func:`ambseal.app.commands.target_pid`).

    Parameters
    ----------
    cfg : RigConfig
    method : {"tustin", "zoh"}

    Returns
    -------
    ambseal.robust.digital_loop.DiscreteController
        With ``description = {"type": "pid", kp, ti, td, eps, "discretisation"}``.
    """

    p = reference_pid(cfg)
    K = pid_of(p, channel_names(cfg))
    ctrl = discrete_controller(K, 1.0 / cfg.controller.sample_rate_hz, method)
    return replace(ctrl, description={"type": "pid", **pid_description(p),
                                      "discretisation": method})


def pid_description(p: dict) -> dict:
    """The PID's parameters as a record's or a controller file's ``controller`` metadata
    names them.

    Parameters
    ----------
    p : dict
        A PID as :func:`reference_pid` returns it.

    Returns
    -------
    dict
        ``kp`` (A/m), ``ti``, ``td`` (s), ``eps`` (-) and, where it has any, ``filters``
        (``[[controller.filter]]`` tables as dicts) and cross-axis gains (``cross_kp``,
        ``cross_kd``).
    """
    out = {k: p[k] for k in ("kp", "ti", "td", "eps")}
    if p.get("filters"):
        out["filters"] = [dict(f) for f in p["filters"]]
    out.update({k: p[k] for k in CROSS if p.get(k)})
    return out


#: The cross-axis gains of a PID description (:func:`pid_controller`), 0 when left out.
CROSS = ("cross_kp", "cross_kd")


def pid_of(p: dict, channels) -> control.StateSpace:
    """:func:`pid_controller` of a PID description (:func:`reference_pid`,
    :func:`pid_description`) on the rig's ``channels``.

    Parameters
    ----------
    p : dict
        ``kp``, ``ti``, ``td``, ``eps``, and optionally ``filters``, ``cross_kp`` and
        ``cross_kd``.
    channels : sequence of str
        The AMB channels (:func:`ambseal.model.amb.channel_names`).

    Returns
    -------
    control.StateSpace
    """
    return pid_controller(p["kp"], p["ti"], p["td"], p["eps"], channels, p.get("filters", ()),
                          *(float(p.get(k) or 0.0) for k in CROSS))


def controller_from_metadata(meta: dict, axes: tuple[str, ...], source: str = "<data>"):
    """The digital controller that ran, from a record's ``controller`` metadata, a PID
    description included.

    ``{"type": "pid", kp, ti, td, eps, "discretisation": "tustin"|"zoh"}`` (P5 Eq. 6 at the
    record's sample rate), with ``filters`` (``[[controller.filter]]`` tables) where the PID
    has any, is discretised here; anything else is read by
    :func:`ambseal.identify.fitting.stages.state_space_from_metadata`.

    Parameters
    ----------
    meta : dict
        A record's metadata (its ``controller`` and ``sample_rate_hz``).
    axes : tuple of str
        The rig's actuator axes, one controller input and output each.
    source : str, optional
        The record's file, for the messages.

    Returns
    -------
    DiscreteController
        The controller at the record's sample time, ``u = −K y``.

    Raises
    ------
    DataError
        Missing or malformed controller metadata, naming the file.
    """

    c = meta.get("controller")
    if not (isinstance(c, dict) and c.get("type") == "pid" and "state_space" not in c):
        return state_space_from_metadata(meta, axes, source)
    fs = sample_rate_of(meta, source)
    try:
        kp, ti, td, eps = (float(c[k]) for k in ("kp", "ti", "td", "eps"))
        if not (kp > 0 and ti > 0 and td >= 0 and eps > 0):
            raise ValueError("expected kp > 0, ti > 0, td >= 0, eps > 0")
        method = c.get("discretisation", "tustin")
        filters = c.get("filters", [])
        if not isinstance(filters, list):
            raise ValueError("filters: expected a list of [[controller.filter]] tables")
        filters = [PidFilter.model_validate(f) for f in filters]
        cross = [float(c.get(k, 0.0)) for k in CROSS]
        if not all(np.isfinite(cross)):
            raise ValueError("cross_kp, cross_kd: expected finite numbers")
        ctrl = discrete_controller(pid_controller(kp, ti, td, eps, axes, filters, *cross),
                                   1.0 / fs, method)
    except ValidationError as exc:
        raise DataError(f"{source}: metadata.controller.filters: "
                        f"{exc.errors()[0]['msg']}") from None
    except (KeyError, TypeError, ValueError) as exc:
        raise DataError(f"{source}: metadata.controller: {exc}") from None
    return check_controller(replace(ctrl, description=dict(c)), axes, fs, source)

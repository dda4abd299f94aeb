"""A closed-loop mode named by its kind, the words a rotordynamicist uses for it: rigid
cylindrical or rigid conical (the rotor moving as a rigid body, its ends in phase or in
opposition across the bearing span) or bending (the shaft's curvature), with its whirl
(forward, backward; at speed a forward conical mode is the gyroscopic nutation and a
backward one the precession: Genta, *Dynamics of Rotating Systems*, 2005, §4.6;
Schweitzer & Maslen, *Magnetic Bearings*, 2009, ch. on gyroscopic rotors).

The kind is read from the mode's lateral shape (:class:`ambseal.analysis.campbell.
ClosedLoopModes`): each plane's node amplitudes are fitted by a straight line in z, by
least squares weighted by each node's share of the shaft length; the shape is *bending*
when the residual carries more than :data:`BENDING_SHARE` of its norm, else rigid, and
then *cylindrical* when the line's amplitudes at the two ends of the bearing span move in
phase (Re Σ u_A ū_B ≥ 0 over both planes) and *conical* when they move in opposition.
A failing loop's line names it (:func:`failing_mode_kind`), so that the remedy can be
chosen for the mode that defeats the design."""

from __future__ import annotations

import numpy as np

from ambseal.analysis.campbell import closed_loop_modes

__all__ = ["mode_kind", "failing_mode_kind", "support_span_m", "BENDING_SHARE"]

#: Residual of the straight-line fit, as a share of the shape's norm, above which a mode
#: is a bending mode (a rigid mode on AMBs bends its shaft a few per cent)
BENDING_SHARE = 0.25
#: Below this speed (Hz) a conical mode has no gyroscopic name
_STANDSTILL_HZ = 1e-9


def support_span_m(cfg) -> tuple[float, float]:
    """The bearing span (m): the outermost AMB positions, or the shaft's ends with fewer
    than two AMBs.

    Parameters
    ----------
    cfg : RigConfig
        The rig.

    Returns
    -------
    (float, float)
        Axial positions of the span's ends (m), increasing.
    """
    z = sorted(a.position for a in cfg.amb)
    if len(z) >= 2 and z[-1] > z[0]:
        return float(z[0]), float(z[-1])
    return 0.0, float(cfg.length)


def mode_kind(shape_xy: np.ndarray, node_z_m: np.ndarray, span_m: tuple[float, float],
              whirl: str = "planar", speed_hz: float = 0.0) -> str:
    """The kind of one mode from its lateral shape (module docstring).

    Parameters
    ----------
    shape_xy : ndarray of complex, shape (n_nodes, 2)
        X and Y amplitude at each node (any scale).
    node_z_m : ndarray, shape (n_nodes,)
        Node positions (m), increasing.
    span_m : (float, float)
        The bearing span's ends (m), :func:`support_span_m`.
    whirl : str
        ``"forward"``, ``"backward"``, ``"mixed"`` or ``"planar"``
        (:func:`ambseal.analysis.campbell.whirl_of`).
    speed_hz : float
        Spin speed (Hz): above standstill a forward conical mode is named the nutation, a
        backward one the precession; at standstill no whirl is named.

    Returns
    -------
    str
        E.g. ``"rigid conical, backward whirl: the precession"``, ``"bending, forward
        whirl"``, ``"rigid cylindrical"`` (planar, or at standstill, where a rotor has no
        whirl of its own).

    Raises
    ------
    ValueError
        Shapes and positions of different lengths, fewer than two nodes, or a shape that
        does not move.
    """
    X = np.asarray(shape_xy, complex)
    z = np.asarray(node_z_m, float)
    if X.ndim != 2 or X.shape[1] != 2 or X.shape[0] != z.size or z.size < 2:
        raise ValueError(f"mode_kind: shape {X.shape} and {z.size} node positions; expected "
                         "(n_nodes, 2) and n_nodes ≥ 2 positions")
    # each node's share of the shaft: half of each neighbouring element
    w = np.zeros(z.size)
    dz = np.diff(z)
    w[:-1] += dz / 2
    w[1:] += dz / 2
    sw = np.sqrt(w)[:, None]
    norm = float(np.sqrt(np.sum(w[:, None] * np.abs(X) ** 2)))
    if not norm > 0:
        raise ValueError("mode_kind: the shape does not move")
    zc = float(np.sum(w * z) / np.sum(w))
    Z = np.column_stack([np.ones_like(z), z - zc])
    coef = np.linalg.lstsq(sw * Z, sw * X, rcond=None)[0]  # (2, 2): per plane a, b
    residual = float(np.sqrt(np.sum(w[:, None] * np.abs(X - Z @ coef) ** 2))) / norm
    if residual > BENDING_SHARE:
        kind = "bending"
    else:
        u = np.array([[1.0, e - zc] for e in span_m]) @ coef  # (2 ends, 2 planes)
        inphase = float(np.real(np.sum(u[0] * np.conj(u[1]))))
        kind = "rigid cylindrical" if inphase >= 0 else "rigid conical"
    # a rotor at standstill has no whirl of its own: an isotropic one's pair of modes is
    # one frequency, any combination of them an eigenvector
    if whirl not in ("forward", "backward") or abs(speed_hz) <= _STANDSTILL_HZ:
        return f"{kind}, mixed whirl" if whirl == "mixed" and speed_hz else kind
    text = f"{kind}, {whirl} whirl"
    if kind == "rigid conical":
        text += ": the nutation" if whirl == "forward" else ": the precession"
    return text


def failing_mode_kind(cfg, controller, *, pressure_bar: float, speed_hz: float,
                      pole: complex) -> str | None:
    """The kind of the closed-loop mode nearest ``pole``: the loop the run judges
    (:func:`ambseal.analysis.campbell.closed_loop_modes`, the target's delay included)
    at that pressure drop and speed, its oscillating mode closest to the pole.

    Parameters
    ----------
    cfg : RigConfig
        The rig.
    controller : control.StateSpace, ScheduledController or DigitalController
        The controller (``i = −K y``); a scheduled one frozen at the speed; a digital one
        designed on the sampled plant closed as it runs (:func:`closed_loop_modes`).
    pressure_bar, speed_hz : float
        The condition.
    pole : complex
        The failing pole (rad/s; a sampled loop's ln z / T).

    Returns
    -------
    str or None
        :func:`mode_kind` of that mode; None for a real (non-oscillating) pole or where
        the loop has no oscillating mode near it.
    """
    f = abs(complex(pole).imag) / (2 * np.pi)
    if not f > 0:
        return None
    m = closed_loop_modes(cfg, controller, speed_hz=speed_hz, pressure_bar=pressure_bar,
                          max_hz=1.5 * f + 10.0)
    if m.poles.size == 0:
        return None
    s = complex(pole.real, abs(pole.imag))
    k = int(np.argmin(np.abs(m.poles - s)))
    return mode_kind(m.shapes[k], m.node_z_m, support_span_m(cfg), m.whirl[k], speed_hz)

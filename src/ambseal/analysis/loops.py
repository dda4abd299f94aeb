"""Closed loops of an AMB plant and a controller: poles, S_o, S_i, T, KS and compliance.

AMB convention (thesis P5 §4, Fig. 8): the controller ``K`` maps sensor displacements (m) to
current references (A) and the loop is closed with **negative feedback**, ``u = −K y + d``,
so a PID with positive ``K_p`` stabilises the negative-stiffness plant ``G`` (P5 Eq. 1).

* output sensitivity ``S_o = (I + G K)⁻¹`` (ny × ny), the function ISO 14839-3 grades
  (P5 §4.1 item 4, Fig. 13);
* input sensitivity ``S_i = (I + K G)⁻¹`` (nu × nu);
* complementary sensitivity ``T_o = G K S_o`` (ny × ny);
* control sensitivity ``K S_o`` (nu × ny);
* compliance ``S_o G_f`` (ny × nf, m/N): displacements per unit external force, P5 §4.4.1,
  Fig. 11.

Frequencies are rad/s inside (``omega_rad_s``), Hz at the edges (``frequency_hz``).
Peaks are grid maxima: pass a grid dense enough around resonances.

The controller is connected by its signal names (:func:`ambseal.lti.interconnect.wired`):
a controller for ``[[amb]]`` A, B drives the same axes on a rig that lists B first, and a
missing, extra or renamed signal is an error; only a system without names is connected by
position.

The same functions close and evaluate **discrete** loops (plant and controller of one sample
time ``dt``, e.g. the ZOH-sampled plant and the controller that runs on the target): poles
are then ``z``, stable means ``|z| < 1``, and responses are taken at ``z = e^{jωdt}``
(ω up to Nyquist, π/dt).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from ambseal.errors import ModelError
from ambseal.lti import as_omega, freqresp_at, json_float, json_list, labels, ss_matrices, wired
from ambseal.machine import loop_matrices, sample_time

__all__ = [
    "LoopResponse",
    "Peak",
    "SensitivityPeaks",
    "ComplianceResponse",
    "loop_responses",
    "loop_responses_from",
    "sensitivity_peaks",
    "compliance",
    "compliance_from",
    "sigma_max",
    "peak_of",
    "resolved_grid",
    "resolved_peaks",
    "response_points",
]

_TWO_PI = 2.0 * np.pi


# --------------------------------------------------------------------------- results
@dataclass(frozen=True)
class Peak:
    """Peak of a gain over a frequency grid.

    Attributes
    ----------
    value : float
        Peak gain, in the unit of the function (dimensionless for sensitivities).
    frequency_hz : float
        Frequency of the peak (Hz).
    channel : str
        ``"sigma_max"`` for the largest singular value, else the channel name (diagonal element).
    """

    value: float
    frequency_hz: float
    channel: str = "sigma_max"

    @property
    def value_db(self) -> float:
        """Peak in dB (``20 log10 value``)."""
        return float(20.0 * np.log10(self.value)) if self.value > 0 else float("-inf")

    def to_dict(self) -> dict:
        return {
            "channel": self.channel,
            "value": json_float(self.value),
            "value_db": json_float(self.value_db),
            "frequency_hz": json_float(self.frequency_hz),
        }


@dataclass(frozen=True)
class SensitivityPeaks:
    """Peaks of one closed-loop function: of σ̄ and of each diagonal element.

    Attributes
    ----------
    sigma_max : Peak
        Peak of the largest singular value (the thesis's measure, P5 §4.1 item 4).
    diagonal : tuple of Peak
        Peak of ``|F_ii|`` per channel (the per-axis measure of ISO 14839-3).
    """

    sigma_max: Peak
    diagonal: tuple[Peak, ...]

    @property
    def max_diagonal(self) -> Peak:
        """The largest of the per-axis peaks."""
        return max(self.diagonal, key=lambda p: p.value)

    def to_dict(self) -> dict:
        return {"sigma_max": self.sigma_max.to_dict(), "diagonal": [p.to_dict() for p in self.diagonal]}


@dataclass(frozen=True, eq=False)
class LoopResponse:
    """S_o, S_i, T_o and K S_o of a closed loop on a frequency grid.

    Attributes
    ----------
    omega_rad_s : ndarray, shape (n_w,)
        Frequencies (rad/s).
    So : ndarray of complex, shape (n_w, ny, ny)
        Output sensitivity ``(I + G K)⁻¹``.
    Si : ndarray of complex, shape (n_w, nu, nu)
        Input sensitivity ``(I + K G)⁻¹``.
    To : ndarray of complex, shape (n_w, ny, ny)
        Complementary sensitivity ``G K S_o``.
    KS : ndarray of complex, shape (n_w, nu, ny)
        Control sensitivity ``K S_o`` (A/m).
    output_names, input_names : tuple of str
        Plant output (= sensor) and input (= actuator) channel names.
    """

    omega_rad_s: np.ndarray
    So: np.ndarray
    Si: np.ndarray
    To: np.ndarray
    KS: np.ndarray
    output_names: tuple[str, ...]
    input_names: tuple[str, ...]

    @property
    def frequency_hz(self) -> np.ndarray:
        """Frequencies (Hz), shape (n_w,)."""
        return self.omega_rad_s / _TWO_PI

    def _get(self, which: str) -> tuple[np.ndarray, tuple[str, ...]]:
        table = {"So": (self.So, self.output_names), "Si": (self.Si, self.input_names),
                 "To": (self.To, self.output_names), "KS": (self.KS, self.input_names)}
        if which not in table:
            raise ModelError(f"LoopResponse: which must be one of {sorted(table)}, got {which!r}")
        return table[which]

    def sigma_max(self, which: str = "So") -> np.ndarray:
        """Largest singular value of ``which`` ∈ {"So", "Si", "To", "KS"} per frequency, (n_w,)."""
        return sigma_max(self._get(which)[0])

    def peaks(self, which: str = "So", sigma: np.ndarray | None = None) -> SensitivityPeaks:
        """Peaks of σ̄ and of each diagonal element of ``which`` (diagonal of square part);
        ``sigma``: σ̄ of ``which`` per frequency when already computed (:meth:`sigma_max`)."""
        F, names = self._get(which)
        return _peaks(F, self.omega_rad_s, names, sigma)

    def to_dict(self) -> dict:
        """JSON-safe: frequency grid (Hz) and σ̄ of each function, plus S_o peaks."""
        return {
            "frequency_hz": json_list(self.frequency_hz),
            "sigma_max": {k: json_list(self.sigma_max(k)) for k in ("So", "Si", "To", "KS")},
            "So_peaks": self.peaks("So").to_dict(),
            "output_names": list(self.output_names),
            "input_names": list(self.input_names),
        }


@dataclass(frozen=True, eq=False)
class ComplianceResponse:
    """Compliance ``S_o G_f`` (m/N) on a frequency grid (P5 §4.4.1, Fig. 11).

    Attributes
    ----------
    omega_rad_s : ndarray, shape (n_w,)
        Frequencies (rad/s).
    H_m_per_n : ndarray of complex, shape (n_w, ny, nf)
        Displacements (m) per unit force (N).
    sigma_max_m_per_n : ndarray, shape (n_w,)
        Largest singular value (m/N), the upper bound of P5 Fig. 11.
    peak : Peak
        Peak of ``sigma_max_m_per_n`` (value in m/N).
    output_names, force_names : tuple of str
    """

    omega_rad_s: np.ndarray
    H_m_per_n: np.ndarray
    sigma_max_m_per_n: np.ndarray
    peak: Peak
    output_names: tuple[str, ...]
    force_names: tuple[str, ...]

    @property
    def frequency_hz(self) -> np.ndarray:
        """Frequencies (Hz), shape (n_w,)."""
        return self.omega_rad_s / _TWO_PI

    def to_dict(self) -> dict:
        return {
            "frequency_hz": json_list(self.frequency_hz),
            "sigma_max_m_per_n": json_list(self.sigma_max_m_per_n),
            "peak_m_per_n": json_float(self.peak.value),
            "peak_frequency_hz": json_float(self.peak.frequency_hz),
            "output_names": list(self.output_names),
            "force_names": list(self.force_names),
        }


# --------------------------------------------------------------------------- functions
def sigma_max(F: np.ndarray) -> np.ndarray:
    """Largest singular value per frequency of a stack ``F`` of shape (n_w, p, q) → (n_w,).

    Non-finite entries (a frequency on a pole) give ``inf``.
    """
    F = np.asarray(F)
    out = np.full(F.shape[0], np.inf)
    ok = np.all(np.isfinite(F), axis=(1, 2))
    if ok.any():
        out[ok] = np.linalg.svd(F[ok], compute_uv=False)[:, 0]
    return out


def peak_of(gain: np.ndarray, omega_rad_s: np.ndarray, channel: str = "sigma_max") -> Peak:
    """Grid maximum of a real gain curve (NaN ignored) as a :class:`Peak` (frequency in Hz)."""
    g = np.asarray(gain, dtype=float)
    if g.size == 0 or np.all(np.isnan(g)):
        return Peak(float("nan"), float("nan"), channel)
    k = int(np.nanargmax(g))
    return Peak(float(g[k]), float(omega_rad_s[k] / _TWO_PI), channel)


def _peaks(F: np.ndarray, w: np.ndarray, names: tuple[str, ...],
           sigma: np.ndarray | None = None) -> SensitivityPeaks:
    m = min(F.shape[1], F.shape[2])
    diag = tuple(peak_of(np.abs(F[:, i, i]), w, names[i] if i < len(names) else f"[{i}]") for i in range(m))
    return SensitivityPeaks(sigma_max=peak_of(sigma_max(F) if sigma is None else sigma, w),
                            diagonal=diag)


def resolved_grid(omega: Any, poles: np.ndarray, *, zeta_max: float = 0.2,
                  points: int = 41, width: float = 4.0) -> np.ndarray:
    """A frequency grid that resolves every lightly damped resonance.

    Adds, around each pole with damping ratio ζ < ``zeta_max`` and damped frequency ω_d
    inside the grid's range, ``points`` frequencies over ω_d (1 ± ``width``·ζ) — the
    half-power band is ω_d (1 ± ζ), so a single resonance's peak is caught within 0.5 % of
    its height (at most 0.1ζ·ω_d from a frequency: 1/√(1 + 0.01)) — and
    returns the sorted union with ``omega`` (rad/s). A 0.5 % damped bending mode is
    otherwise easily stepped over by a log grid.
    """
    w = as_omega(omega)
    extra = _windows(w, poles, zeta_max, points, width)
    out = np.unique(np.concatenate([w, *extra])) if extra else w
    return out[(out >= w.min()) & (out <= w.max())]


def _windows(w: np.ndarray, poles, zeta_max: float, points: int, width: float) -> list:
    """:func:`resolved_grid`'s frequencies around each lightly damped pole, one array per
    pole (unclipped)."""
    p = np.asarray(poles, complex)
    p = p[p.imag > 0]
    wn = np.abs(p)
    with np.errstate(invalid="ignore", divide="ignore"):
        zeta = -p.real / wn
    keep = (zeta < zeta_max) & (p.imag >= w.min()) & (p.imag <= w.max())
    return [wd * (1 + np.linspace(-width, width, points) * max(z, 1e-4))
            for wd, z in zip(p.imag[keep], np.abs(zeta[keep]))]


#: Spacing of the first pass of :func:`resolved_peaks` around a pole, in units of ζ·ω_d:
#: every second half-power width. A resonance's peak then lies within ζ·ω_d of a first-pass
#: frequency, where a single pole's |1/(1 + j x/ζ)| is at least 1/√2 of its peak.
PEAK_STENCIL_ZETA = 2.0


def resolved_peaks(omega: Any, poles: np.ndarray, evaluate, gains, *,
                   zeta_max: float = 0.2, points: int = 41, width: float = 4.0
                   ) -> tuple[np.ndarray, tuple]:
    """The maxima of :func:`resolved_grid`, evaluated on the part of it that can hold them.

    A first pass evaluates ``omega`` and, around each lightly damped pole, every
    :data:`PEAK_STENCIL_ZETA`-th ζ·ω_d of :func:`resolved_grid`'s frequencies; the second
    evaluates the rest of a pole's frequencies only where some gain there reaches 1/√2
    of its largest value in the first pass. Near a resonance its gain is at least 1/√2
    of the resonance's peak at the nearest first-pass frequency (a single pole,
    :data:`PEAK_STENCIL_ZETA`), so a resonance left out cannot exceed the first pass's
    maximum of any gain: the maxima are :func:`resolved_grid`'s to its own resolution,
    on a third to a half of its frequencies where a full-order rotor's aliased and high
    modes crowd the band (benchmarks/README.md, "Sensitivity peaks in two passes": the
    same on seven of the nine examples; up to 0.25 % lower on the blower, whose full-grid
    peak lay on a point of another pole's window).

    Parameters
    ----------
    omega : array_like, shape (n,)
        The base grid (rad/s), as :func:`resolved_grid`.
    poles : ndarray of complex
        The loop's poles (rad/s), as :func:`resolved_grid`.
    evaluate : callable
        ``evaluate(w)`` → a tuple of arrays whose first axis is ``w`` (the responses).
    gains : callable
        ``gains(*evaluate(w))`` → ndarray, shape (len(w), m): the gains whose maxima are
        wanted (σ̄ and each axis's, say).
    zeta_max, points, width
        As :func:`resolved_grid`.

    Returns
    -------
    w : ndarray, shape (n_w,)
        The frequencies evaluated, ascending: a subset of :func:`resolved_grid`'s.
    parts : tuple of ndarray
        ``evaluate``'s arrays on ``w``.
    """
    w = as_omega(omega)
    lo, hi = w.min(), w.max()
    windows = [x[(x >= lo) & (x <= hi)] for x in _windows(w, poles, zeta_max, points, width)]
    step = max(1, round(PEAK_STENCIL_ZETA * (points - 1) / (2 * width)))
    first = np.unique(np.concatenate([w, *(x[::step] for x in windows)]))
    parts = tuple(np.asarray(a) for a in evaluate(first))
    g = np.asarray(gains(*parts), float).reshape(first.size, -1)
    level = np.max(g, axis=0, initial=-np.inf) / math.sqrt(2.0)
    near = [x for x in windows if x.size and np.any(
        g[np.searchsorted(first, x[::step])] >= level)]
    rest = np.setdiff1d(np.concatenate(near), first) if near else first[:0]
    if not rest.size:
        return first, parts
    # with the first pass's ends, which a large plant's response checks its modal form at
    # (ambseal.lti.freqresp's probes): that check is then the first pass's, kept
    more = tuple(np.asarray(a)[1:-1] for a in evaluate(np.r_[first[0], rest, first[-1]]))
    order = np.argsort(np.concatenate([first, rest]), kind="stable")
    return (np.concatenate([first, rest])[order],
            tuple(np.concatenate([a, b])[order] for a, b in zip(parts, more)))


def loop_responses(G: Any, K: Any, omega: Any) -> LoopResponse:
    """S_o, S_i, T_o and K S_o of ``(G, K)`` on a frequency grid.

    ``G(jω)`` and ``K(jω)`` (or at ``e^{jωdt}``) come from
    :func:`ambseal.lti.freqresp.freqresp_at`; the small
    ``ny × ny`` / ``nu × nu`` inverses are batched ``numpy.linalg.solve`` calls over ω.

    Parameters
    ----------
    G, K : control.StateSpace
        Plant (A → m) and controller (m → A), negative feedback (module docstring).
    omega : array_like, shape (n_w,)
        Frequencies (rad/s).

    Returns
    -------
    LoopResponse

    Raises
    ------
    ModelError
        On dimension mismatch, a bad grid, or a grid frequency on an imaginary-axis pole of
        ``G`` or ``K`` (e.g. ω = 0 with an integral action: start the grid above 0).

    Notes
    -----
    The functions are evaluated whether or not the loop is stable; check
    :func:`closed_loop` ``.stable`` before reading a peak as a robustness margin.
    """
    w = as_omega(omega)
    loop_matrices(G, K)
    K = wired(G, K)
    ny, nu = ss_matrices(G, name="G", allow_discrete=True)[3].shape
    pts, kw = response_points(w, sample_time(G))
    return loop_responses_from(freqresp_at(G, pts, **kw), freqresp_at(K, pts), w,
                               labels(G, "output", ny, "y"), labels(G, "input", nu, "u"))


def loop_responses_from(Gw: np.ndarray, Kw: np.ndarray, w: np.ndarray,
                        ny_names: Sequence[str], nu_names: Sequence[str]) -> LoopResponse:
    """:func:`loop_responses` from the frequency responses ``G(jω)`` (n_w, ny, nu) and
    ``K(jω)`` (n_w, nu, ny) (or at ``e^{jωdt}``) already evaluated on ``w`` (rad/s) — for a
    caller that needs them for several loop functions (one eigendecomposition of the plant,
    not one per function). Raises ModelError as :func:`loop_responses` on a non-finite
    response."""
    _check_finite(w, Gw, Kw)
    ny, nu = Gw.shape[1:]
    GK = Gw @ Kw
    KG = Kw @ Gw
    So = _batched_inv(np.eye(ny) + GK)
    Si = _batched_inv(np.eye(nu) + KG)
    To = GK @ So
    KS = Kw @ So
    return LoopResponse(w, So, Si, To, KS, tuple(ny_names), tuple(nu_names))


def sensitivity_peaks(G: Any, K: Any, omega: Any, which: str = "So") -> SensitivityPeaks:
    """Peaks of σ̄ and of each diagonal element of S_o (or ``which``) over ``omega`` (rad/s).

    Shortcut for ``loop_responses(G, K, omega).peaks(which)``; frequencies reported in Hz.

    Parameters
    ----------
    G, K : control.StateSpace
        Plant (A → m) and controller (m → A), negative feedback, as in
        :func:`loop_responses`.
    omega : array_like, shape (n_w,)
        Frequencies (rad/s).
    which : {"So", "Si", "To", "KS"}
        The closed-loop function.

    Returns
    -------
    SensitivityPeaks
        The peak of σ̄ (thesis P5 §4.1) and of each diagonal element (ISO 14839-3, per
        axis), each with its frequency (Hz).

    Raises
    ------
    ModelError
        As :func:`loop_responses`, or an unknown ``which``.
    """
    return loop_responses(G, K, omega).peaks(which)


def compliance(G: Any, K: Any, Gf: Any, omega: Any) -> ComplianceResponse:
    """Compliance ``S_o(jω) G_f(jω)`` (m/N) of the closed loop, P5 §4.4.1 and Fig. 11.

    From ``y = G u + G_f f`` and ``u = −K y``: ``y = (I + G K)⁻¹ G_f f``.

    Parameters
    ----------
    G, K : control.StateSpace
        Plant and controller as in :func:`loop_responses`.
    Gf : control.StateSpace
        Force (N) → displacement (m) plant with the same outputs as ``G``.
    omega : array_like, shape (n_w,)
        Frequencies (rad/s).

    Returns
    -------
    ComplianceResponse

    Raises
    ------
    ModelError
        If ``Gf`` has a different number of outputs than ``G``, or a grid frequency is on an
        imaginary-axis pole of ``G``, ``K`` or ``Gf``.
    """
    w = as_omega(omega)
    loop_matrices(G, K)
    K = wired(G, K)
    pts, kw = response_points(w, sample_time(G))
    Gfw = freqresp_at(Gf, pts, **kw)
    Gw = freqresp_at(G, pts, **kw)
    if Gfw.shape[1] != Gw.shape[1]:
        raise ModelError(f"Gf has {Gfw.shape[1]} outputs, G has {Gw.shape[1]}: they must share outputs")
    return compliance_from(Gw, freqresp_at(K, pts), Gfw, w,
                           labels(G, "output", Gw.shape[1], "y"),
                           labels(Gf, "input", Gfw.shape[2], "f"))


def compliance_from(Gw: np.ndarray, Kw: np.ndarray, Gfw: np.ndarray, w: np.ndarray,
                    names_y: Sequence[str], names_f: Sequence[str]) -> ComplianceResponse:
    """:func:`compliance` from ``G(jω)``, ``K(jω)`` and ``G_f(jω)`` (n_w, ny, nf) (or at
    ``e^{jωdt}``) already evaluated on ``w`` (rad/s), as :func:`loop_responses_from`."""
    _check_finite(w, Gw, Kw, Gfw)
    ny = Gw.shape[1]
    H = _batched_solve(np.eye(ny) + Gw @ Kw, Gfw)
    sm = sigma_max(H)
    return ComplianceResponse(w, H, sm, peak_of(sm, w), tuple(names_y), tuple(names_f))


def response_points(w: np.ndarray, dt: float) -> tuple[np.ndarray, dict]:
    """``jω`` (continuous) or ``e^{jω dt}`` (discrete, ω at most Nyquist π/dt), and the
    options of :func:`freqresp_at` for the plant: near Nyquist the modal and Hessenberg
    forms of a ZOH-sampled full-order rotor agree to ~5e-8 (1e-11 below 1 kHz), so a
    discrete plant is checked at rtol 1e-6 rather than falling back to the O(n²)-per-point
    Hessenberg solve on thousands of frequencies."""
    if not dt:
        return 1j * w, {}
    if w.max() > np.pi / dt * (1 + 1e-9):
        raise ModelError(f"frequency grid reaches {w.max():.6g} rad/s, above the Nyquist "
                         f"frequency {np.pi / dt:.6g} rad/s of the discrete loop")
    return np.exp(1j * w * dt), {"rtol": 1e-6}


def _check_finite(w: np.ndarray, *responses: np.ndarray) -> None:
    """Raise if a grid frequency sits on an imaginary-axis pole of G, K or Gf."""
    for R in responses:
        bad = ~np.all(np.isfinite(R), axis=(1, 2))
        if bad.any():
            raise ModelError(
                f"frequency grid hits a pole on the imaginary axis at {w[bad][0]:.6g} rad/s"
                " (e.g. omega = 0 with an integrating controller); use a grid that avoids it"
            )


def _batched_inv(M: np.ndarray) -> np.ndarray:
    return _batched_solve(M, np.broadcast_to(np.eye(M.shape[1]), M.shape))


def _batched_solve(M: np.ndarray, R: np.ndarray) -> np.ndarray:
    """Solve ``M_k X_k = R_k`` for each k; singular or non-finite ``M_k`` give ``inf``."""
    out = np.full(M.shape[:2] + (R.shape[2],), np.inf + 0j)
    ok = np.all(np.isfinite(M), axis=(1, 2)) & np.all(np.isfinite(R), axis=(1, 2))
    if ok.any():
        try:
            out[ok] = np.linalg.solve(M[ok], R[ok])
        except np.linalg.LinAlgError:
            for k in np.flatnonzero(ok):
                try:
                    out[k] = np.linalg.solve(M[k], R[k])
                except np.linalg.LinAlgError:
                    pass
    return out

"""The controller that runs on the target: its discretisation chosen, not assumed.

A continuous controller (``u = −K y``) becomes the digital controller of a real-time
target in three steps (Franklin, Powell & Workman, *Digital Control of Dynamic
Systems*, 3rd ed., ch. 6):

1. **Fast poles removed.** Controller poles above ``FAST_FRACTION`` (one half) of the
   Nyquist frequency — H∞ and μ syntheses leave poles of several kHz from the roll-off of
   W_u, which no discretisation maps faithfully — are removed by singular perturbation
   (residualisation: the fast states held at their steady state, so the static gain is
   kept; Skogestad & Postlethwaite §11.4) in one state basis, the ordered real Schur basis
   of the slow poles. The rise of γ (H∞) or μ that this costs is reported by the
   caller's ``rise``;
   a fast pole that is unstable is refused. A fast pole that is
   stable and whose damped frequency |Im p|/2π lies below Nyquist aliases nothing under a
   hold equivalent (``z = e^{pT}`` inside the unit disc at an angle below π, which maps
   back to p alone; a real pole, a pair damped near ζ = 1, or a lightly damped pair
   between half of Nyquist and Nyquist, :func:`hold_keeps`), so when every fast pole
   does, the hold equivalents are also tried on the controller as designed (candidates
   ``zoh+fast``, ``foh+fast``; an H∞ controller with real poles at 5.9 and 7.9 kHz keeps
   them: its discrete σ̄(S_o) peaks are then those of the continuous loop to 0.1–3 %
   instead of up to 145 %; an LPV table's 6.3–6.6 kHz pairs, ζ ≥ 0.998, cost +7.5 % at
   its 190 Hz σ̄(S_o) peak when residualised, −0.3 % when kept under the triangle hold;
   a generated flywheel's LPV at 20 kHz with a pair at 5.1 kHz, ζ = 0.006, runs only with
   the pair kept; benchmarks/README.md).
2. **Candidates.** Tustin, Tustin pre-warped at the frequency that matters (the
   least-damped pole of the continuous loop on the full-order plant: where the loop is
   closest to instability, the controller's phase must be right), the zero-order-hold
   and the triangle-hold (first-order-hold) equivalents. MATLAB's "matched" pole-zero
   method is SISO only; the triangle hold is its state-space cousin for a MIMO
   controller (poles mapped as ``z = e^{sT}``, Franklin et al. §6.3.2).
3. **Choice.** Each candidate, delayed by ``delay_samples`` samples of computation, is
   closed with the full-order plant sampled exactly (ZOH) at each given condition; the
   candidate kept is stable wherever the continuous loop is (with the delay, or without
   it for a design that ignores the delay), and among those the one
   whose σ̄(S_o) peaks (log grid up to Nyquist) are closest to the continuous loop's
   (the largest relative difference over the conditions where the continuous loop is
   stable). The continuous loop here is the plant with the hold + computation delay as
   a Padé lag (:mod:`ambseal.robust.delay`), so the choice keeps the discrete loop closest to the
   continuous prediction of what runs. If none is, the controller is refused
   (:class:`~ambseal.errors.SynthesisError`) with the reason.

The result, :class:`DigitalController`, holds the one discrete controller object
(:class:`~ambseal.robust.digital_loop.DiscreteController`) that an export, a discrete
analysis and a simulation of the loop as it runs can all share.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property
from typing import Any, Callable, Sequence

import control
import numpy as np
import scipy.linalg as sla
from scipy.signal import cont2discrete

from ambseal.errors import ConfigError, ModelError, SynthesisError
from ambseal.lti import (
    feedback_poles,
    finite_or_none_tree,
    freqresp_at,
    sampled_response_at,
    series_inputs,
    ss_matrices,
    zoh,
)
from ambseal.robust._digital_choice import first_stable as _first_stable
from ambseal.robust._digital_choice import so_peak as _so_peak
from ambseal.robust.delay import loop_delay
from ambseal.robust.timing import MAX_DELAY_SAMPLES, check_timing
from ambseal.robust.digital_loop import DiscreteController
from ambseal.robust.stability import is_stable

__all__ = ["FAST_FRACTION", "DISCRETISATIONS", "PEAK_TOLERANCE", "chosen_error",
           "peak_difference", "DigitalController", "split_fast", "residualize",
           "hold_keeps", "HOLDS", "KEPT", "discretize_as", "with_delay",
           "digital_controller", "check_rate", "choose_method", "prewarp_frequency_hz",
           "SampledPlants", "sampled_plants"]

#: Controller poles above this fraction of the Nyquist frequency are removed before
#: discretisation (at half of Nyquist a Tustin pole is warped by 27 % in frequency and a
#: ZOH one already aliases its neighbourhood).
FAST_FRACTION = 0.5
#: Largest relative difference between the discrete and the continuous σ̄(S_o) peaks taken
#: as the same loop (10 %); a larger one is explained (:func:`peak_difference`).
PEAK_TOLERANCE = 0.10
#: The candidate discretisations, in the order they are tried.
DISCRETISATIONS = ("tustin", "tustin_prewarp", "zoh", "foh")
#: The hold equivalents, also tried with the fast poles kept where they alias nothing
#: (:func:`hold_keeps`; suffix ``KEPT``).
HOLDS, KEPT = ("zoh", "foh"), "+fast"

Matrices = tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]


@dataclass(frozen=True, eq=False)
class DigitalController:
    """A controller as it runs on the target, and how it was obtained.

    Attributes
    ----------
    continuous : control.StateSpace
        The continuous controller, measurements → commands, ``command = −K y``.
    reduced : control.StateSpace
        The continuous controller that was discretised (fast poles removed; ``continuous``
        when none were).
    discrete : DiscreteController
        ``x[k+1] = A x[k] + B y[k]``, ``u[k] = C x[k] + D y[k]``, command ``−u`` at ``dt = Ts``.
    method : str
        One of :data:`DISCRETISATIONS`.
    prewarp_hz : float or None
        Pre-warping frequency (Hz) of ``"tustin_prewarp"``.
    sample_rate_hz : float
    delay_samples : int
        Whole samples between reading ``y[k]`` and applying ``u[k]`` on the target.
    removed_poles_hz : tuple of float
        |p|/2π of the removed controller poles (Hz).
    reduction : dict or None
        The cost of the removal as the caller's ``rise`` reports it (e.g. ``order_full``,
        ``order`` and ``gamma_full``/``gamma`` or ``mu_full``/``mu``).
    candidates : tuple of dict
        Each candidate method: per condition ``max_abs_z`` and the σ̄(S_o) peaks
        ``sensitivity_peak`` (discrete, delay included) and ``sensitivity_peak_continuous``
        (``None`` where the loop is unstable), and ``sensitivity_peak_error`` (the largest
        relative distance between them). A candidate whose error ranks after the chosen
        one's was not closed with the sampled plants: ``stable`` and ``max_abs_z`` are
        ``None`` and ``not_checked`` says why (:func:`choose_method`).
    choice : str
        The candidate kept (``method``, or ``method + KEPT`` when the fast poles were kept).
    synthesis_plant : {"continuous", "sampled"}
        The plant ``continuous`` was designed on: ``"sampled"`` for a controller designed
        in the w-plane (:func:`~ambseal.robust.w_plane.w_plane_plant`), whose discrete form
        is its Tustin transform and whose ``continuous`` form is no loop that runs
        (:attr:`as_runs_only`).
    """

    continuous: Any = field(repr=False)
    reduced: Any = field(repr=False)
    discrete: DiscreteController = field(repr=False)
    method: str
    prewarp_hz: float | None
    sample_rate_hz: float
    delay_samples: int
    removed_poles_hz: tuple = ()
    reduction: dict | None = None
    candidates: tuple = ()
    choice: str = ""
    synthesis_plant: str = "continuous"

    @property
    def as_runs_only(self) -> bool:
        """True for a controller designed on the sampled plant: it exists only as it runs.
        Its ``continuous`` form is the w-plane controller, which closed with the continuous
        plant parts from the loop that runs towards Nyquist (the bilinear map warps
        frequency, w = (2/T)·tan(ωT/2)), so every loop of it is closed as it runs."""
        return self.synthesis_plant == "sampled"

    @property
    def Ts(self) -> float:
        """Sample time (s), MATLAB's name."""
        return 1.0 / self.sample_rate_hz

    @property
    def inputs(self) -> list[str]:
        return list(self.continuous.input_labels)

    @property
    def outputs(self) -> list[str]:
        return list(self.continuous.output_labels)

    def statespace(self, delayed: bool = False):
        """The discrete controller as a named ``control.StateSpace`` (``dt = Ts``); with
        ``delayed`` the computation delay included (what the plant sees)."""

        d = self.discrete
        mats = (d.A, d.B, d.C, d.D)
        if delayed:
            mats = with_delay(mats, self.delay_samples)
        return control.ss(*mats, self.Ts, inputs=self.inputs, outputs=self.outputs,
                          name=f"{self.continuous.name}_{self.method}")

    def to_dict(self) -> dict:
        """JSON-ready description (no matrices; non-finite numbers as ``None``)."""
        return finite_or_none_tree({"method": self.method, "choice": self.choice or self.method,
                "prewarp_hz": self.prewarp_hz,
                "sample_rate_hz": self.sample_rate_hz, "Ts": self.Ts,
                "delay_samples": self.delay_samples,
                "synthesis_plant": self.synthesis_plant,
                "fast_fraction_of_nyquist": FAST_FRACTION,
                "removed_poles_hz": [float(f) for f in self.removed_poles_hz],
                "order": int(self.discrete.A.shape[0]),
                "reduction": self.reduction,
                "peak_difference": peak_difference(chosen_error(self), self.method,
                                                   self.removed_poles_hz),
                "candidates": [dict(c) for c in self.candidates]})


def chosen_error(dc) -> float | None:
    """The chosen candidate's largest relative σ̄(S_o) peak difference on the choice grid.

    Parameters
    ----------
    dc : DigitalController or a scheduled controller's digital table
        Anything with ``choice`` (or ``method``) and the ``candidates`` of
        :func:`choose_method`.

    Returns
    -------
    float or None
        ``sensitivity_peak_error`` of the chosen candidate; None if it has none.
    """
    name = getattr(dc, "choice", "") or dc.method
    c = next((c for c in dc.candidates if c["method"] == name), None)
    return None if c is None else c.get("sensitivity_peak_error")


def peak_difference(err: float | None, method: str, removed_poles_hz) -> dict:
    """How far the discrete loop's σ̄(S_o) peaks are from the continuous ones, explained.

    Parameters
    ----------
    err : float or None
        Largest relative difference over the conditions (-): the choice's (400-point grid)
        or a later analysis's over its own conditions.
    method : str
        The chosen discretisation, named in the explanation when no fast pole was removed.
    removed_poles_hz : sequence of float
        The controller poles removed before discretisation (Hz); may be empty.

    Returns
    -------
    dict
        ``relative`` (``err``), ``within_tolerance`` (≤ :data:`PEAK_TOLERANCE`) and, when
        not, ``explanation``: the removal of fast poles (named, Hz) when there was one (the
        continuous loop keeps them, the discrete one cannot), else the discretisation.
    """
    out = {"relative": err, "tolerance": PEAK_TOLERANCE,
           "within_tolerance": err is not None and err <= PEAK_TOLERANCE}
    if err is not None and err > PEAK_TOLERANCE:
        fast = sorted({round(float(f)) for f in removed_poles_hz})
        why = (f"the controller's poles at {', '.join(f'{f:g}' for f in fast)} Hz, above half "
               "of Nyquist, are removed before discretisation (the continuous loop keeps "
               "them)" if fast else f"the {method} discretisation itself")
        out["explanation"] = (f"discrete σ̄(S_o) peak differs from the continuous one by "
                              f"{100 * err:.0f} % (> {100 * PEAK_TOLERANCE:.0f} %): {why}")
    return out


def check_rate(K, sample_rate_hz: float, delay_samples: int = 0, removable: bool = True
               ) -> None:
    """Refuse a sample rate or delay that cannot run ``K``: ``ConfigError`` naming them.

    A positive rate, a whole delay ≥ 0 and, unless the controller's fast poles may be
    removed (``removable``: a design whose γ or μ can be re-checked, or a scheduled one),
    a rate of at least twice its highest pole (Hz).

    Parameters
    ----------
    K : control.StateSpace or None
        The continuous controller (anything with a state matrix ``A``; a static gain or
        ``None`` has no poles to check).
    sample_rate_hz : float
        The target's sample rate (Hz).
    delay_samples : int, optional
        Computation delay (samples).
    removable : bool, optional
        Whether poles above half of Nyquist may be removed before discretisation; if not,
        the rate must be at least twice the highest pole.

    Raises
    ------
    ConfigError
        A rate or delay the target cannot run, naming ``controller.sample_rate_hz``.
    ModelError
        ``K`` with a NaN or infinite entry.
    """

    check_timing(sample_rate_hz, delay_samples)
    if K is not None and hasattr(K, "A"):
        ss_matrices(K, name="controller", allow_discrete=True, finite=True)
    A = np.asarray(getattr(K, "A", np.zeros((0, 0))), float)
    if not removable and A.size:
        f_max = float(np.abs(np.linalg.eigvals(A)).max()) / (2 * np.pi)
        if sample_rate_hz < 2 * f_max:
            raise ConfigError(
                f"controller.sample_rate_hz = {sample_rate_hz:g} Hz is below twice the "
                f"highest pole of {getattr(K, 'name', 'the controller')} ({f_max:.4g} Hz): "
                f"expected at least {2 * f_max:.4g} Hz")


def split_fast(A: np.ndarray, f_cut_hz: float) -> tuple[np.ndarray, int, np.ndarray]:
    """A basis ``V`` (n × n, real) in which ``A`` is block-diagonal: the ``k`` poles with
    ``|λ| ≤ 2π f_cut`` first, the fast ones after (ordered real Schur form, then a
    Sylvester equation removes the coupling block; Golub & Van Loan §7.6.3).

    Parameters
    ----------
    A : ndarray, shape (n, n)
        A real state matrix (rad/s).
    f_cut_hz : float
        The boundary (Hz): poles of modulus up to ``2π f_cut_hz`` are slow.

    Returns
    -------
    V : ndarray, shape (n, n)
        ``V⁻¹ A V = diag(A_slow, A_fast)``.
    k : int
        Number of slow poles.
    fast : ndarray of complex
        The fast poles (rad/s).
    """
    wc = 2 * np.pi * f_cut_hz
    T, Z, k = sla.schur(A, output="real", sort=lambda re, im: abs(complex(re, im)) <= wc)
    n = A.shape[0]
    X = sla.solve_sylvester(T[:k, :k], -T[k:, k:], -T[:k, k:]) if 0 < k < n else None
    S = np.eye(n)
    if X is not None:
        S[:k, k:] = X
    return Z @ S, int(k), np.linalg.eigvals(T[k:, k:]) if k < n else np.zeros(0, complex)


def hold_keeps(fast: np.ndarray, fs: float) -> bool:
    """Whether the hold equivalents may discretise a controller with its fast poles kept
    (module docstring, step 1; Franklin, Powell & Workman §6.3).

    Parameters
    ----------
    fast : array_like of complex, shape (n_f,)
        The controller's poles above ``FAST_FRACTION`` of Nyquist (rad/s).
    fs : float
        Sample rate (Hz).

    Returns
    -------
    bool
        True when there is one at least and each is stable with |Im p| below Nyquist
        ``fs/2`` (2π·fs/2 rad/s): ``z = e^{pT}`` inside the unit disc at an angle below π,
        aliasing no other frequency (the map from p to z is one to one in that strip).
        Whether the held controller then runs the loop as designed is for the choice
        (step 3) to judge.
    """
    fast = np.asarray(fast, complex)
    return bool(fast.size and is_stable(fast)
                and np.all(np.abs(fast.imag) < 2 * np.pi * fs / 2))


def residualize(mats: Matrices, V: np.ndarray, k: int) -> Matrices:
    """Singular perturbation of ``(A, B, C, D)`` in the basis ``V``: the last ``n − k``
    states held at steady state, ``x₂ = −A₂₂⁻¹ (A₂₁ x₁ + B₂ y)`` (keeps the static gain;
    Skogestad & Postlethwaite, *Multivariable Feedback Control*, Eq. 11.26).

    Parameters
    ----------
    mats : (A, B, C, D)
        A continuous system, ``n`` states.
    V : ndarray, shape (n, n)
        The state basis (:func:`split_fast`): ``V⁻¹ A V`` block-diagonal, slow block first.
    k : int
        States kept (the slow block).

    Returns
    -------
    (A, B, C, D)
        The residualised system, ``k`` states, the same inputs and outputs.
    """
    A, B, C, D = mats
    At = np.linalg.solve(V, A @ V)
    Bt = np.linalg.solve(V, B)
    Ct = C @ V
    A11, A12, A21, A22 = At[:k, :k], At[:k, k:], At[k:, :k], At[k:, k:]
    if A22.size == 0:
        return At, Bt, Ct, D
    X = np.linalg.solve(A22, np.hstack([A21, Bt[k:]]))
    X21, X2 = X[:, :k], X[:, k:]
    return (A11 - A12 @ X21, Bt[:k] - A12 @ X2, Ct[:, :k] - Ct[:, k:] @ X21,
            D - Ct[:, k:] @ X2)


def discretize_as(mats: Matrices, dt: float, method: str, prewarp_hz: float | None = None
                  ) -> Matrices:
    """Discrete equivalent of continuous ``(A, B, C, D)`` by one of :data:`DISCRETISATIONS`.

    ``"tustin"``/``"tustin_prewarp"``: python-control's bilinear transform (with
    ``prewarp_frequency`` 2π·``prewarp_hz``); ``"zoh"``: :func:`ambseal.lti.discrete.zoh`;
    ``"foh"``: SciPy's triangle-hold equivalent (``cont2discrete(method="foh")``).

    Parameters
    ----------
    mats : (A, B, C, D)
        The continuous system.
    dt : float
        Sample time (s).
    method : str
        One of :data:`DISCRETISATIONS`.
    prewarp_hz : float, optional
        The frequency matched exactly by ``"tustin_prewarp"`` (Hz), below Nyquist.

    Returns
    -------
    (A, B, C, D)
        The discrete system at ``dt``, float arrays, the same number of states.

    Raises
    ------
    ConfigError
        Unknown method, or ``"tustin_prewarp"`` without a frequency below Nyquist.
    ModelError
        ``mats`` no system of consistent shapes, or with a NaN or infinite entry.
    """

    A, B, C, D = ss_matrices(mats if hasattr(mats, "A") else tuple(mats), name="controller",
                             finite=True)
    if method == "zoh":
        Ad, Bd = zoh(A, B, dt)
        return Ad, Bd, C.copy(), D.copy()
    if method == "foh":
        Ad, Bd, Cd, Dd, _ = cont2discrete((A, B, C, D), dt, method="foh")
        return tuple(np.asarray(X, float) for X in (Ad, Bd, Cd, Dd))
    if method not in ("tustin", "tustin_prewarp"):
        raise ConfigError(f"discretisation method {method!r}: expected one of {DISCRETISATIONS}")
    w0 = None
    if method == "tustin_prewarp":
        if prewarp_hz is None or not 0 < prewarp_hz < 0.5 / dt:
            raise ConfigError(f"tustin_prewarp: prewarp_hz={prewarp_hz!r}, expected a "
                              f"frequency between 0 and Nyquist ({0.5 / dt:g} Hz)")
        w0 = 2 * np.pi * prewarp_hz
    d = control.sample_system(control.ss(A, B, C, D), dt, "tustin", prewarp_frequency=w0)
    return tuple(np.asarray(X, float) for X in (d.A, d.B, d.C, d.D))


def with_delay(mats: Matrices, n: int) -> Matrices:
    """The discrete controller followed by ``n`` samples of delay, ``u[k] = v[k − n]``:
    ``n·nu`` extra states holding the last outputs.

    Parameters
    ----------
    mats : (A, B, C, D)
        A discrete system, ``nu`` outputs.
    n : int
        Delay (samples), ≥ 0.

    Returns
    -------
    (A, B, C, D)
        The delayed system, ``n·nu`` states more.

    Raises
    ------
    ConfigError
        ``n`` not a whole number of samples from 0 to
        :data:`~ambseal.robust.timing.MAX_DELAY_SAMPLES`.
    """
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)) \
            or not 0 <= n <= MAX_DELAY_SAMPLES:
        raise ConfigError(f"with_delay: n={n!r}, expected a whole number of samples from 0 "
                          f"to {MAX_DELAY_SAMPLES}")
    A, B, C, D = mats
    for _ in range(int(n)):
        nk, (nu, ny) = A.shape[0], D.shape
        A = np.block([[A, np.zeros((nk, nu))], [C, np.zeros((nu, nu))]])
        B = np.vstack([B, D])
        C = np.hstack([np.zeros((nu, nk)), np.eye(nu)])
        D = np.zeros((nu, ny))
    return A, B, C, D


def prewarp_frequency_hz(G_list, K: Matrices, fs: float, *, lag: Matrices | None = None
                         ) -> float | None:
    """Damped frequency (Hz) of the least-damped pole of the continuous loops below half
    of Nyquist, the frequency where the discrete controller's phase matters most.

    Parameters
    ----------
    G_list : sequence of (A, B, C, D)
        The continuous plants, each closed with ``K`` as ``u = −K y``.
    K : (A, B, C, D)
        The continuous controller.
    fs : float
        Sample rate (Hz).
    lag : (A, B, C, D), optional
        A SISO lag in front of every plant input (the hold and computation delay).

    Returns
    -------
    float or None
        The frequency (Hz); ``None`` if no loop has a pole with a damped frequency between
        0 and ``FAST_FRACTION`` of Nyquist.
    """
    best, f_best = np.inf, None
    for G in G_list:
        lam = feedback_poles(G, K, lag=lag, dt=0.0)
        lam = lam[(lam.imag > 0) & (lam.imag < 2 * np.pi * FAST_FRACTION * fs / 2)]
        if lam.size:
            zeta = -lam.real / np.abs(lam)
            i = int(np.argmin(zeta))
            if zeta[i] < best:
                best, f_best = zeta[i], float(lam[i].imag / (2 * np.pi))
    return f_best


def _remove_fast(K, mats: Matrices, fs: float, rise: Callable | None):
    """Fast poles removed (module docstring, step 1): (matrices, StateSpace, poles, rise).
    Nothing is removed without ``rise`` (no design to report the cost on)."""

    f_cut = FAST_FRACTION * fs / 2
    if not mats[0].size or rise is None:
        return mats, K, np.zeros(0), None
    V, k, fast = split_fast(mats[0], f_cut)
    if not fast.size:
        return mats, K, fast, None
    if not is_stable(fast):
        raise SynthesisError(
            f"controller.sample_rate_hz = {fs:g} Hz: {K.name} has unstable poles above "
            f"{f_cut:g} Hz (half of Nyquist), which cannot be removed; raise the sample "
            "rate or redesign")
    reduced = residualize(mats, V, k)
    Kr = control.ss(*reduced, inputs=list(K.input_labels), outputs=list(K.output_labels),
                    name=f"{K.name}_r")
    return reduced, Kr, fast, rise(Kr)


@dataclass(frozen=True, eq=False)
class SampledPlants:
    """The full-order plants the choice is made on, continuous (``ideal``: where the
    design must run stably; ``plants``: with the hold + computation delay of
    ``delay_samples`` as the Padé lag ``lag`` on every input) and ZOH-sampled at ``fs``
    (``sampled``: without, the delay is the discrete controller's), with their frequency
    responses on a log grid up to Nyquist: computed once, shared by every controller
    chosen for the same conditions (:func:`sampled_plants`). The choice itself needs only
    ``ideal`` and ``lag`` (its loops' poles come from the plants' modal forms);
    ``plants`` and ``sampled`` are formed when first asked for."""

    fs: float
    omega_rad_s: np.ndarray
    continuous_response: list
    sampled_response: list
    ideal: list
    lag: tuple

    @cached_property
    def plants(self) -> list:
        """The continuous plants with the lag before every input, ``(A, B, C, D)``."""
        return [series_inputs(G, self.lag)[:4] for G in self.ideal]

    @cached_property
    def sampled(self) -> list:
        """The plants sampled by a zero-order hold at ``fs`` (:func:`zoh`), ``(A, B, C, D)``."""
        return [(*zoh(G[0], G[1], 1.0 / self.fs), G[2], G[3]) for G in self.ideal]

    def delayed_poles(self, j: int, K: Matrices) -> np.ndarray:
        """Poles of ``K`` closed on plant ``j`` with the lag (``plants[j]``): from the
        plant without it and the lag joined to the controller
        (:func:`~ambseal.lti.interconnect.feedback_poles`), the plant's modal form then
        shared with its frequency responses."""
        return feedback_poles(self.ideal[j], K, lag=self.lag, dt=0.0)


def sampled_plants(plants: Sequence[Matrices], fs: float, n_grid: int = 400, *,
                   delay_samples: int = 1) -> SampledPlants:
    """:class:`SampledPlants` of continuous ``(A, B, C, D)`` plants at ``fs`` (Hz): the
    responses on ``n_grid`` log-spaced frequencies from 1 Hz to Nyquist — at ``jω`` the
    plant's (:func:`freqresp_at`) times the Padé lag's of ``delay_samples`` + ½ samples
    (:func:`ambseal.robust.delay.loop_delay`), at ``e^{jωT}`` the sampled plant's from
    the continuous plant's modal form (:func:`ambseal.lti.freqresp.sampled_response_at`,
    checked at rtol 1e-6); the delayed and sampled plants themselves when asked for.

    Parameters
    ----------
    plants : sequence of (A, B, C, D)
        The continuous full-order plants, one per condition.
    fs : float
        Sample rate (Hz).
    n_grid : int, optional
        Frequencies of the grid.
    delay_samples : int, optional
        Computation delay (samples) of the target.

    Returns
    -------
    SampledPlants

    Raises
    ------
    ConfigError
        A rate or delay out of range (:func:`~ambseal.robust.timing.check_timing`).
    ModelError
        A plant that is no ``(A, B, C, D)`` of consistent shapes, or has a NaN or infinite
        entry.
    """

    check_timing(fs, delay_samples)
    T = 1.0 / fs
    w = 2 * np.pi * np.logspace(0, np.log10(0.999 * fs / 2), n_grid)
    plants = [ss_matrices(G if hasattr(G, "A") else tuple(G), name=f"plants[{k}]",
                          finite=True) for k, G in enumerate(plants)]
    L = loop_delay(fs, delay_samples).system
    L = tuple(np.asarray(getattr(L, m), float) for m in ("A", "B", "C", "D"))
    # the lag is one SISO block before every input: the delayed plant's response is the
    # plant's times the lag's, and the sampled plant's comes from the plant's modal form
    lag = freqresp_at(L, 1j * w)[:, :1, :1]
    return SampledPlants(float(fs), w, [freqresp_at(G, 1j * w) * lag for G in plants],
                         [sampled_response_at(G, T, w) for G in plants], plants, L)


def choose_method(sp: SampledPlants, cont: list, discrete: Callable, delay: int, methods,
                  f_pw: float | None, name: str, foreseen: bool = True):
    """Step 3 of the module docstring: the candidates closed with each sampled plant.

    Parameters
    ----------
    sp : SampledPlants
        The plants, continuous and sampled, with their responses (:func:`sampled_plants`).
    cont : list of (A, B, C, D)
        The continuous controller at each plant (``u = −K y``).
    discrete : callable
        ``discrete(method)`` → the discrete controllers (matrices) at every plant.
    delay : int
        Computation delay (samples), appended to each discrete controller.
    methods : sequence of str
        The candidates tried, in order (:data:`DISCRETISATIONS`, the hold equivalents with
        :data:`KEPT`).
    f_pw : float or None
        Prewarp frequency (Hz) of ``"tustin_prewarp"``; ``None`` skips that candidate.
    name : str
        The controller's name in the error message.
    foreseen : bool
        Whether the continuous loop is the one the design foresaw, so that the sampled
        loop must be stable wherever it is (the default). False for a controller designed
        on the sampled plant (in the w-plane), whose foreseen loop is the sampled one
        itself: nothing is asked of it here, and where its loop as it runs is unstable
        the judgement says so.

    Returns
    -------
    method : str
        The chosen candidate.
    discrete : list of (A, B, C, D)
        Its discrete controllers, one per plant, without the delay.
    candidates : tuple of dict
        Every candidate tried: ``method``, ``stable``, ``max_abs_z``, the σ̄(S_o) peaks
        and ``sensitivity_peak_error``.

    Raises
    ------
    SynthesisError
        No candidate keeps every sampled loop stable where the continuous loop is.

    Notes
    -----

    The kept candidate is the one with the smallest σ̄(S_o) peak error (first in
    ``methods`` on a tie) among those stable wherever the design is. Each candidate's error
    comes from its frequency responses alone; the sampled loops' poles (one eigenvalue
    problem of the full-order loop per plant, most of the cost) are then computed in the
    order of the errors, only until the first stable candidate
    (``first_stable`` of the module ``_digital_choice``): a candidate that ranks after it
    cannot be chosen, and is reported with ``stable`` and ``max_abs_z`` ``None`` and the
    reason (``not_checked``).
    """
    fs, T, w = sp.fs, 1.0 / sp.fs, sp.omega_rad_s

    # the sampled loop must be stable wherever the continuous loop is, without the delay
    # (a design that ignores it) or with it (a design that carries it, as the H∞, μ and
    # LPV designs do: without the delay their loop may be unstable, and a rule on the
    # undelayed loop alone then asked nothing of the sampled one); the peaks are compared
    # where both are stable
    ideal_stable = [is_stable(feedback_poles(G, Kc, dt=0.0)) for G, Kc in zip(sp.ideal, cont)]
    delayed_stable = [is_stable(sp.delayed_poles(j, Kc)) for j, Kc in enumerate(cont)]
    cont_stable = [foreseen and (a or b) for a, b in zip(ideal_stable, delayed_stable)]
    judged = [j for j in range(len(cont)) if ideal_stable[j] and delayed_stable[j]]
    peak_c = {j: _so_peak(sp.continuous_response[j], freqresp_at(cont[j], 1j * w))
              for j in judged}
    n = len(sp.ideal)
    cands, Kd = [], {}
    for m in methods:
        if m == "tustin_prewarp" and f_pw is None:
            continue
        Kds = discrete(m)
        Kdel = [with_delay(K, delay) for K in Kds]
        peak_d = [_so_peak(sp.sampled_response[j], freqresp_at(Kdel[j], np.exp(1j * w * T)))
                  if j in peak_c else None for j in range(n)]
        err = max((abs(peak_d[j] - peak_c[j]) / peak_c[j] for j in judged), default=0.0)
        Kd[m] = Kds, Kdel
        cands.append({"method": m, "max_abs_z": [None] * n, "sensitivity_peak": peak_d,
                      "sensitivity_peak_continuous": [peak_c.get(j) for j in range(n)],
                      "sensitivity_peak_error": err, "stable": None})
    best = _first_stable(cands, Kd, sp.ideal, T, cont_stable)
    if best is None:
        raise SynthesisError(_none_holds(cands, cont_stable, fs, delay, name, methods))
    return best["method"], Kd[best["method"]][0], tuple(cands)


def _none_holds(cands: list, cont_stable: list, fs: float, delay: int, name: str,
                methods) -> str:
    """Why no candidate of :func:`choose_method` runs: the candidate whose sampled loop
    comes closest to stable (the smallest largest |z| where the continuous loop is stable)
    and where. The controller's own poles are not the reason (those above half of Nyquist
    were removed or kept by a hold that aliases nothing); the gap is between the sampled
    loop and the continuous one the design foresaw, which narrows as the rate rises."""
    def worst(c):
        zs = [(z, j) for j, (z, ok) in enumerate(zip(c["max_abs_z"], cont_stable))
              if ok and z is not None]
        return max(zs) if zs else (float("inf"), -1)

    closest = min(cands, key=lambda c: worst(c)[0])
    z, j = worst(closest)
    n_bad = sum(1 for zj, ok in zip(closest["max_abs_z"], cont_stable)
                if ok and zj is not None and zj >= 1)
    return (f"controller.sample_rate_hz = {fs:g} Hz (delay {delay} samples): no "
            f"discretisation of {name} ({', '.join(methods)}) keeps the sampled loop stable "
            f"where the continuous loop is; the closest, {closest['method']}, leaves a "
            f"sampled-loop pole at |z| = {z:.6g} (condition {j + 1} of {len(cont_stable)}; "
            f"unstable at {n_bad}): the loop as it runs differs from the continuous one "
            "its design foresaw, a gap that narrows as the rate rises: raise "
            "controller.sample_rate_hz or lower controller.delay_samples")


def digital_controller(K, sample_rate_hz: float, plants, *,
                       delay_samples: int = 1, rise: Callable | None = None,
                       methods: Sequence[str] = DISCRETISATIONS,
                       w_plane: bool = False) -> DigitalController:
    """Choose the discrete controller that runs on the target (module docstring).

    Parameters
    ----------
    K : control.StateSpace
        Continuous controller, measurements → commands, ``command = −K y``.
    sample_rate_hz : float
        The target's sample rate (Hz).
    plants : sequence of (A, B, C, D), or SampledPlants
        Full-order continuous plants (commands → measurements) at the conditions the
        controller must run at (or :func:`sampled_plants` of them at ``sample_rate_hz``).
    delay_samples : int
        Computation delay of the target (samples).
    rise : callable, optional
        ``rise(K_reduced) → dict or None`` reporting the cost of removing fast poles
        (e.g. the rise of a design's H∞ norm or μ); without it the controller's poles
        are not removed and a rate below twice the highest is refused.
    methods : sequence of str
        Candidates, a subset of :data:`DISCRETISATIONS`.
    w_plane : bool
        ``K`` was designed on the sampled plant in the w-plane
        (:func:`~ambseal.robust.w_plane.w_plane_plant`): its Tustin transform without
        prewarp is the discrete design itself, the only candidate, nothing removed
        (``rise`` and ``methods`` ignored); its poles, however fast, map inside the unit
        circle, so the rate check does not apply; and its sampled loop is the loop it
        foresaw, so none is refused for parting from ``K`` closed in continuous time
        (:func:`choose_method`'s ``foreseen``): where it is unstable the judgement says so.

    Returns
    -------
    DigitalController

    Raises
    ------
    ConfigError
        A bad sample rate or delay.
    ModelError
        No plant given.
    SynthesisError
        An unstable fast pole, or no candidate keeps the sampled loop stable where the
        continuous loop is: the reason names the rate and the controller's poles.
    """
    if w_plane:
        check_timing(sample_rate_hz, delay_samples)
        rise, methods = None, ("tustin",)
    else:
        check_rate(K, sample_rate_hz, delay_samples, removable=rise is not None)
    if not isinstance(plants, SampledPlants) and len(plants) == 0:
        raise ModelError("digital_controller: plants is empty; expected the full-order plant "
                         "at one condition at least, (A, B, C, D) each")
    fs, T = float(sample_rate_hz), 1.0 / float(sample_rate_hz)
    mats = tuple(np.asarray(X, float) for X in (K.A, K.B, K.C, K.D))
    reduced, Kr, fast, red = _remove_fast(K, mats, fs, rise)
    sp = plants if isinstance(plants, SampledPlants) else sampled_plants(
        plants, fs, delay_samples=delay_samples)
    if abs(sp.fs - fs) > 1e-9 * fs:
        raise ConfigError(f"digital_controller: plants sampled at {sp.fs} Hz, not {fs} Hz")
    n = len(sp.ideal)
    f_pw = None if w_plane else prewarp_frequency_hz(sp.ideal, mats, fs, lag=sp.lag)
    keep = hold_keeps(fast, fs)
    tried = list(methods) + ([f"{m}{KEPT}" for m in HOLDS if m in methods] if keep else [])

    def discrete(m):
        base = m.removesuffix(KEPT)
        return [discretize_as(mats if m.endswith(KEPT) else reduced, T, base, f_pw)] * n

    m, Kds, cands = choose_method(sp, [mats] * n, discrete, int(delay_samples), tried, f_pw,
                                  str(K.name), foreseen=not w_plane)
    choice = m
    if m.endswith(KEPT):  # the controller as designed: nothing removed
        m, Kr, fast, red = m.removesuffix(KEPT), K, np.zeros(0), None
    desc = {"type": "state_space", "name": str(K.name), "discretisation": m}
    return DigitalController(
        continuous=K, reduced=Kr, discrete=DiscreteController(*Kds[0], T, description=desc),
        method=m, prewarp_hz=f_pw if m == "tustin_prewarp" else None, sample_rate_hz=fs,
        delay_samples=int(delay_samples),
        removed_poles_hz=tuple(sorted(float(abs(p)) / (2 * np.pi) for p in fast)),
        reduction=red, candidates=cands, choice=choice,
        synthesis_plant="sampled" if w_plane else "continuous")

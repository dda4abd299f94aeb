"""The design model's flexible modes over the speed range, and their natural frequency as
an uncertain parameter of the μ design.

A μ controller is designed on the plant frozen at one speed (the design speed). The
gyroscopic moments move each flexible mode with the speed: the forward whirl up, the
backward whirl down, the pair splitting from one frequency at standstill. A lightly
damped mode the controller phase-stabilises at the design speed may meet it at another
frequency elsewhere in the speed range and go unstable. μ holds it over the range when the
mode's frequency is one of the uncertain parameters, over the band it sweeps:

* :func:`mode_bands` follows each lightly damped mode of the design model from the design
  speed over the judged speeds (the LPV model of :func:`ambseal.design.lpv_plant.lpv_plant`:
  the same modal reduction, its projected gyroscopic term, thesis P3 Eqs. 4–10), matching
  eigenvalues between neighbouring speeds;
* :func:`with_modal_frequencies` adds, per band, one real parameter θ = ω_d² (rad²/s²) to
  the design plant as a rank-one LFT channel that moves that mode alone. With λ = σ + jω_d
  a mode of A, v = v_r + j v_i its right eigenvector and w = w_r + j w_i its left one
  (w v = 1), A [v_r, v_i] = [v_r, v_i] [[σ, ω_d], [−ω_d, σ]], and the left basis is
  [2 w_r; −2 w_i]. The change ``ΔA = −(θ − ω_d²)/ω_d · v_i (2 w_r)`` turns that block
  into [[σ, ω_d], [−θ/ω_d, σ]], whose eigenvalues are σ ± j√θ exactly, and leaves every
  other eigenvalue where it was (it acts inside the mode's invariant subspace): θ is the
  mode's squared damped frequency, entering A affinely as the LFT of thesis P1 Eqs. 46–52
  asks. The real parameter is one scalar block (Young's D–G–K keeps it real). v is known
  only up to a phase, and the channel turns with it: the phase is fixed by a rule
  (:func:`_fixed_phase`), not by the BLAS kernels' rounding.

This is the modal-parameter uncertainty of flexible-structure robust control (natural
frequencies as real parametric uncertainty in μ-synthesis; e.g. Balas & Doyle,
"Robustness and performance trade-offs in control design for flexible structures", IEEE
Transactions on Control Systems Technology, 1994).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
from scipy.optimize import linear_sum_assignment

from ambseal.design.lpv_plant import lpv_plant
from ambseal.design.specs import RIGID_STATES
from ambseal.errors import ModelError
from ambseal.model import Parameter, Plant

__all__ = ["ModeBand", "mode_bands", "with_modal_frequencies", "bands_near"]

_TWO_PI = 2.0 * np.pi

#: Modes with damping ratio below this are the lightly damped (structural) ones a damping
#: margin or a mode band applies to; rigid-body modes on AMBs are real and unstable, the
#: actuator's poles real: neither is touched.
LIGHT_DAMPING = 0.2

#: Speeds (evenly spaced over the judged range, plus the design speed) on which the modes
#: are followed: the gyroscopic shift is smooth in Ω, and neighbouring speeds this close
#: keep each mode nearest to itself (a step of 1/30 of the range).
TRACK_POINTS = 31

#: A lost mode is taken to be a band's when its frequency lies in the band widened by this
#: factor: the controller moves a closed-loop mode a little off its open-loop frequency.
BAND_MATCH = 1.05


@dataclass(frozen=True)
class ModeBand:
    """One lightly damped mode of the design model and the band it sweeps with speed.

    Attributes
    ----------
    f_hz : float
        Damped natural frequency Im λ/2π at the design speed (Hz).
    lo_hz, hi_hz : float
        Lowest and highest Im λ/2π over the speed range (Hz), lo_hz ≤ f_hz ≤ hi_hz.
    """

    f_hz: float
    lo_hz: float
    hi_hz: float

    @property
    def name(self) -> str:
        """The LFT parameter's name, ``"mode_<f>Hz.omega_sq"``."""
        return f"mode_{self.f_hz:.0f}Hz.omega_sq"

    def text(self) -> str:
        """``"255 Hz (241–256 Hz)"``: the mode and its band, for messages."""
        return f"{self.f_hz:.4g} Hz ({self.lo_hz:.4g}–{self.hi_hz:.4g} Hz)"


def _light(lam: np.ndarray, light_damping: float, growing: bool = False) -> np.ndarray:
    """The oscillatory poles damped below ``light_damping``; with ``growing`` those of
    negative damping too."""
    mag = np.abs(lam)
    zeta = -lam.real / np.maximum(mag, 1e-300)
    return (lam.imag > 1e-9 * mag) & ((zeta > 0) | growing) & (zeta < light_damping)


def mode_bands(cfg, speeds_hz, *, design_speed_hz: float, states: int,
               light_damping: float = LIGHT_DAMPING) -> tuple[ModeBand, ...]:
    """The band each lightly damped mode of the design model sweeps over a speed range.

    Parameters
    ----------
    cfg : ambseal.config.RigConfig
        The rig.
    speeds_hz : array_like
        The speeds judged (Hz); their span is the range followed.
    design_speed_hz : float
        The design model's speed (Hz), the one its modes are named at.
    states : int
        Mechanical states of the design model (its modal reduction).
    light_damping : float
        Flexible modes with damping ratio between 0 and this are followed; the
        :data:`~ambseal.design.specs.RIGID_STATES` eigenvalues nearest zero are the
        rigid-body modes on the AMBs, which the feedback itself places, and are not.

    Returns
    -------
    tuple of ModeBand
        By frequency at the design speed; a mode whose band is a point (no gyroscopic
        shift) is left out.

    Raises
    ------
    ModelError
        A negative speed, or a modal reduction that cannot be made.
    """

    f = np.asarray(speeds_hz, float).ravel()
    f0 = float(design_speed_hz)
    if f.size == 0 or np.any(f < 0) or f0 < 0:
        raise ModelError(f"mode_bands: speeds {f.tolist()} Hz, design speed {f0} Hz: expected "
                         "speeds ≥ 0")
    grid = np.unique(np.r_[np.linspace(f.min(), f.max(), TRACK_POINTS), f0])
    if grid.size < 2:
        return ()
    lpv = lpv_plant(cfg, grid, reference_speed_hz=f0, states=states)

    def modes(fk):
        # the mechanical states come first and the actuator's after, in series upstream:
        # the mechanical block's eigenvalues are the rotor's
        return np.linalg.eigvals(lpv.A_at(_TWO_PI * fk)[:states, :states])

    lam0 = modes(f0)
    flexible = np.argsort(np.abs(lam0))[RIGID_STATES:]
    lam0 = lam0[flexible][_light(lam0[flexible], light_damping)]
    lam0 = lam0[np.argsort(lam0.imag)]
    lo = hi = lam0.imag.copy()
    k0 = int(np.searchsorted(grid, f0))
    for path in (grid[k0::-1], grid[k0:]):
        cur = lam0
        for fk in path[1:]:
            lam = modes(fk)
            lam = lam[lam.imag > 0]
            rows, cols = linear_sum_assignment(np.abs(cur[:, None] - lam[None, :]))
            nxt = cur.copy()
            nxt[rows] = lam[cols]
            cur = nxt
            lo, hi = np.minimum(lo, cur.imag), np.maximum(hi, cur.imag)
    out = [ModeBand(float(w / _TWO_PI), float(a / _TWO_PI), float(b / _TWO_PI))
           for w, a, b in zip(lam0.imag, lo, hi) if b - a > 1e-6 * w]
    return tuple(out)


def bands_near(bands, f_hz: float) -> list[ModeBand]:
    """The bands a mode lost at ``f_hz`` calls for: those whose sweep starts below
    ``f_hz`` widened by :data:`BAND_MATCH` — the lost mode's own (the controller moves a
    closed-loop mode a little off its open-loop frequency) and every sweeping mode below
    it, which the controller has to phase-stabilise as well and which, left frozen, would
    be the next one lost.

    Parameters
    ----------
    bands : iterable of ModeBand
        The design model's bands (:func:`mode_bands`).
    f_hz : float
        Damped frequency of the lost closed-loop mode (Hz).

    Returns
    -------
    list of ModeBand
        In the order of ``bands``.
    """
    return [b for b in bands if b.lo_hz / BAND_MATCH <= f_hz]


#: Components of a mode's output shape (or, for a mode the outputs do not see, of its
#: eigenvector) within this relative distance of the largest magnitude tie
#: (:func:`_fixed_phase`): the two transverse directions of a circular whirl are equal in
#: magnitude up to rounding.
PHASE_TIE_RTOL = 1e-6

#: A mode whose output shape ``C v`` is below this share of ``‖C‖·max|v|`` is one the
#: outputs do not see; its phase is fixed on its state coordinates instead.
UNSEEN_RTOL = 1e-9


def _fixed_phase(V, C):
    """The eigenvectors ``V`` (columns) of a plant with output matrix ``C``, each turned by
    a phase so that its output shape ``C v`` has its first component within
    :data:`PHASE_TIE_RTOL` of its largest magnitude real and positive.

    A complex eigenvector is unique only up to such a phase, and the rank-one channel of
    :func:`with_modal_frequencies` (the mode's real and imaginary parts) turns with it.
    LAPACK makes the largest state component real: on a rotor whose two transverse axes
    are alike, a circular whirl has two largest components equal but for rounding, and
    which one LAPACK takes follows the machine's BLAS kernels. A rule on the state
    components still follows them, since the design model's state coordinates do: its
    modal reduction is built from the full model's eigenvectors, whose phases turn each
    mode's pair of real coordinates. Under Haswell and SkylakeX kernels three of the
    overhung compressor example's four bands had other channels, so its μ designs under
    the two began from different uncertainty sets and ended at μ 1.018 and 0.826. The
    output shape does not depend on the state coordinates (``C T⁻¹ · T v``); the outputs
    (sensors) come in the rig's channel order, which breaks a circular whirl's tie
    (benchmarks/README.md, "A circular whirl's uncertain frequency" and "The design model's
    coordinates").
    """
    def first_largest(Y):
        mag = np.abs(Y)
        first = np.argmax(mag >= (1.0 - PHASE_TIE_RTOL) * mag.max(axis=0), axis=0)
        return Y[first, np.arange(Y.shape[1])]

    C = np.asarray(C)
    shown = first_largest(C @ V)
    scale = UNSEEN_RTOL * np.linalg.norm(C, 2)
    # a mode the outputs do not see: its largest state component, as LAPACK's rule
    pivot = np.where(np.abs(shown) > scale * np.abs(V).max(axis=0), shown, first_largest(V))
    return V * (np.abs(pivot) / pivot)


def with_modal_frequencies(plant: Plant, bands) -> tuple[Plant, dict]:
    """The plant with each band's mode frequency as an LFT parameter (module docstring).

    Parameters
    ----------
    plant : ambseal.model.lft.Plant
        Design model (small: a dense eigendecomposition), at the design speed.
    bands : iterable of ModeBand
        The modes (matched to the plant's by the nearest damped frequency, so the
        band's shifts apply to the plant's own frequency at its pressure) and their bands.

    Returns
    -------
    plant : Plant
        The same A, B, C, D; a parameter ``band.name`` (rad²/s², nominal ω_d²) per band
        (``mode_<f>Hz_2.omega_sq`` and on for a second band of the same rounded frequency).
    ranges : dict
        ``{name: (low, high)}``: (ω_d + 2π(lo − f))², (ω_d + 2π(hi − f))² — the band's
        shifts applied to the plant's mode — for :func:`generalized_plant`'s uncertainty.

    Raises
    ------
    ModelError
        A band whose mode the plant does not have (no lightly damped mode within
        :data:`BAND_MATCH` of its frequency).
    """

    A = np.asarray(plant.A, float)
    lam, V = np.linalg.eig(A)
    V = _fixed_phase(V, plant.C)
    W = np.linalg.inv(V)
    # a mode a damping margin (ambseal.design.plant.less_damped) took below zero damping is
    # still the band's mode: with it left out, a design given both remedies for one mode
    # found no mode to make uncertain (and which remedies it gets varies with rounding)
    light = np.flatnonzero(_light(lam, LIGHT_DAMPING, growing=True))
    params, ranges, used = dict(plant.parameters), {}, set()
    for band in bands:
        wb = _TWO_PI * band.f_hz
        # the nearest mode no other band took: a pair that coincides at the design speed
        # (the two whirls of an isotropic rotor at standstill) is two modes, two channels
        free = [k for k in light if k not in used]
        k = free[int(np.argmin(np.abs(lam[free].imag - wb)))] if free else -1
        if k < 0 or not (wb / BAND_MATCH <= lam[k].imag <= wb * BAND_MATCH):
            raise ModelError(f"with_modal_frequencies: the design model has no lightly damped "
                             f"mode near {band.f_hz:.4g} Hz")
        used.add(k)
        name = band.name
        for j in range(2, len(used) + 2):
            if name not in params:
                break
            name = band.name.replace("Hz.", f"Hz_{j}.")
        wd = float(lam[k].imag)
        vi, wr = V[:, k].imag, W[k, :].real
        # ΔA = (θ − ω_d²) · (−v_i/ω_d)(2 w_r), the two factors balanced in norm
        b, c = -vi / wd, 2.0 * wr
        s = np.sqrt(np.linalg.norm(c) / max(np.linalg.norm(b), 1e-300))
        params[name] = Parameter(
            name=name, nominal=wd ** 2, unit="rad²/s²", B=(b * s)[:, None],
            C=(c / s)[None, :], D=np.zeros((1, plant.B.shape[1])))
        ranges[name] = tuple(sorted(((wd + _TWO_PI * (band.lo_hz - band.f_hz)) ** 2,
                                          (wd + _TWO_PI * (band.hi_hz - band.f_hz)) ** 2)))
    return replace(plant, parameters=params), ranges

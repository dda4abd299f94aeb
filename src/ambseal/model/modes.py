"""Modal analysis of the rig model: damped natural frequencies, damping, unstable poles."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .rig import SecondOrderSystem

__all__ = ["Modes", "modes"]


@dataclass(frozen=True)
class Modes:
    """Eigenvalues of a second-order system in the terms a rotordynamicist reads.

    Attributes
    ----------
    natural_frequencies_hz : tuple of float
        Damped natural frequencies Im(λ)/2π (Hz) of the oscillating modes (Im λ > 0),
        ascending; rigid-body (λ ≈ 0) and non-oscillating modes are left out.
    damping_ratios : tuple of float
        −Re(λ)/|λ| of the same modes.
    unstable_poles : tuple of (float, float)
        [Re λ, Im λ] (rad/s) of every eigenvalue with Re λ > 0 (beyond rounding).
    poles : ndarray
        All eigenvalues (rad/s), sorted by |λ|.
    """

    natural_frequencies_hz: tuple[float, ...]
    damping_ratios: tuple[float, ...]
    unstable_poles: tuple[tuple[float, float], ...]
    poles: np.ndarray

    def to_dict(self) -> dict:
        return {
            "natural_frequencies_hz": list(self.natural_frequencies_hz),
            "damping_ratios": list(self.damping_ratios),
            "unstable_poles": [list(p) for p in self.unstable_poles],
        }


def modes(sys: SecondOrderSystem) -> Modes:
    """Damped natural frequencies, damping ratios and unstable poles of ``sys``.

    The eigenvalues λ of the first-order form x = [q; q̇] (Friswell et al. 2010, §3.6):
    a mode oscillates at Im λ/2π Hz with damping ratio −Re λ/|λ|. Eigenvalues with
    |λ| below 1e-6 of the largest (free–free rigid-body modes) count as zero.
    """
    lam = sys.poles()
    scale = max(float(np.abs(lam).max()), 1.0)
    tol = 1e-6 * scale
    rigid = np.abs(lam) < max(tol, 1e-3)
    osc = lam[(lam.imag > tol) & ~rigid]
    osc = osc[np.argsort(osc.imag)]
    unstable = lam[(lam.real > 1e-9 * scale) & ~rigid]
    unstable = unstable[np.argsort(-unstable.real)]
    return Modes(
        natural_frequencies_hz=tuple(float(x) for x in osc.imag / (2 * np.pi)),
        damping_ratios=tuple(float(x) for x in -osc.real / np.abs(osc)),
        unstable_poles=tuple((float(p.real), float(p.imag)) for p in unstable),
        poles=lam,
    )

"""The w-plane: a sampled, delayed generalised plant as a continuous one, for synthesis.

A controller that runs at the sample time T with ``n_d`` samples of computation delay acts
on the plant through a zero-order hold (the DAC). The plant it sees is then exactly
discrete: the ZOH equivalent ``(A_d, B_d, C, D)`` of the continuous plant (:func:`ambseal.
lti.discrete.zoh`) with ``n_d·n_u`` more states holding the delayed commands. The bilinear
(Tustin) map z = (1 + wT/2)/(1 − wT/2) takes that discrete system to a continuous-time one
in w,

    A_w = (2/T)(A_d − I)(A_d + I)⁻¹,   B_w = (2/T)(A_d + I)⁻¹B_d,
    C_w = 2C(A_d + I)⁻¹,               D_w = D − ½C_wB_d,

the inverse of the Tustin transform without prewarp (``scipy.signal.cont2discrete``'s
``"bilinear"``; the w transformation of Ogata, *Discrete-Time Control Systems*, 2nd ed.,
1995, ch. 4). The map takes the unit circle onto the imaginary axis and the unit disc
onto the left half-plane, so a system's H∞ norm and its stability are the same in z and
in w: an H∞ or μ controller designed on the w-plane plant, transformed by Tustin without
prewarp, is a discrete controller whose sampled, delayed loop has the same closed-loop
norm and is stable where the w-plane loop is — no Padé lag of the delay, and no gap
between the loop designed and the loop that runs.

Nothing here knows the machine: :func:`w_plane_plant` takes any generalised plant whose
last ``ncon`` inputs are the commands.
"""

from __future__ import annotations

import control
import numpy as np

from ambseal.errors import ConfigError, SynthesisError
from ambseal.lti import zoh
from ambseal.robust.digital import with_delay
from ambseal.robust.timing import check_timing

__all__ = ["w_plane_plant"]

#: The sampled plant counts as having a pole at z = −1 where the smallest singular value of
#: A_d + I is below this share of 1 + ‖A_d‖₂: the image's entries would lose the inverse
#: of it times ε of their digits (2e-6 here), its poles lie beyond 2/T over it.
SINGULAR_RTOL = 1e-10


def w_plane_plant(P, ncon: int, sample_rate_hz: float, delay_samples: int):
    """The generalised plant ``P`` sampled by zero-order hold with ``delay_samples`` of
    computation delay on its commands, mapped to the w-plane (module docstring).

    Parameters
    ----------
    P : control.StateSpace
        Continuous generalised plant, inputs ``[w, u]`` with the ``ncon`` commands ``u``
        last, outputs ``[z, y]``; its names are kept.
    ncon : int
        Number of commands, ≥ 1.
    sample_rate_hz : float
        The target's sample rate (Hz), > 0.
    delay_samples : int
        Computation delay (samples) on every command, from 0 to
        :data:`~ambseal.robust.timing.MAX_DELAY_SAMPLES`.

    Returns
    -------
    control.StateSpace
        The w-plane plant: ``n + delay_samples·ncon`` states, the inputs and outputs of
        ``P``. Its loop with a controller ``K_w`` is stable, and has the H∞ norm, that the
        sampled loop of ``P`` with the Tustin transform of ``K_w`` (no prewarp) and its
        delay has.

    Raises
    ------
    ConfigError
        A non-positive rate, a delay outside its range, or ``ncon`` not between 1 and the
        number of inputs.
    SynthesisError
        The sampled plant has a pole at z = −1 (a mode at the Nyquist frequency with no
        damping; :data:`SINGULAR_RTOL`): it has no w-plane image.
    """
    check_timing(sample_rate_hz, delay_samples)
    A, B, C, D = (np.asarray(X, float) for X in (P.A, P.B, P.C, P.D))
    m = B.shape[1]
    if not 1 <= ncon <= m:
        raise ConfigError(f"w_plane_plant: ncon={ncon!r}, expected 1 to {m} (the inputs)")
    T = 1.0 / float(sample_rate_hz)
    Ad, Bd = zoh(A, B, T, keep=False)
    # u[k] reaches the plant delay_samples later: the target's own delay block
    # (:func:`~ambseal.robust.digital.with_delay` of a unit gain) in front of the commands
    nw = m - ncon
    Al, Bl, Cl, Dl = with_delay((np.zeros((0, 0)), np.zeros((0, ncon)), np.zeros((ncon, 0)),
                                 np.eye(ncon)), int(delay_samples))
    Bw_, Bu = Bd[:, :nw], Bd[:, nw:]
    Dw_, Du = D[:, :nw], D[:, nw:]
    k = Al.shape[0]
    Ad = np.block([[Ad, Bu @ Cl], [np.zeros((k, Ad.shape[0])), Al]])
    Bd = np.block([[Bw_, Bu @ Dl], [np.zeros((k, nw)), Bl]])
    C, D = np.hstack([C, Du @ Cl]), np.hstack([Dw_, Du @ Dl])
    I = np.eye(Ad.shape[0])
    lu = Ad + I
    sv = np.linalg.svd(lu, compute_uv=False)
    if not sv[-1] > SINGULAR_RTOL * (1.0 + np.linalg.norm(Ad, 2)):
        raise SynthesisError(f"w_plane_plant: the plant sampled at {sample_rate_hz:g} Hz has a "
                             "pole at z = -1 (an undamped mode at the Nyquist frequency): no "
                             "w-plane image")
    Mi = np.linalg.solve(lu.T, I).T  # (A_d + I)⁻¹ from the right
    Aw = (2.0 / T) * (Ad - I) @ Mi
    Bw = (2.0 / T) * np.linalg.solve(lu, Bd)
    Cw = 2.0 * C @ Mi
    Dw = D - 0.5 * Cw @ Bd
    return control.ss(Aw, Bw, Cw, Dw, inputs=list(P.input_labels),
                      outputs=list(P.output_labels), name=P.name)

"""ambseal.lti: state-space numerics every layer shares, and nothing physical.

The lowest numerical layer (it imports only :mod:`ambseal.errors`); each idea once, on
``control.StateSpace`` or plain ``(A, B, C, D)`` matrices:

* :func:`freqresp_at` — ``C (sI − A)⁻¹ B + D`` at any complex points (the unit circle of a
  discrete system, say); :func:`ambseal.lti.freqresp.freqresp` on ``s = jω`` for large
  continuous models, modal or Hessenberg (Laub, IEEE TAC 26(2), 1981);
* :func:`lft_lower`, :func:`lft_lower_matrices` — ``F_l(P, K)`` (Skogestad &
  Postlethwaite, *Multivariable Feedback Control*, 2nd ed., Eq. 3.111);
  :func:`feedback_matrices`, :func:`feedback_poles` — the negative-feedback loop ``u = −K y + d``;
  :func:`wired` — a controller matched to its plant by signal names;
* :func:`zoh`, :func:`discretize`, :func:`simulate_lti` — exact zero-order hold (Franklin,
  Powell & Workman, *Digital Control of Dynamic Systems*, 3rd ed., §6.3), Tustin, and the
  discrete recursion every time response runs through;
* :func:`interp_table` — the one rule for tables against a parameter;
* :func:`lowest_eigenpairs` — the eigenvalues of smallest |λ| of a large state matrix with
  right and left eigenvectors (shift-invert Arnoldi; a modal reduction's input);
* :func:`picklable` — ``control.StateSpace`` through :mod:`pickle` (Dask workers).

``freqresp`` is not re-exported here: it shares its module's name, and re-exporting it
would hide :mod:`ambseal.lti.freqresp` (``import ambseal.lti.freqresp as fr`` would then
give the function).
"""

from ambseal.lti.discrete import discretize, simulate_lti, zoh
from ambseal.lti.freqresp import freqresp_at
from ambseal.lti.interconnect import (
    feedback_matrices,
    feedback_poles,
    lft_lower,
    lft_lower_matrices,
    wired,
)
from ambseal.lti.lowest import lowest_eigenpairs
from ambseal.lti.pickling import picklable
from ambseal.lti.tables import interp_table

__all__ = ["discretize", "feedback_matrices", "feedback_poles", "freqresp_at",
           "interp_table", "lft_lower", "lft_lower_matrices", "lowest_eigenpairs", "picklable",
           "simulate_lti", "wired", "zoh"]

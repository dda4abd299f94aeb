"""ambseal.lti: state-space numerics every layer shares, and nothing physical.

The lowest numerical layer (it imports only :mod:`ambseal.errors`); each idea once, on
``control.StateSpace`` or plain ``(A, B, C, D)`` matrices:

* :func:`freqresp_at` — ``C (sI − A)⁻¹ B + D`` at any complex points (the unit circle of a
  discrete system, say); :func:`ambseal.lti.freqresp.freqresp` on ``s = jω`` for large
  continuous models, modal or Hessenberg (Laub, IEEE TAC 26(2), 1981);
* :func:`lft_lower`, :func:`lft_lower_matrices` — ``F_l(P, K)`` (Skogestad &
  Postlethwaite, *Multivariable Feedback Control*, 2nd ed., Eq. 3.111);
  :func:`feedback_matrices`, :func:`feedback_poles`, :func:`feedback_response` — the
  negative-feedback loop ``u = −K y + d``, its poles and time response (of a large plant
  from its modal form);
  :func:`wired` — a controller matched to its plant by signal names;
* :func:`zoh`, :func:`discretize`, :func:`simulate_lti` — exact zero-order hold (Franklin,
  Powell & Workman, *Digital Control of Dynamic Systems*, 3rd ed., §6.3), Tustin, and the
  discrete recursion every time response runs through; :func:`sampled_modal_form` and
  :func:`simulate_modal_loop` — a large plant sampled from its modal form (no ``expm``),
  and a discrete loop stepped on it;
* :func:`eigenvalues` — of a large system's state matrix, from the decomposition its
  responses and loops share;
* :func:`interp_table` — the one rule for tables against a parameter;
* :func:`lowest_eigenpairs` — the eigenvalues of smallest |λ| of a large state matrix with
  right and left eigenvectors (shift-invert Arnoldi; a modal reduction's input);
* :func:`picklable` — ``control.StateSpace`` through :mod:`pickle` (Dask workers);
* what every layer shares beneath them: :func:`ss_matrices`, :func:`as_omega`,
  :func:`labels`, :func:`shared_ss`, :func:`select_inputs` (checked matrices, grids, signal
  names, and systems sharing a large state matrix instead of copying it),
  :class:`ArrayMemo` (results of expensive functions of large arrays, kept by their
  digest), :func:`freeze` (an array made read-only, its digest then computed once),
  :func:`state_poles`, :func:`series_inputs`, :func:`sampled_response_at`,
  :func:`cached_njit` (numba's cached compilation), :data:`DENSE_STATES`,
  :data:`STRUCTURED_STATES`, and the JSON conventions of every result (:func:`json_float`,
  :func:`json_list`, :func:`finite_or_none`, :func:`finite_or_none_tree`).

``freqresp`` is not re-exported here: it shares its module's name, and re-exporting it
would hide :mod:`ambseal.lti.freqresp` (``import ambseal.lti.freqresp as fr`` would then
give the function).
"""

from ambseal.lti.compiled import cached_njit
from ambseal.lti.discrete import discretize, simulate_lti, simulate_modal_loop, zoh
from ambseal.lti.freqresp import (
    STRUCTURED_STATES,
    eigenvalues,
    freqresp_at,
    sampled_modal_form,
    sampled_response_at,
)
from ambseal.lti.interconnect import (
    feedback_matrices,
    feedback_poles,
    feedback_response,
    lft_lower,
    lft_lower_matrices,
    series_inputs,
    state_poles,
    wired,
)
from ambseal.lti.json_safe import finite_or_none, finite_or_none_tree, json_float, json_list
from ambseal.lti.lowest import DENSE_STATES, lowest_eigenpairs
from ambseal.lti.matrices import (
    ArrayMemo,
    as_omega,
    freeze,
    labels,
    select_inputs,
    shared_ss,
    ss_matrices,
)
from ambseal.lti.pickling import picklable
from ambseal.lti.tables import interp_table

__all__ = ["ArrayMemo", "DENSE_STATES", "STRUCTURED_STATES", "as_omega", "cached_njit",
           "discretize", "eigenvalues", "feedback_matrices", "feedback_poles",
           "feedback_response", "finite_or_none", "finite_or_none_tree", "freeze", "freqresp_at",
           "interp_table", "json_float", "json_list", "labels", "lft_lower",
           "lft_lower_matrices", "lowest_eigenpairs", "picklable", "sampled_modal_form",
           "sampled_response_at", "select_inputs", "series_inputs", "shared_ss",
           "simulate_lti", "simulate_modal_loop", "ss_matrices", "state_poles", "wired", "zoh"]

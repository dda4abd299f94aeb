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
* :func:`least_squares_converged` — SciPy's nonlinear least squares ended by its own
  tolerances or a stated stall test, never by a count of evaluations;
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

Each name loads its module on first use (PEP 562 ``__getattr__``,
:func:`ambseal.lazy.lazy_face`): the modules on ``control.StateSpace`` load python-control
(1 s of start-up), which the model's modes do not need.
"""

from ambseal.lazy import lazy_face

#: Each public name (``__all__``) and the module that defines it.
_FROM = {
    "cached_njit": "compiled", "discretize": "discrete", "simulate_lti": "discrete",
    "simulate_modal_loop": "discrete", "zoh": "discrete", "STRUCTURED_STATES": "freqresp",
    "eigenvalues": "freqresp", "freqresp_at": "freqresp", "sampled_modal_form": "freqresp",
    "sampled_response_at": "freqresp", "feedback_matrices": "interconnect",
    "feedback_poles": "interconnect", "feedback_response": "interconnect",
    "lft_lower": "interconnect", "lft_lower_matrices": "interconnect",
    "series_inputs": "interconnect", "state_poles": "interconnect", "wired": "interconnect",
    "finite_or_none": "json_safe", "finite_or_none_tree": "json_safe",
    "json_float": "json_safe", "json_list": "json_safe", "DENSE_STATES": "lowest",
    "lowest_eigenpairs": "lowest", "ArrayMemo": "memo", "as_omega": "matrices",
    "freeze": "memo", "labels": "matrices", "select_inputs": "matrices",
    "shared_ss": "matrices", "ss_matrices": "matrices", "picklable": "pickling",
    "interp_table": "tables", "least_squares_converged": "least_squares",
}

__all__ = sorted(_FROM)

__getattr__, __dir__ = lazy_face(__name__, _FROM)

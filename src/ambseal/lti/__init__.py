"""Linear time-invariant systems: the numerics every stage shares, and nothing physical.

The lowest stage of ambseal (it imports only :mod:`ambseal.errors`): each idea once.

* :mod:`~ambseal.lti.freqresp` — ``freqresp`` (continuous, jω) and ``freqresp_at`` (any
  complex points, e.g. the unit circle of a discrete system);
* :mod:`~ambseal.lti.interconnect` — ``lft_lower`` / ``lft_lower_matrices`` (F_l(P, K)) and
  ``feedback_matrices`` (the AMB loop u = −K y + d);
* :mod:`~ambseal.lti.discrete` — ``zoh``, ``discretize`` and ``simulate_lti``;
* :mod:`~ambseal.lti.matrices` — ``ss_matrices``, ``as_omega``, ``labels``.
"""

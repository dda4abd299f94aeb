"""ambseal.analysis: judge a closed loop of a plant and a controller, whatever made them.

Modules (import them directly; this package imports nothing heavy and no plotting):

* :mod:`ambseal.analysis.spinup` — spin-up of a speed-scheduled rotor, frozen-speed S_o (P3 §4);
* :mod:`ambseal.analysis.loops` — closed loop, poles, S_o, S_i, T_o, K S_o, compliance;
* :mod:`ambseal.analysis.iso` — ISO 14839-3 zones from sensitivity peaks;
* :mod:`ambseal.analysis.unbalance` — ISO 21940-11 unbalance force and response bound;
* :mod:`ambseal.analysis.response` — current-impulse time response (P5 §5.1).

Conventions: negative feedback ``u = −K y``; rad/s inside, Hz at the edges (``*_hz``);
results are frozen dataclasses with ``to_dict()`` (JSON-safe, ``inf`` → ``"inf"``,
``NaN`` → ``None``).
"""

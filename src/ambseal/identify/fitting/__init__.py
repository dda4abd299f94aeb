"""ambseal.identify.fitting: Fitting physical parameters to closed-loop records: the output-error fit and its stages, its statistics, intervals and checks, the frequency-domain and Youla (Hansen) schemes, static loading and seal tests (thesis P1, P2, P4, P5 §3).

Internal to :mod:`ambseal.identify`, whose face lists what other packages use.
"""

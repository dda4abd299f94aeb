"""ambseal.identify.facility: The virtual test facility whose truth is known, and the rig a design takes from an identification (thesis P5 §3).

Internal to :mod:`ambseal.identify`, whose face lists what other packages use.
"""

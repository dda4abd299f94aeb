"""ambseal.identify.excitation.plan: The excitation of the identification experiment: the plan derived from the rig, and the signals added to the AMB current references.

Internal to :mod:`ambseal.identify`, whose face lists what other packages use.
"""

"""ambseal.io: other tools' formats in and out — :mod:`ambseal.io.ross` (ROSS rotors in).

Import the submodules directly; this package imports nothing heavy.
"""

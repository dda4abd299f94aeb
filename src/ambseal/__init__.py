"""ambseal: rotors on active magnetic bearings pushed towards instability by annular seals.

Model (FE rotor, AMBs, seals, couplings), identify in closed loop, design controllers and
judge them against ISO 14839-3. Source: J. S. Lauridsen, PhD thesis, DTU 2017.

Importing the package is light: numerics modules are imported on use, and no plotting
library is loaded at import time.
"""

__version__ = "0.1.0"

__all__ = ["__version__"]

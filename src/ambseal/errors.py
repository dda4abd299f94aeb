"""The project's own exceptions.

Every error raised on bad input names the file, key or column and what was expected; the
CLI turns an :class:`AmbsealError` into one line on stderr and exit code 2.
"""

from __future__ import annotations


class AmbsealError(Exception):
    """Base class of every error ambseal raises on purpose."""


class ConfigError(AmbsealError, ValueError):
    """A rig file is missing a key, has a wrong type or an inconsistent value."""


class DataError(AmbsealError, ValueError):
    """A measurement file is malformed (non-uniform time, NaN, wrong channels, ...)."""


class ModelError(AmbsealError, ValueError):
    """A model cannot be built or reduced as asked."""


class IdentificationError(AmbsealError):
    """A parameter fit failed or did not converge."""


class SynthesisError(AmbsealError):
    """A controller cannot be synthesised (unstabilisable plant, rank-deficient D12, ...)."""

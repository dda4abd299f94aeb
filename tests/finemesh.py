"""The embedded test facility meshed finer: its rig file with the ``[[shaft]]`` sections'
``elements`` raised to a given number of beam elements in all (a long rotor, a mesh
convergence check)."""

import re

from ambseal.config import default_rig_path


def fine_rig_text(total: int) -> str:
    """The embedded rig file's text with ``total`` beam elements in the whole shaft: each
    section but the longest gets its share by length (rounded, at least 1), the longest the
    rest; every other line (comments included) unchanged."""
    text = default_rig_path().read_text(encoding="utf-8")
    lengths = [float(x) for x in re.findall(r"^\[\[shaft\]\]\nlength = ([0-9.eE+-]+)",
                                            text, flags=re.M)]
    share = [max(1, round(total * x / sum(lengths))) for x in lengths]
    longest = lengths.index(max(lengths))
    share[longest] = total - (sum(share) - share[longest])
    counts = iter(share)
    out, n = re.subn(r"^elements = \d+$", lambda m: f"elements = {next(counts)}", text,
                     flags=re.M)
    assert n == len(lengths) == 3, "the embedded rig's [[shaft]] sections changed"
    return out

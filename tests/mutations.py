"""Mutations of a parsed document (a rig, a sidecar, a fit) for the property tests: a key
deleted, a value replaced by an odd one, a number scaled by a wild factor, or an entry
duplicated (hypothesis strategies)."""

import copy
import math

from hypothesis import strategies as st

#: Replacement values: wrong types, non-finite and extreme numbers, empty containers.
ODD = st.sampled_from([True, False, "1.5", "", "x.y", {}, [], [1.0, "a"], math.nan, math.inf,
                       -math.inf, 1e308, -1e308, 1e-308, 0, 0.0, -1, -1.0, 10**30, 2**63,
                       {"at_zero": math.nan}, {"zeta": 1.0}, {"frequency_hz": [1.0, 0.5],
                                                             "value": [1.0, 2.0]}])


def paths(node, prefix=()):
    """Every path (tuple of keys/indices) to a value inside ``node``."""
    out = []
    items = node.items() if isinstance(node, dict) else (
        enumerate(node) if isinstance(node, list) else ())
    for k, v in items:
        out.append(prefix + (k,))
        out += paths(v, prefix + (k,))
    return out


@st.composite
def mutated(draw, doc: dict, under: tuple = ()):
    """``doc`` with 1–3 mutations: a key deleted, a value replaced by an odd one, a number
    scaled by a wild factor, or a table duplicated; only inside the tables ``under``
    names, where it names any."""
    doc = copy.deepcopy(doc)
    for _ in range(draw(st.integers(1, 3))):
        where = [p for p in paths(doc) if not under or (p[0] in under and len(p) > 1)]
        if not where:
            break
        path = draw(st.sampled_from(where))
        parent = doc
        for k in path[:-1]:
            parent = parent[k]
        key, value = path[-1], parent[path[-1]]
        op = draw(st.sampled_from(["delete", "replace", "scale", "duplicate"]))
        if op == "delete":
            del parent[key]
        elif op == "scale" and isinstance(value, (int, float)) and not isinstance(value, bool):
            factor = draw(st.sampled_from([-1.0, 0.0, 1e-12, 1e-3, 1.000001, 1e3, 1e12]))
            parent[key] = type(value)(value * factor) if isinstance(value, float) else (
                int(value * factor))
        elif op == "duplicate" and isinstance(parent, list):
            parent.append(copy.deepcopy(value))
        else:
            parent[key] = copy.deepcopy(draw(ODD))
    return doc

"""The turboexpander example (P1/P3): its published numbers and the seal table's shape."""

from pathlib import Path

import numpy as np
import pytest

from ambseal.config import load_rig
from ambseal.model.modes import modes
from ambseal.model.rig import build_system

RIG = Path(__file__).resolve().parents[2] / "examples" / "turboexpander.toml"


@pytest.fixture(scope="module")
def rig():
    return load_rig(RIG)


def test_mesh_bending_mode_and_open_loop(rig):
    """40 nodes and a first free–free bending mode near 1 kHz (P1 §III, P3 §2); the AMB
    rotor is open-loop unstable at every speed of the 20–300 Hz range."""
    free = build_system(rig, speed_rpm=0.0, include_amb=False, include_seals=False,
                        include_springs=False)
    assert free.mesh.n_nodes == 40
    assert modes(free).natural_frequencies_hz[0] == pytest.approx(1000.0, rel=0.1)
    for f in (20.0, 140.0, 300.0):
        assert modes(build_system(rig, speed_rpm=60 * f)).unstable_poles


def test_hole_pattern_seal_table_shape(rig):
    """Published hole-pattern behaviour (Childs & Wade 2004; P3 Figs. 3–4): direct
    stiffness rising with frequency, cross-coupled stiffness falling, effective damping
    C − k/ω negative at low frequency and positive above a crossover."""
    seal = rig.seal[0]
    f = np.array(seal.K.frequency_hz)
    K, k, C = (np.array(getattr(seal, n).value) for n in ("K", "k", "C"))
    assert np.all(np.diff(K) > 0) and np.all(np.diff(k) < 0)
    c_eff = C - k / (2 * np.pi * f)
    assert c_eff[0] < 0 < c_eff[-1]
    assert rig.operating.speed_range_hz == (20.0, 300.0)

"""Tests of ambseal.analysis.unbalance: ISO 21940-11 force and the σ̄·F response bound."""

from __future__ import annotations

import json

import numpy as np
import pytest

from ambseal.analysis import loops, unbalance
from ambseal.errors import ModelError

from .amb_test_plants import mass_1dof, rigid_rotor


def test_thesis_force_g25_69kg_500hz():
    """Reference: P5 §4.4.1 — G2.5 on the 69 kg rotor (Table 1) at 500 Hz gives 541 N;
    exact value 69 · 2.5e-3 · 2π·500 = 541.92 N."""
    F = unbalance.unbalance_force(69.0, 2.5, 2 * np.pi * 500.0)
    assert float(F) == pytest.approx(541.9, abs=0.05)
    assert float(F) == pytest.approx(69 * 2.5e-3 * 2 * np.pi * 500, rel=1e-12)


def test_force_balanced_for_max_speed():
    """Reference: ISO 21940-11, e = G/Ω_max fixed, F = m e Ω²: equals m G Ω at Ω_max and
    scales with Ω² below."""
    wmax = 2 * np.pi * 500
    w = np.array([0.0, wmax / 2, wmax])
    F = unbalance.unbalance_force(69.0, 2.5, w, max_speed_rad_s=wmax)
    np.testing.assert_allclose(F, [0.0, 541.92 / 4, 541.92], rtol=1e-4)


@pytest.mark.parametrize("args", [(0.0, 2.5, 1.0), (69.0, -1.0, 1.0), (69.0, 2.5, -1.0)])
def test_force_rejects_bad_input(args):
    """Reference: ISO 21940-11 quantities are positive; bad values raise ModelError."""
    with pytest.raises(ModelError):
        unbalance.unbalance_force(*args)


def test_response_siso_closed_form():
    """Reference: closed form for a SISO loop with the force at the actuator (Gf = G/ki):
    response = |S(jΩ) G(jΩ)|/ki · m G Ω with S = 1/(1+GK) (P5 §4.4.1, Fig. 12)."""
    G, K, (nG, dG), (nK, dK) = mass_1dof()
    ki = 100.0
    Gf = G * (1.0 / ki)
    w = 2 * np.pi * np.linspace(1.0, 200.0, 300)
    r = unbalance.unbalance_response(G, K, Gf, w, mass_kg=10.0, grade_mm_s=6.3)
    s = 1j * w
    Gs = np.polyval(nG, s) / np.polyval(dG, s)
    Ks = np.polyval(nK, s) / np.polyval(dK, s)
    ref = np.abs(Gs / ki / (1 + Gs * Ks)) * 10.0 * 6.3e-3 * w
    np.testing.assert_allclose(r.response_m, ref, rtol=1e-8)
    assert r.peak_um == pytest.approx(ref.max() * 1e6, rel=1e-8)
    assert r.peak_speed_hz == pytest.approx(w[np.argmax(ref)] / (2 * np.pi))


def test_response_from_compliance_is_sigma_times_force():
    """Reference: definition σ̄(S_o G_f)·F_u on the rigid rotor (P5 Fig. 12); JSON-safe dict."""
    G, Gf, K = rigid_rotor()
    w = 2 * np.pi * np.linspace(1.0, 200.0, 200)
    comp = loops.compliance(G, K, Gf, w)
    r = unbalance.unbalance_from_compliance(comp, mass_kg=69.0, grade_mm_s=2.5)
    np.testing.assert_allclose(r.response_m, comp.sigma_max_m_per_n * 69.0 * 2.5e-3 * w, rtol=1e-12)
    d = json.loads(json.dumps(r.to_dict()))
    assert d["peak_um"] == pytest.approx(r.response_um.max())

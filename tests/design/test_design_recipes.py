"""Acceptance of the PID / H∞ / μ designs on the FULL-order test-facility plant.

References: thesis P5 §4.1 (objectives), §4.4 and Figs. 11–13 (σ̄(S_o) of PID/H∞/μ over
0 … 4.08 bar; the PID loses stability at high pressure), §4.4.1 and Fig. 12 (worst-case
unbalance orbit, G2.5 at 500 Hz on the 69 kg rotor, ISO 21940-11: F_u = m·G·Ω²/Ω_max), ISO
14839-3 (σ̄(S_o) < 3, zone A).
Designs are made on the reduced model; every check uses ``build_plant(cfg, pressure_bar=p)``.

σ̄(S_o) peaks are taken on the log grid PLUS a fine grid around every lightly damped
closed-loop pole: the first bending mode (≈ 557 Hz) has closed-loop damping ratios down to
≈ 0.002, a resonance the 800-point log grid steps over (the previous μ design read 2.8 on
the log grid but 5.8 at 556.8 Hz, 4.08 bar).
"""

from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

from ambseal.analysis.loops import compliance, loop_responses
from ambseal.machine.loop import closed_loop
from ambseal.analysis.unbalance import unbalance_from_compliance
from ambseal.design.plant import UncertainParameter
from ambseal.design import recipes
from ambseal.design.recipes import (
    MU_BOUNDARY_RTOL,
    ORDER_RISE,
    _outside,
    _unstable_message,
    design,
)
from ambseal.design.weights import Weights
from ambseal.config import load_rig

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"

OMEGA = 2 * np.pi * np.logspace(-1, np.log10(3000.0), 800)
#: ISO 14839-3:2006 zone A/B boundary of the sensitivity peak (3, i.e. 9.5 dB; P5 §4.1).
ISO_ZONE_A_LIMIT = 3.0
#: Thesis demand on the worst-case G2.5 unbalance orbit up to 200 Hz (P5 §4.4.1): 8 µm.
ORBIT_DEMAND_UM = 8.0


@pytest.fixture(scope="module")
def cfg(testrig_cfg):
    return testrig_cfg


@pytest.fixture(scope="module")
def plants(testrig_plants, cfg):
    """0 … 4.08 bar in 9 steps (P5 Fig. 13), full order (tests/conftest.py), with the
    digital controller's hold + computation delay (1.5 samples at 10 kHz, Padé) in front
    of the currents: the loop the H∞/μ designs are made for and every loop is judged on
    (ambseal.robust.delay)."""
    from ambseal.machine.loop import delayed_plant
    from ambseal.robust.delay import loop_delay

    assert sorted(testrig_plants)[0] == 0.0 and sorted(testrig_plants)[-1] == 4.08
    L = loop_delay(cfg.controller.sample_rate_hz, cfg.controller.delay_samples).system
    return {p: (delayed_plant(G, list(range(G.ninputs)), L), Gf)
            for p, (G, Gf) in testrig_plants.items()}


@pytest.fixture(scope="module")
def designs(testrig_designs):
    return testrig_designs


def _so_peak(G, K):
    """Peak σ̄(S_o) with every lightly damped closed-loop resonance resolved (module doc)."""
    p = closed_loop(G, K).poles
    p = p[(p.imag > 0) & (p.imag < OMEGA[-1]) & (np.abs(p.real) < 0.1 * np.abs(p))]
    w = np.sort(np.concatenate([OMEGA] + [q.imag + abs(q.real) * np.linspace(-4, 4, 81)
                                         for q in p]))
    return loop_responses(G, K, w[w > 0]).peaks("So").sigma_max.value


def test_pid_is_p5_eq6_on_every_axis(cfg, designs):
    """Reference: P5 Eq. 6 closed form, K(jω) = Kp (1 + 1/(Ti jω) + Td jω/(ε Td jω + 1)) with
    the rig's [controller.pid] values, the same on the 4 axes and nothing across axes; from
    displacement (m) to current (A), named per axis."""
    K = designs["pid"].K
    pid = cfg.controller.pid
    for f in (0.5, 10.0, 100.0, 1000.0):
        s = 2j * np.pi * f
        want = pid.kp * (1 + 1 / (pid.ti * s) + pid.td * s / (pid.eps * pid.td * s + 1))
        np.testing.assert_allclose(np.asarray(K(s)), want * np.eye(4), rtol=1e-10,
                                   atol=1e-12 * abs(want))
    assert K.input_labels == ["y_A_zeta", "y_A_eta", "y_B_zeta", "y_B_eta"]
    assert K.output_labels == ["i_A_zeta", "i_A_eta", "i_B_zeta", "i_B_eta"]


def test_hinf_gamma_is_the_verified_closed_loop_norm(designs):
    """Reference: python-control side by side — γ of the H∞ design equals
    control.norm(P.lft(K_P), 'inf') (slycot AB13DD) of the nominal generalised plant closed
    by the synthesis-form controller K_P = −(D_e/D_u) K (DESIGN.md scaling), and that loop is
    stable (its poles by python-control)."""
    r = designs["hinf"]
    gp = r.plant
    g = -gp.d_e / gp.d_u
    import control as ct

    K_P = ct.ss(r.K.A, r.K.B, g * np.asarray(r.K.C), g * np.asarray(r.K.D))
    cl = gp.P_nominal.lft(K_P, gp.nmeas, gp.ncon)
    assert cl.poles().real.max() < 0
    assert r.gamma == pytest.approx(ct.norm(cl, "inf"), rel=1e-5)
    assert r.K.ninputs == r.K.noutputs == 4 and r.order == r.K.nstates


def test_mu_reduction_reduces_within_the_order_band(designs):
    """The test rig's μ controller is reduced (46 states at full order when this was
    written) and its peak μ stays within ``ORDER_RISE`` of the full-order one: the
    automatic order stopped inside its band, not at the full order."""
    mu = designs["mu"]
    red = mu.reduction
    assert red is not None and red["order"] < red["order_full"] == mu.order_full
    assert mu.order == mu.K.nstates == red["order"]
    assert red["mu"] <= (1 + ORDER_RISE) * red["mu_full"]


def _order_choice(monkeypatch, mu_full: float, rises: dict, asked: dict | None = None
                  ) -> float:
    """μ delivered by :func:`_reduce_best` from a 70-state D–G–K controller of peak μ
    ``mu_full``, whose balanced truncation to order n raises μ by ``rises[n]``: the
    reductions scripted, the rule the design's. Where the scan asks whether an order's μ
    is above a level and it is, the answer is a lower bound 0.1 % below the peak, as
    :func:`~ambseal.robust.mu.lower_on_grid` gives one; each level asked is recorded in
    ``asked`` (order → level or None)."""
    from ambseal.robust.order import ReductionResult

    def reduce(P, K, order, nmeas, ncon, *, blocks=None, omega=None, full=None,
               mu_above=None):
        mu = full[1] * (1 + rises[order])
        low = 0.999 * mu
        if asked is not None:
            asked[order] = mu_above
        lower = mu_above is not None and low > mu_above
        return ReductionResult(K=order, order_full=70, order=order, gamma_full=1.0,
                               gamma=1.0, mu_full=full[1], mu=low if lower else mu,
                               mu_is_lower=lower)

    monkeypatch.setattr(recipes, "reduce_controller", reduce)
    cand = {"step": "D-G-K", "K": SimpleNamespace(nstates=70), "mu": mu_full, "gamma": 1.0}
    _, red, _, mu = recipes._reduce_best(None, [cand], 48, True,
                                         SimpleNamespace(nmeas=4, ncon=4), [(1, 1)], None)
    assert red["order"] < 70
    return mu


def test_the_order_scan_asks_each_order_below_the_full_one_only_whether_it_is_above_its_band(
        monkeypatch):
    """An order the scan steps past matters only as "above the band": each truncation below
    the full order is asked whether its μ exceeds (1 + ``ORDER_RISE``)·μ of the full-order
    controller, which a certified lower bound can answer without the upper bound. An
    order whose lower bound sits above the band is stepped past, and the order delivered,
    and its μ, are the peak's — the same as a scan that computed every upper bound."""
    asked: dict = {}
    rises = {48: 0.25, 52: 0.089, 56: 0.017, 60: 0.008, 64: 0.004}
    mu = _order_choice(monkeypatch, 0.7530, rises, asked)
    assert asked == {n: pytest.approx((1 + ORDER_RISE) * 0.7530, rel=1e-15)
                     for n in (48, 52, 56, 60)}
    assert mu == pytest.approx(0.7530 * (1 + rises[60]), rel=1e-15)


def test_orders_on_either_side_of_the_bands_edge_deliver_mu_within_its_tolerance(
        monkeypatch):
    """The overhung compressor's μ design on two revisions whose arithmetic differed only
    in rounding (benchmarks/README.md, "μ's Newton steps"): full-order μ 0.7598 against
    0.7530 (0.9 %), and the truncation to 52 states raising it by 8.9 % on one side and by
    just over 10 % on the other, where 56 states cost 1.7 % and 1.5 %. With the band at
    10 % the delivered μ were 0.827 and 0.766, 7.4 % apart; a band of half μ's stated
    tolerance (``MU_BOUNDARY_RTOL``) keeps the two within that tolerance."""
    one = _order_choice(monkeypatch, 0.7598, {48: 0.25, 52: 0.089, 56: 0.017, 60: 0.008,
                                              64: 0.004})
    other = _order_choice(monkeypatch, 0.7530, {48: 0.24, 52: 0.101, 56: 0.015, 60: 0.006,
                                                64: 0.002})
    assert abs(one / other - 1) <= MU_BOUNDARY_RTOL, (one, other)
    assert ORDER_RISE <= MU_BOUNDARY_RTOL / 2


def test_mu_delivers_the_candidate_with_lower_mu_after_reduction(designs):
    """Reference: the definition of the delivered controller: after the order
    reduction the μ design keeps, of D–G–K's controller and complex D–K's, the one whose
    reduced loop has the lower peak μ, and reports both. There are two candidates exactly
    when a D–G–K step beat complex D–K at full order (``musyn_dgk``'s ``alternatives``);
    on the test rig's rig-file design today D–G–K is skipped (the uncertainty does not set
    D–K's μ peak), so only that equivalence and the reported μ are checked here."""
    mu = designs["mu"]
    red = mu.reduction
    cands = red.get("candidates", [])
    dgk_won = min(mu.history, key=lambda h: h["mu"]).get("step") == "D-G-K"
    assert bool(cands) == dgk_won
    if cands:
        assert {c["step"] for c in cands} == {"D-K", "D-G-K"}
        low = min(cands, key=lambda c: c["mu"])
        assert red["kept"] == low["step"] and red["mu"] == low["mu"]
        assert all(c["mu_full"] > 0 and c["order"] <= c["order_full"] for c in cands)
    assert mu.mu == red["mu"]


def test_hinf_beats_pid_at_nominal_pressure(designs, plants):
    """P5 §4.4, Fig. 13: H∞ at its design point has a lower σ̄(S_o) peak than the PID."""
    G, _ = plants[2.04]
    for m in ("pid", "hinf"):
        assert closed_loop(G, designs[m].K).stable
    assert _so_peak(G, designs["hinf"].K) < _so_peak(G, designs["pid"].K)


def test_pid_unstable_at_high_pressure(designs, plants):
    """P5 Fig. 13: the decentralised PID stabilises the rig at 0 and at the nominal 2.04 bar
    but not at 4.08 bar (2× nominal)."""
    assert closed_loop(plants[0.0][0], designs["pid"].K).stable
    assert closed_loop(plants[2.04][0], designs["pid"].K).stable
    assert not closed_loop(plants[4.08][0], designs["pid"].K).stable


def test_mu_robust_stability_and_sensitivity_over_pressure(designs, plants):
    """P5 §4.1 items 2 and 4, §4.4.2: μ keeps the loop stable and σ̄(S_o) in ISO 14839-3
    zone A (< 3) for 0 … 4.08 bar (measured ≈ 2.5 when written).

    The seal's k goes from 0 to 2× its nominal value over this range (P5 §4.1 items 2–3).
    """
    K = designs["mu"].K
    for p in sorted(plants):
        G, _ = plants[p]
        assert closed_loop(G, K).stable, f"unstable at {p} bar"
        peak = _so_peak(G, K)
        assert peak < ISO_ZONE_A_LIMIT, f"σ̄(S_o) = {peak:.2f} at {p} bar, not ISO zone A"


def test_unbalance_orbit_hinf_and_mu_below_8um(designs, plants):
    """P5 §4.4.1, Fig. 12: "Both the H∞ and μ controllers ensure an orbit below 8 µm over the
    200 Hz frequency range": worst-case orbit σ̄(S_o G_f(jΩ))·F_u(Ω) for Ω ≤ 200 Hz.

    F_u = m·G·Ω²/Ω_max (ISO 21940-11; G2.5 at Ω_max = 2π·500 rad/s on the 69 kg rotor, 541.9 N
    at 500 Hz), the forces at the bearings A and B where P5 §4.4.1 takes the compliance,
    orbit at the sensors, on the full-order plant at every pressure of the grid 0 … 4.08 bar.
    The PID's orbit, where it is stable, is above 8 µm (the thesis names only H∞ and μ):
    the demand is not met by accident.
    """
    w = 2 * np.pi * np.linspace(1.0, 200.0, 400)
    worst = dict.fromkeys(("mu", "hinf", "pid"), 0.0)
    for p in sorted(plants):  # plant outermost: its decompositions are shared by the three
        G, Gf = plants[p]
        for m in worst:
            K = designs[m].K
            if not closed_loop(G, K).stable:
                continue
            c = compliance(G, K, Gf, w)
            worst[m] = max(worst[m], unbalance_from_compliance(
                c, mass_kg=69.0, grade_mm_s=2.5, max_speed_rad_s=2 * np.pi * 500.0).peak_um)

    assert worst["mu"] < ORBIT_DEMAND_UM
    assert worst["hinf"] < ORBIT_DEMAND_UM
    assert worst["pid"] > ORBIT_DEMAND_UM


@pytest.mark.parametrize("law", ["iso21940", "constant_velocity"])
def test_mu_force_weight_reads_as_orbit_bound(law):
    """W_p·W_f/D_e = |F_u(jΩ)|·|B_4|/orbit (closed form): the force channel bounds the orbit;
    F_u = m·G·Ω²/Ω_max (ISO 21940-11) or m·G·Ω, hand formulas."""
    wmax = 2 * np.pi * 500.0
    wts = Weights(M=3.0, omega_b=30.0, orbit_um=6.0, wf_rolloff_hz=260.0,
                  unbalance_mass_kg=69.0, d_e=20e-6, unbalance_law=law, max_speed_rad_s=wmax)
    Wp, Wf = wts.Wp(), wts.Wf()  # D_e = wts.d_e = 20 µm
    for hz in (10.0, 100.0, 200.0, 557.0):
        s = 2j * np.pi * hz
        b4 = 1 / np.sqrt(1 + (hz / 260.0) ** 8)  # |Butterworth, 4th order|
        force = 69.0 * 2.5e-3 * abs(s) * (abs(s) / wmax if law == "iso21940" else 1.0)
        want = force * b4 / 6e-6
        assert abs(complex(Wp(s)) * complex(Wf(s))) / 20e-6 == pytest.approx(want, rel=1e-6)
    assert Weights().Wf() is None
    with pytest.raises(ValueError, match="orbit_um"):
        Weights(orbit_um=-1.0).Wf()
    with pytest.raises(ValueError, match="max_speed_rad_s"):
        Weights(orbit_um=6.0, wf_rolloff_hz=260.0, unbalance_mass_kg=69.0).Wf()


def test_mu_robust_performance_and_moderate_gains(designs, cfg):
    """P5 §4.1 objective 1 and Fig. 10, Ch. 7 item 2: the μ controller "guarantees robust
    performance (μ ≤ 1) and simultaneously keeps the controller gains moderate": every
    direct gain |K_ii| within a factor 2 of the reference PID's (P5 Eq. 6, closed form) from
    1 to 200 Hz, and no gain |K_ij| above 3× the PID's peak Kp (1 + 1/ε) below Nyquist;
    order 28: the thesis's μ controller order 24 (P5 §4.4) plus one state per current for
    the digital controller's delay in the design model (first-order Padé,
    ambseal.robust.delay)."""
    from ambseal.lti.freqresp import freqresp

    mu = designs["mu"]
    assert mu.mu <= 1.0
    pid = cfg.controller.pid
    f = np.logspace(0, np.log10(0.5 * cfg.controller.sample_rate_hz), 400)
    s = 2j * np.pi * f
    k_pid = np.abs(pid.kp * (1 + 1 / (pid.ti * s) + pid.td * s / (pid.eps * pid.td * s + 1)))
    H = np.abs(freqresp(mu.K, 2 * np.pi * f))
    low = f <= 200.0
    for i in range(4):
        ratio = H[low, i, i] / k_pid[low]
        assert 0.5 <= ratio.min() and ratio.max() <= 2.0, (i, ratio.min(), ratio.max())
    assert H.max() <= 3 * pid.kp * (1 + 1 / pid.eps)
    assert mu.order == 28


def test_design_is_deterministic_and_validates(cfg, designs):
    """Same input, same controller; bad method and bad weights give clear errors."""
    again = design(cfg, "hinf")
    assert np.allclose(np.asarray(again.K.D), np.asarray(designs["hinf"].K.D))
    with pytest.raises(ValueError, match="method"):
        design(cfg, "lqg")
    with pytest.raises(ValueError, match="M="):
        design(cfg, "hinf", weights=Weights(M=-1.0))
    with pytest.raises(ValueError, match="zero or negative width"):
        design(cfg, "mu", uncertainty={"seal.k": (2e6, 2e6)})


def test_a_mode_lost_at_another_speed_is_blamed_on_the_speed_not_the_seal():
    """The back-to-back compressor's H∞, designed at 183.3 Hz without a damping margin,
    loses its first bending mode (kept in the design model) at standstill, 0 bar
    (measured: 254 Hz, ζ −0.04), and at
    standstill at its design pressure too (ζ −0.03): the refusal names the speed and the
    controller scheduled on speed, not only a seal range that cannot cover a gyroscopic
    shift; where the pressure alone lost it (the manual's compressor: its piston's K gone
    at 0 bar), the seal's range."""
    check = {"mode_hz": 253.9, "damping": -0.043, "pressure_bar": 0.0, "speed_hz": 0.0}
    msg = _unstable_message("hinf", check, 30, [], 1000.0, (False, True, 183.333))
    assert "gyroscopic" in msg and "--method lpv" in msg and "uncertainty" not in msg
    msg = _unstable_message("hinf", check, 30, [], 1000.0, (True, True, 183.333))
    assert "gyroscopic" in msg and "[[design.uncertainty]]" in msg
    msg = _unstable_message("hinf", check, 30, [], 1000.0, (True, False, 183.333))
    assert "[[design.uncertainty]]" in msg and "--method lpv" not in msg


def test_a_mu_refusal_names_the_parameter_it_was_not_robust_to():
    """The back-to-back compressor's μ robust to the division wall's k over 0–9.96 MN/m
    (±100 % at 60 bar): at 120 bar its k is 8.3e4·120 = 9.96e6 N/m (the rig file's
    affine law), on the range's edge, and its K (1.5e4·120 = 1.8e6 N/m) and C
    (100 + 220·120 N·s/m) differ from the design's 60 bar values and are not uncertain; at
    0 bar the eye labyrinths' k is 0 against 6e5 N/m. The refusal names each, the
    parameter and its value there, never only "widen the uncertainty"; with nothing
    outside, it names the bandwidth and the design-model states instead."""
    cfg = load_rig(EXAMPLES / "b2b_compressor.toml")
    f0 = cfg.operating.speed_rpm / 60.0
    k = UncertainParameter("division_wall.k", 4.98e6, 0.0, 9.96e6, 2, "N/m")
    out = _outside(cfg, (k,), {"pressure_bar": 120.0, "speed_hz": f0}, 60.0)
    assert any(o.startswith("division_wall.K = 1.8e+06 N/m") and "9e+05" in o for o in out)
    assert any(o.startswith("division_wall.C = 2.65e+04 N*s/m") for o in out)
    assert not any(o.startswith("division_wall.k") for o in out)
    narrow = UncertainParameter("division_wall.k", 4.98e6, 2e6, 8e6, 2, "N/m")
    out = _outside(cfg, (narrow,), {"pressure_bar": 120.0, "speed_hz": f0}, 60.0)
    assert "division_wall.k = 9.96e+06 N/m there, outside its range 2e+06–8e+06" in out
    out = _outside(cfg, (k,), {"pressure_bar": 0.0, "speed_hz": f0}, 60.0)
    assert any(o.startswith("eye_labyrinths.k = 0 N/m there against 6e+05") for o in out)
    check = {"mode_hz": 6.5, "damping": -0.3, "pressure_bar": 0.0, "speed_hz": f0}
    msg = _unstable_message("mu", check, 30, [], 1000.0, (True, False, f0), out)
    assert "eye_labyrinths.k = 0 N/m" in msg and "[[design.uncertainty]]" in msg
    msg = _unstable_message("mu", check, 30, [], 1000.0, (True, False, f0), [])
    assert "omega_b_rad_s" in msg and "design.model_states" in msg

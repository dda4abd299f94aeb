"""Generalised plant of the robust designs (thesis P5 §4.3, Figs. 8–9)."""

import numpy as np
import pytest
import control as ct

from ambseal.config import load_rig
from ambseal.lti.freqresp import freqresp
from ambseal.robust.mu import check_blocks
from ambseal.design.plant import generalized_plant
from ambseal.design.pid import pid_controller
from ambseal.design.weights import control_weight, performance_weight
from ambseal.errors import ModelError
from ambseal.model.rig import build_plant

W = 2 * np.pi * np.array([3.0, 40.0, 150.0, 600.0])


@pytest.fixture(scope="module")
def cfg():
    return load_rig()


@pytest.fixture(scope="module")
def gp(cfg):
    W1 = ct.tf([8.0, 0.0], [1.0, 2 * np.pi * 40.0])
    return generalized_plant(cfg, performance_weight(2.5, 30.0), control_weight(0.2),
                             uncertainty={"seal.k": 1.0}, states=12, input_disturbance=W1)


@pytest.fixture(scope="module")
def K(cfg):
    q = cfg.controller.pid
    return pid_controller(q.kp, q.ti, q.td, q.eps, ("A_zeta", "A_eta", "B_zeta", "B_eta"))


def _hand(G, K, Wp, Wu, W1, d_e, d_u, w):
    """[z_p; z_u] ← [d_i; d_o] by hand: e = S_o (G D_u/D_e W_1 d_i + d_o), u = −(D_e/D_u) K e."""
    Gw, Kw = freqresp(G, w), freqresp(K, w)
    out = []
    for k, wk in enumerate(w):
        s = 1j * wk
        So = np.linalg.inv(np.eye(4) + Gw[k] @ Kw[k])
        Kp = -(d_e / d_u) * Kw[k]
        e_di = So @ Gw[k] * (d_u / d_e) * complex(W1(s))
        e_do = So
        Ep = np.hstack([e_di, e_do])
        out.append(np.vstack([complex(Wp(s)) * Ep, complex(Wu(s)) * Kp @ Ep]))
    return np.array(out)


def test_channels_and_blocks(gp):
    """Order [w_Δ, d_i, d_o, u] / [z_Δ, z_p, z_u, y]; k and −k share one δ: block (−2, 0)."""
    assert gp.blocks == ((-2, 0), (8, 8))
    assert gp.P.ninputs == 2 + 4 + 4 + 4 and gp.P.noutputs == 2 + 4 + 4 + 4
    assert gp.P.input_labels[:3] == ["wD_seal_k_0", "wD_seal_k_1", "di_A_zeta"]
    assert gp.P.output_labels[-1] == "y_B_eta"
    assert gp.P_nominal.ninputs == 12 and gp.P_nominal.noutputs == 12
    k = gp.parameters[0]
    assert (k.low, k.high) == pytest.approx((0.0, 2 * 2.244e6))  # P5 §4.1: ±100 % of k(2.04 bar)
    check_blocks(gp.P, gp.blocks, gp.nmeas, gp.ncon)


def test_closed_loop_equals_hand_built_interconnection(gp, K):
    """F_l(P_nominal, K_P) = hand-built W_p S_o, W_p S_o G W_1, W_u K S_o … (P5 Fig. 8)."""
    Wp = performance_weight(2.5, 30.0)
    Wu = control_weight(0.2)
    W1 = ct.tf([8.0, 0.0], [1.0, 2 * np.pi * 40.0])
    got = freqresp(gp.closed_loop(K, nominal=True), W)
    want = _hand(gp.design_plant.to_statespace(), K, Wp, Wu, W1, gp.d_e, gp.d_u, W)
    assert np.allclose(got, want, rtol=1e-5, atol=1e-6 * np.abs(want).max())


@pytest.mark.parametrize("delta", [-1.0, 0.5, 1.0])
def test_uncertain_loop_equals_plant_at_that_k(cfg, gp, K, delta):
    """F_u(F_l(P, K_P), δ I₂) = the loop on the plant with k = k_c + h δ (P5 App. A LFT)."""
    M = freqresp(gp.closed_loop(K), W)
    Dl = delta * np.eye(2)
    Fu = np.array([m[2:, 2:] + m[2:, :2] @ Dl @ np.linalg.solve(np.eye(2) - m[:2, :2] @ Dl, m[:2, 2:])
                   for m in M])
    k = gp.parameters[0].value(delta)
    G = build_plant(cfg, reduced=True, states=12).with_values({"seal.k": k}).to_statespace()
    want = _hand(G, K, performance_weight(2.5, 30.0), control_weight(0.2),
                 ct.tf([8.0, 0.0], [1.0, 2 * np.pi * 40.0]), gp.d_e, gp.d_u, W)
    assert np.allclose(Fu, want, rtol=1e-5, atol=1e-6 * np.abs(want).max())


def test_force_disturbance_channel(cfg, K):
    """With W_f on a force at the seal, d_f → z_p is W_p S_o G_f W_f / D_e (P5 §4.4.1)."""
    Wp = performance_weight(2.5, 30.0)
    Wf = ct.tf([0.5, 0.0], [1 / 1000.0, 1.0])
    g = generalized_plant(cfg, Wp, control_weight(0.2), states=12, force_disturbance=Wf,
                          force_positions=(0.43,))
    assert g.P_nominal.input_labels[8:10] == ["df_F0_x", "df_F0_y"]
    pl = build_plant(cfg, reduced=True, states=12, force_positions=(0.43,))
    G = pl.select_inputs(pl.input_names[:4]).to_statespace()
    Gf = pl.select_inputs(pl.input_names[4:]).to_statespace()
    Gw, Kw, Gfw = freqresp(G, W), freqresp(K, W), freqresp(Gf, W)
    got = freqresp(g.closed_loop(K, nominal=True), W)[:, :4, 8:10]
    for k, wk in enumerate(W):
        So = np.linalg.inv(np.eye(4) + Gw[k] @ Kw[k])
        want = complex(Wp(1j * wk)) * complex(Wf(1j * wk)) * So @ Gfw[k] / g.d_e
        assert np.allclose(got[k], want, rtol=1e-7)


def test_bad_inputs(cfg, gp):
    """Zero-width range, improper weight, unknown parameter, mismatched blocks: clear errors."""
    Wp, Wu = performance_weight(2.5, 30.0), control_weight(0.2)
    with pytest.raises(ValueError, match="zero or negative width"):
        generalized_plant(cfg, Wp, Wu, uncertainty={"seal.k": (1e6, 1e6)})
    with pytest.raises(ValueError, match="W_p is not proper"):
        generalized_plant(cfg, ct.tf([1, 1], [1]), Wu)
    with pytest.raises(ValueError, match="W_u"):
        generalized_plant(cfg, Wp, ct.tf([1], [1, 1]))  # strictly proper: D12 rank
    with pytest.raises(ModelError, match="unknown parameter"):
        generalized_plant(cfg, Wp, Wu, uncertainty={"seal.kk": 1.0})
    with pytest.raises(ValueError, match="covers 3 inputs"):
        check_blocks(gp.P, [(-3, 0), (8, 8)][:1], gp.nmeas, gp.ncon)
    from ambseal.robust.dk import musyn

    with pytest.raises(ValueError, match="blocks"):
        musyn(gp.P, [(-3, 0), (8, 8)], gp.nmeas, gp.ncon, W)

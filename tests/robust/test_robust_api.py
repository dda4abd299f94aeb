"""The robust-control core on a plant that is not a rotor, with no rotor module loaded.

Skogestad & Postlethwaite, *Multivariable Feedback Control*, 2nd ed., §8.12.4 (the
distillation column with input uncertainty and performance weights, tests/distillation.py).
The calls are those a control engineer makes with python-control at hand; the script runs
in a fresh interpreter so that its ``sys.modules`` shows what ``ambseal.robust`` pulled in.
"""

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[2]

SCRIPT = r"""
import json, sys
import control
import numpy as np
from slycot import ab13md
sys.path.insert(0, ROOT)
from tests.distillation import distillation_rp_plant

from ambseal.robust import hinfsyn, lpvsyn, mussv, musyn

P = distillation_rp_plant()
blocks = [(1, 1), (1, 1), (2, 2)]
K, CL, gamma, info = hinfsyn(P, 2, 2)              # as control.hinfsyn(P, nmeas, ncon)
w = np.logspace(-3, 3, 61)
mu = mussv(CL, blocks, w, tol=1e-5)
H = np.moveaxis(CL(1j * w), -1, 0)
ref = [ab13md(Hk, np.array([1, 1, 2]), np.array([2, 2, 2]))[0] for Hk in H]
Kdk, CLdk, mu_dk, dk = musyn(P, blocks, 2, 2, w, max_iter=3, search=100)  # unpacked alike
mu_cl = mussv(CLdk, blocks, dk.check_omega, tol=1e-5).upper.max()
poles = [1 / 100, 1 / 75, 1 / 50]                   # an LPV family: the column's pole
family = [distillation_rp_plant(a, wp_low=0.1) for a in poles]
Klpv, CLlpv, gamma_lpv, lpv = lpvsyn(family, poles, 2, 2)   # CL: a function of the pole
frozen = [hinfsyn(Pk, 2, 2).gamma_opt for Pk in family]
wl = np.logspace(-4, 2, 40)
cl_gap, cl_norm = [], []
for a, Pk in zip(poles, family):                    # python-control's lower LFT, u = K y
    ref_cl = Pk.lft(control.ss(Klpv.at(a)), 2, 2)
    cl_gap.append(float(np.max(np.abs(CLlpv(a)(1j * wl) - ref_cl(1j * wl)))))
    cl_norm.append(float(control.linfnorm(CLlpv(a))[0]))
rotor = sorted({m.split(".")[1] for m in sys.modules if m.startswith("ambseal.")}
               - {"robust", "lti", "errors", "files", "threads", "lazy"})
print(json.dumps({
    "gamma": gamma, "gamma_opt": info.gamma_opt, "gamma_pc": control.hinfsyn(P, 2, 2)[2],
    "closed_loop_inputs": CL.ninputs, "K_inputs": list(K.input_labels),
    "closed_loop_inputs_names": list(CL.input_labels),
    "mu_upper": mu.upper.tolist(), "mu_lower": mu.lower.tolist(), "mu_ab13md": ref,
    "musyn_mu": mu_dk, "musyn_mu_of_its_loop": mu_cl, "lpv_gamma": gamma_lpv, "lpv_stable": lpv.check_stable,
    "lpv_gamma_design": lpv.gamma_design, "lpv_cl_gap": cl_gap, "lpv_cl_norm": cl_norm,
    "lpv_cl_inputs": list(CLlpv(poles[0]).input_labels),
    "frozen_gamma": frozen, "rotor_modules": rotor}))
"""


def test_the_core_runs_on_skogestads_column_with_no_rotor_in_sight():
    """References: python-control's hinfsyn on the same plant (γ_opt to 1e-4), SLICOT
    AB13MD at every frequency (μ upper bound to 1e-3), the frozen H∞ optima as lower
    bounds of the LPV γ; the D–K iteration improves on the H∞ controller's μ (its D
    search capped at 100 γ evaluations: the defaults' search, about 20 s here, is
    tests/robust/test_robust_dk.py's)."""
    out = subprocess.run([sys.executable, "-c", SCRIPT.replace("ROOT", repr(str(ROOT)))],
                         capture_output=True, text=True, check=True)
    r = json.loads(out.stdout.strip().splitlines()[-1])
    assert r["rotor_modules"] == []
    assert abs(r["gamma_opt"] - r["gamma_pc"]) <= 1e-4 * r["gamma_pc"]
    assert r["gamma_opt"] <= r["gamma"] <= 1.02 * r["gamma_opt"]
    assert r["closed_loop_inputs"] == 4 and r["K_inputs"] == ["v0", "v1"]  # P's names
    up, lo, ref = (np.array(r[k]) for k in ("mu_upper", "mu_lower", "mu_ab13md"))
    np.testing.assert_allclose(up, ref, rtol=1e-3)
    assert np.all(lo <= up * (1 + 1e-9))
    assert r["musyn_mu"] < up.max()
    assert abs(r["musyn_mu_of_its_loop"] - r["musyn_mu"]) <= 2e-3 * r["musyn_mu"]
    assert r["lpv_stable"] and r["lpv_gamma"] >= max(r["frozen_gamma"]) * (1 - 1e-6)
    # the frozen closed loops lpvsyn hands back are python-control's lft of P and K(Ω),
    # and each meets the reconstruction's bound (1.02 γ_design, lpvsyn's docstring)
    assert max(r["lpv_cl_gap"]) < 1e-9
    assert max(r["lpv_cl_norm"]) <= 1.02 * r["lpv_gamma_design"]
    assert r["lpv_cl_inputs"] == r["closed_loop_inputs_names"]

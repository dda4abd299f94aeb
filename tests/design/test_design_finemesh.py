"""The whole μ design path on a rotor meshed with 400 beam elements, the rig format's bound
(3 200+ states): the design model is a modal reduction of the FE model (thesis P3, P5), so
the fine mesh changes what the synthesis sees only by the mesh's convergence, and the
full-order loops are still judged on every state."""

import numpy as np
import pytest

from ambseal.config import load_rig
from ambseal.design.recipes import design, full_order_check
from ambseal.design.specs import design_spec
from ambseal.robust.hinf import hinfsyn

from ..finemesh import fine_rig_text

#: the sections' elements: split at the component positions off their boundaries, the
#: mesh holds 400 beam elements, MAX_ELEMENTS (ambseal.model.rotor.build_mesh)
ELEMENTS = 396


@pytest.mark.slow
def test_mu_design_on_400_elements(tmp_path, testrig_cfg, testrig_designs):
    """``design(cfg, "mu")`` (``build_plant(reduced=True)``, D–K, order reduction, the
    full-order check at the judged conditions) on the embedded rig at 400 elements:

    * the design problem is the default mesh's: the nominal H∞ optimum γ of the
      generalised plant equals the 34-element one to 1e-4 (a continuous function of the
      plant, measured 7e-7 apart at 230 elements);
    * the controller stabilises the full-order loop of its own 400-element plant and of
      the default mesh's at every judged condition (an independent model of the same
      machine);
    * its D–K μ before order reduction lies within 5 % of the default mesh's (D–K is a
      local iteration that stops at 1 % progress; its first K-step's μ varies from 2.5 to
      7 between meshes whose γ agree to 1e-6, and it ends 1.5–1.8 % apart at 230 and 400
      elements).
    """
    rig = tmp_path / f"testrig_{ELEMENTS}.toml"
    rig.write_text(fine_rig_text(ELEMENTS), encoding="utf-8")
    cfg = load_rig(rig)
    assert sum(s.elements for s in cfg.shaft) == ELEMENTS
    r = design(cfg, "mu")
    ref = testrig_designs["mu"]
    assert r.design_states == ref.design_states
    gammas = [hinfsyn(d.plant.P_nominal, d.plant.nmeas, d.plant.ncon).gamma for d in (r, ref)]
    assert gammas[0] == pytest.approx(gammas[1], rel=1e-4)
    assert r.full_order["stable"]
    sp = design_spec(testrig_cfg)
    conditions = [(q, f) for q in sp.pressures_bar for f in sp.speeds_hz]
    assert full_order_check(testrig_cfg, r.K, conditions)["stable"]
    assert np.isfinite(r.mu)
    assert r.reduction["mu_full"] == pytest.approx(ref.reduction["mu_full"], rel=0.05)

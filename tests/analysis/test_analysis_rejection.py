"""The unbalance force rejection judged (analysis/rejection.py) on the turboexpander: its
loops at the judged conditions and its synchronous response against the controller
alone."""

import numpy as np
import pytest

from ambseal.analysis.judge import OperatingPoint, judge_settings
from ambseal.analysis.rejection import rejection_effect, rejection_stability
from ambseal.design import design_spec

from ..freq_at import at


@pytest.fixture
def rejection(turbo_rejection):
    return turbo_rejection


def test_rejection_stability_judges_where_the_notch_is_on(turbo_cfg, rejection):
    """Conditions below the minimum continuous speed are left to the controller alone;
    at the others both loops are judged: stable, continuous and as it runs."""
    lo, hi = turbo_cfg.operating.continuous_hz
    p = turbo_cfg.operating.pressure_bar
    points = [OperatingPoint(p, 60 * f, f"{f:g} Hz") for f in (0.0, 0.5 * lo, lo, hi)]
    rows = rejection_stability(turbo_cfg, rejection, points)
    assert [r["condition"] for r in rows] == [f"{lo:g} Hz", f"{hi:g} Hz"]
    for r in rows:
        assert r["stable"] and r["stable_as_runs"] and r["max_abs_pole_z"] < 1
        assert r["max_real_pole"] < 0


def test_rejection_effect_takes_out_the_synchronous_current(turbo_cfg, turbo_hinf_digital,
                                                            rejection):
    """Over the speed range (its ends the notch's table's) the largest synchronous coil
    current with the notch is below 1 % of the controller's alone at every speed, while
    the bearings still transmit a force (their negative stiffness's) and the rotor
    still has an orbit."""
    s = judge_settings(design_spec(turbo_cfg))
    e = rejection_effect(turbo_cfg, turbo_hinf_digital, rejection, s)
    lo, hi = turbo_cfg.operating.continuous_hz
    assert e["speed_hz"][0] == pytest.approx(lo) and e["speed_hz"][-1] == pytest.approx(hi)
    assert np.all(e["current_a"]["with"] < 1e-2 * e["current_a"]["without"])
    assert np.all(e["current_a"]["without"] > 0)
    assert np.all(e["force_n"]["with"] > 0) and np.all(e["orbit_um"]["with"] > 0)


def test_facility_runout_current_is_the_sampled_loop_s_and_the_notch_removes_it(
        turbo_cfg, turbo_hinf_digital, rejection):
    """Reference: the full-order plant and the amplifier sampled by python-control's
    zero-order hold (c2d) and the controller with its delay, at e^{jΩT_s} (dense solves,
    :mod:`tests.freq_at`): a sensor runout r (ζ: r cos Ωt, η: r sin Ωt) asks the current
    reference −K S_o r and the coil H_a,d of it. The facility's synchronous coil current
    with the controller alone equals that to 2 % (its force law is nonlinear, its plant
    the modes below 10 kHz); with the notch switched on it falls below 1 % of it."""
    import control as ct

    from ambseal.analysis.rejection import facility_rejection
    from ambseal.model import actuator_matrices, build_plant

    cfg = turbo_cfg
    f = float(rejection.speeds_hz[-1])
    r = facility_rejection(cfg, turbo_hinf_digital, rejection, f)
    fs = cfg.controller.sample_rate_hz
    w, T = 2 * np.pi * f, 1.0 / fs
    pl = build_plant(cfg, pressure_bar=rejection.pressure_bar, speed_rpm=60 * f)
    P, cur = pl.to_statespace(), pl.current_inputs()
    G = ct.c2d(ct.ss(P.A, P.B[:, cur], P.C, P.D[:, cur]), T, "zoh")
    K = turbo_hinf_digital.statespace(delayed=True)
    rows = [list(P.output_labels).index(n) for n in K.input_labels]
    cols = [[P.input_labels[j] for j in cur].index(n) for n in K.output_labels]
    z = np.exp(1j * w * T)
    Gz, Kz = at(G, z)[np.ix_(rows, cols)], at(K, z)
    runout = np.array([r.runout_m * (1.0 if n.endswith("zeta") else -1j)
                       for n in K.input_labels])
    iref = -Kz @ np.linalg.solve(np.eye(len(rows)) + Gz @ Kz, runout)
    Ha = at(ct.c2d(ct.ss(*actuator_matrices(cfg.actuator)), T, "zoh"), z)
    coil = np.abs(complex(np.squeeze(Ha)) * iref).max()
    assert r.before_a == pytest.approx(coil, rel=2e-2)
    assert r.after_a < 1e-2 * r.before_a


def test_facility_speed_step_keeps_the_synchronous_current_out(turbo_cfg, turbo_hinf_digital,
                                                              rejection):
    """A step from 270 to 300 Hz on the facility under the runout: with the notch the
    synchronous coil current and the orbit stay below 1 % of the controller's alone after
    the step, at every revolution; the controller alone settles at the new speed to what
    the facility built at that speed gives at constant speed (facility_rejection's
    ``before_a``) to 1 %."""
    from ambseal.analysis.rejection import facility_rejection, facility_speed_step

    step = facility_speed_step(turbo_cfg, turbo_hinf_digital, rejection, 270.0, 300.0)
    after = step.time_s > step.step_s
    for q in (step.current_a, step.orbit_m):
        assert np.all(q["with"][after] < 1e-2 * q["without"][after])
    const = facility_rejection(turbo_cfg, turbo_hinf_digital, rejection, 300.0)
    assert step.current_a["without"][-1] == pytest.approx(const.before_a, rel=1e-2)


def _row(label, p, f, stable, as_runs):
    return {"condition": label, "pressure_bar": p, "speed_hz": f, "stable": stable,
            "stable_as_runs": as_runs}


#: The rows of a rig judged at one speed (305.185 Hz): its judged point labelled by
#: pressure alone, its stability speeds by pressure and speed
LOST_ROWS = [_row("0 bar", 0.0, 305.185, False, False),
             _row("0 bar, 98.66 Hz", 0.0, 98.66, True, True),
             _row("0 bar, 295.987 Hz", 0.0, 295.987, True, False),
             _row("2 bar, 120 Hz", 2.0, 120.0, True, None),
             _row("0 bar, 295.987 Hz", 0.0, 295.987, False, None)]


def test_a_lost_condition_is_named_by_its_pressure_and_speed_whatever_its_label():
    """The lost ones of those rows, joined, had read "0 bar, 0 bar, 295.987 Hz": each is
    named by its own pressure and speed, once, in the rows' order."""
    from ambseal.analysis.rejection import lost_conditions

    assert lost_conditions(LOST_ROWS) == ["0 bar, 305.185 Hz", "0 bar, 295.987 Hz"]

"""The virtual facility refuses a controller that does not stabilise its loop (the
pump's and the blower's records with the test rig's eddy lag in the truth)."""

from pathlib import Path

import numpy as np
import pytest

from ambseal.config import TruthSection, load_rig
from ambseal.design.pid import pid_controller, pid_from_rig
from ambseal.errors import ModelError
from ambseal.robust.digital_loop import discrete_controller
from ambseal.identify.facility.rig_sim import prepare_facility, simulate_facility
from ambseal.identify.fitting.stages import build_models
from ambseal.model.amb import channel_names

PUMP = Path(__file__).resolve().parents[2] / "examples" / "pump.toml"


def test_pump_pid_with_an_unseen_eddy_lag_is_refused():
    """examples/pump.toml has no eddy-current lag; its derived PID (designed on that file)
    with a truth of τ_e = 0.2 ms — the test rig's — is refused before the run, naming τ_e.
    References: (1) the facility's linearised loop poles (sub-step transitions to the power
    ``substeps``) equal those of the fit's model of the same loop, assembled independently
    (continuous plant, amplifier and lag in series, one ZOH at the sample period), to 1e-6;
    (2) the facility's own nonlinear run, not stopped by the check, grows by the pole's
    modulus: a 2 ms kick's response is ≥ 5× larger 0.3 s later (|z|³⁰⁰⁰ = e^2.97 ≈ 19)."""
    cfg = load_rig(PUMP)
    p = pid_from_rig(cfg)
    fs = cfg.controller.sample_rate_hz
    K = discrete_controller(pid_controller(p["kp"], p["ti"], p["td"], p["eps"],
                                           channel_names(cfg)), 1 / fs)
    truth = TruthSection(tau_e=2e-4, bias_current=5.0)
    n = int(0.4 * fs)
    e = np.zeros((n, 4))
    e[:20, 0] = 0.05
    with pytest.raises(ModelError, match=r"does not stabilise.*tau_e = 0\.2 ms"):
        simulate_facility(cfg, truth, e, fs, K, pressure_bar=0.0)
    fac = prepare_facility(cfg, truth, fs, pressure_bar=0.0)
    z = fac.loop_poles(K)
    model = build_models(cfg, [_record(fac.axes, fs)], {"tau_e": 2e-4}, controllers=[K])[0]
    ref = np.linalg.eigvals(model.statespace({}, fac.axes).A)
    assert np.abs(z).max() > 1.0005
    np.testing.assert_allclose(np.sort_complex(z[np.abs(z) > 0.9]),
                               np.sort_complex(ref[np.abs(ref) > 0.9]), atol=1e-6)
    y, _, _ = fac.run(K, np.zeros(K.A.shape[0]), e, np.zeros_like(e), np.zeros_like(e))
    early, late = (np.abs(y[int(a * fs):int(b * fs)]).max() for a, b in ((0.05, 0.1),
                                                                         (0.35, 0.4)))
    assert late > 5 * early
    # the same PID on the rig file's own truth (no lag) runs
    rec = simulate_facility(cfg, TruthSection(bias_current=5.0), e, fs, K, pressure_bar=0.0)
    assert np.abs(rec.displacement_m[-400:]).max() < np.abs(rec.displacement_m).max() / 5


def _record(axes, fs):
    """A record's metadata as build_models reads it (no samples needed for the model)."""
    from types import SimpleNamespace

    return SimpleNamespace(axes=axes, metadata={"sample_rate_hz": fs, "pressure_drop_pa": 0.0})


def test_a_speed_schedule_carries_the_plant_to_the_new_speed(turbo_cfg, turbo_hinf_digital):
    """Reference: the facility built at the new speed itself (its own modes). The
    turboexpander's facility at 150 Hz stepped to 300 Hz at t = 0 — the plant at 300 Hz
    projected on the 150 Hz modes — runs the same current-excitation record, under its
    H∞, as the facility built at 300 Hz to 1e-3 of the response's peak (gyroscopics
    double; a 150 → 150 Hz step is the plain facility to rounding)."""
    from ambseal.identify import at_speed
    from ambseal.robust import DiscreteController

    cfg = turbo_cfg
    fs = cfg.controller.sample_rate_hz
    K = turbo_hinf_digital.statespace(delayed=True)
    Kd = DiscreteController(*(np.asarray(getattr(K, m), float) for m in "ABCD"), 1 / fs)
    n, truth = 4000, TruthSection()
    e = np.zeros((n, 4))
    e[100:110, 0] = 0.05  # a current impulse on A ζ
    z = np.zeros((n, 4))

    def record(f_base, schedule):
        fac = prepare_facility(at_speed(cfg, f_base), truth, fs,
                               pressure_bar=cfg.operating.pressure_bar,
                               speed_schedule=schedule)
        return fac.run(Kd, np.zeros(Kd.A.shape[0]), e, z, z)[0]

    stepped, own = record(150.0, [(0.0, 300.0)]), record(300.0, None)
    assert np.abs(stepped - own).max() < 1e-3 * np.abs(own).max()
    assert np.abs(record(150.0, None) - own).max() > 1e-2 * np.abs(own).max()
    same = record(150.0, [(0.0, 150.0)])
    np.testing.assert_allclose(same, record(150.0, None), rtol=0, atol=1e-9 * np.abs(own).max())
    with pytest.raises(ModelError, match="not both"):
        prepare_facility(cfg, truth, fs, pressure_bar=0.0, pressure_schedule=[(0.1, 1.0)],
                         speed_schedule=[(0.1, 200.0)])

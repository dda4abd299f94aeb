"""The PID derived from the rig (no ``[controller.pid]``, control/recipes.pid_from_rig) and
the controller that cannot run on the target (commands.digitals_for), on the blower and the
pump: two machines of different size, sample rate and first bending mode."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from ambseal.analysis.judge import operating_points
from ambseal.config import load_rig
from ambseal.design.pid import PID_CORNERS_PER_FS, pid_controller, pid_from_rig
from ambseal.design.specs import design_spec
from ambseal.lti.interconnect import feedback_matrices
from ambseal.model.amb import channel_names
from ambseal.model.rig import build_plant
from ambseal.model.rotor import assemble_rotor

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
# From the rig files themselves: Ki (N/A), Ks (N/m), sample rate (Hz)
RIGS = {"blower": (40.0, 2.0e5, 20000.0), "pump": (300.0, 3.0e6, 10000.0)}


@pytest.fixture(scope="module")
def rigs():
    out = {}
    for name in RIGS:
        cfg = load_rig(EXAMPLES / f"{name}.toml")
        points = operating_points(design_spec(cfg))
        plants = []
        for p in points:
            pl = build_plant(cfg, pressure_bar=p.pressure_bar, speed_rpm=p.speed_rpm)
            cur = pl.current_inputs()
            plants.append((pl.A, pl.B[:, cur], pl.C, pl.D[:, cur]))
        out[name] = (cfg, points, plants, pid_from_rig(cfg))
    return out


def _sampled_loop_radius(G, K, fs: float, delay: int) -> float:
    """Largest |z| of the sampled loop, by python-control and SciPy only: the plant sampled
    with a zero-order hold (scipy.signal.cont2discrete), the controller by Tustin
    (control.sample_system), ``delay`` samples of computation as z^-delay on its output
    (Franklin, Powell & Workman, Digital Control of Dynamic Systems, §6.2 and §4.3.4)."""
    import control
    from scipy.signal import cont2discrete

    T = 1.0 / fs
    Ad, Bd, Cd, Dd, _ = cont2discrete(G, T, method="zoh")
    Gd = control.ss(Ad, Bd, Cd, Dd, T)
    Kd = control.sample_system(K, T, "tustin")
    n = K.noutputs
    z_delay = control.ss(np.zeros((0, 0)), np.zeros((0, n)), np.zeros((n, 0)), np.eye(n), T)
    for _ in range(delay):
        z_delay = control.ss(np.zeros((n, n)), np.eye(n), np.eye(n), np.zeros((n, n)), T) \
            * z_delay
    loop = control.feedback(Gd * z_delay * Kd, np.eye(n))  # i = −K y
    return float(np.abs(loop.poles()).max())


def test_derived_pid_rule_closed_forms(rigs):
    """Reference: the rule's closed forms from the rig file's numbers (P5 Eq. 6; Schweitzer
    & Maslen 2009 §7.2): Kp = 1.5 Ks/Ki (k_eq = Ki Kp − Ks = Ks/2), the rigid rotor
    m_b s² + Ki Kp Td s + k_eq critically damped (ζ = 1, m_b half the rotor mass),
    Ti = 50/ω_n, and the derivative filter's pole 1/(ε Td) at one of the stated fractions
    of the sample rate, at most f_s/5."""
    for name, (ki, ks, fs) in RIGS.items():
        cfg, d = rigs[name][0], rigs[name][3]
        K = pid_controller(d["kp"], d["ti"], d["td"], d["eps"], channel_names(cfg))
        corner = d["corner_hz"]
        assert min(abs(corner / fs - c) for c in PID_CORNERS_PER_FS) < 1e-12
        poles = np.sort(np.abs(np.linalg.eigvals(np.asarray(K.A, float))))
        assert poles[-1] == pytest.approx(2 * np.pi * corner, rel=1e-9)
        assert corner <= fs / 5
        kp = 1.5 * ks / ki
        s = 2j * np.pi * 1.0
        m_b = assemble_rotor(cfg).mass / 2
        td = 2 * np.sqrt(0.5 * ks * m_b) / (ki * kp)  # ζ = 1
        ti = 50 / np.sqrt(0.5 * ks / m_b)
        eps = 1 / (2 * np.pi * corner * td)
        want = kp * (1 + 1 / (ti * s) + td * s / (eps * td * s + 1))
        np.testing.assert_allclose(np.asarray(K(s))[0, 0], want, rtol=1e-9)


def test_derived_pid_runs_on_the_target_where_p5s_filter_does_not(rigs):
    """Reference: the sampled loop's poles by SciPy/python-control (_sampled_loop_radius).
    On the blower (20 kHz) and the pump (10 kHz), one sample of delay: the derived PID's
    continuous and sampled loops are stable at every judged condition, while the same PID
    with P5's ε = 0.1 (its filter at 0.50 and 0.43 kHz) is unstable as it runs at each."""
    for name, (cfg, points, plants, d) in rigs.items():
        K = pid_controller(d["kp"], d["ti"], d["td"], d["eps"], channel_names(cfg))
        fs, delay = cfg.controller.sample_rate_hz, cfg.controller.delay_samples
        Kp5 = pid_controller(d["kp"], d["ti"], d["td"], 0.1, channel_names(cfg))
        Km = tuple(np.asarray(getattr(K, m), float) for m in "ABCD")
        for G in plants:
            assert np.linalg.eigvals(feedback_matrices(G, Km)[0]).real.max() < 0, name
            assert _sampled_loop_radius(G, K, fs, delay) < 1, name
            assert _sampled_loop_radius(G, Kp5, fs, delay) > 1, name


def test_a_controller_that_cannot_run_is_stated_and_the_others_go_on(rigs):
    """Reference: the previous test's sampled-loop poles — P5's ε = 0.1 cannot run on the
    pump's target; digitals_for leaves it out with one line naming it, the sample rate and
    the delay, and delivers the derived PID beside it."""
    from ambseal.app.commands import digitals_for
    from ambseal.app.commands import Designed
    from ambseal.design import DesignResult

    cfg, points, _, d = rigs["pump"]
    good = pid_controller(d["kp"], d["ti"], d["td"], d["eps"], channel_names(cfg))
    bad = pid_controller(d["kp"], d["ti"], d["td"], 0.1, channel_names(cfg))
    designs = [Designed(DesignResult("pid", good, 0.0)),
               Designed(DesignResult("old_pid", bad, 0.0))]
    said = []
    digitals, cannot = digitals_for(cfg, designs, points, said.append)
    assert list(digitals) == ["pid"] and list(cannot) == ["old_pid"]
    assert cannot["old_pid"].startswith("old_pid cannot run on the target")
    assert "sample_rate_hz = 10000 Hz (delay 1 samples)" in cannot["old_pid"]
    assert said == [cannot["old_pid"]]


def test_the_rule_says_which_plants_its_damping_ratios_are_of(rigs):
    """The blower's derived PID takes filters for its bending modes, chosen on each judged
    condition's plant reduced to its modes below the sample rate (20 kHz): the damping
    ratios its rule states are of those plants, not of the full-order loop the run judges,
    and the rule says so where it states them."""
    rule = rigs["blower"][3]["rule"]
    assert "structural damping as it runs on the modes below f_s, else the best" in rule
    assert "; flexible modes as it runs on the modes below f_s = 20000 Hz: 1600 Hz mode" in rule

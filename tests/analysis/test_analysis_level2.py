"""API 617 Level II: the table of a rigid rotor on damped springs with a seal and a
stage against the closed form of its cylindrical whirl, m s² + c s + k − jQ = 0; the
graded mode of a gyroscopic rigid rotor on a PID against an independent eigen-analysis
of its sampled loop in complex coordinates."""

from __future__ import annotations

import math
import tomllib

import numpy as np
import pytest
import scipy.linalg as sla
from scipy import signal

from ambseal.analysis.signoff.level1 import stage_cross_coupling
from ambseal.analysis.signoff.level2 import level2_analysis
from ambseal.config import parse_rig
from ambseal.design.pid import pid_controller
from ambseal.model import channel_names
from ambseal.robust import discrete_controller
from ambseal.robust.digital import DigitalController

from ..rigid_rotor import L, inertia, rotor_text
from .test_analysis_level1 import _rigid_rotor


def _log_dec(m, c, k, Q):
    lam = np.roots([m, c, k - 1j * Q])
    lam = lam[lam.imag > 0][0]
    return -2 * math.pi * lam.real / lam.imag


@pytest.mark.parametrize("seal_k, passed", [(2e5, True), (8e5, False)])
def test_level2_rows_are_the_closed_form(seal_k, passed):
    """Rotor alone, + the seal (k, C at mid-span), + Q_A at the stage, all: each row's δ
    the forward root of m s² + c s + k − jQ (Q and c summed at mid-span) within 1 %; the
    verdict δ ≥ 0.1 with every source."""
    k, c, c_seal = 1e7, 2000.0, 100.0
    doc = tomllib.loads(_rigid_rotor(k, c, 4.5e4))
    doc["seal"] = [{"name": "eye", "position": 0.2, "k": seal_k, "C": c_seal}]
    cfg = parse_rig(doc)
    r = level2_analysis(cfg)
    m = math.pi / 4 * 0.2**2 * 0.4 * 7850.0
    qa = stage_cross_coupling(cfg.stage[0], "compressor", 2 * math.pi * 50.0)
    want = [_log_dec(m, c, k, 0.0), _log_dec(m, c + c_seal, k, seal_k),
            _log_dec(m, c, k, qa), _log_dec(m, c + c_seal, k, seal_k + qa)]
    assert [row.component for row in r.rows] == ["rotor and supports", "+ seal eye",
                                                 "+ Q_A at the stages", "all sources"]
    assert [row.log_dec for row in r.rows] == pytest.approx(want, rel=0.01)
    assert r.log_dec == r.rows[-1].log_dec and r.limit == 0.1
    assert r.passed is passed and bool(want[-1] >= 0.1) is passed
    assert r.to_dict()["table"][1]["component"] == "+ seal eye"


def test_level2_judges_the_mode_the_sources_act_on():
    """Without modal damping the shaft's bending modes keep δ ≈ 0.0002 whatever the
    sources do: Level II follows the cylindrical whirl Q_A takes damping from (50 Hz,
    δ = 0.166 by the closed form), not them."""
    doc = tomllib.loads(_rigid_rotor(1e7, 2000.0, 4.5e4))
    cfg = parse_rig(doc)
    r = level2_analysis(cfg)
    m = math.pi / 4 * 0.2**2 * 0.4 * 7850.0
    qa = stage_cross_coupling(cfg.stage[0], "compressor", 2 * math.pi * 50.0)
    assert r.log_dec == pytest.approx(_log_dec(m, 2000.0, 1e7, qa), rel=0.01)
    assert r.rows[-1].frequency_hz == pytest.approx(math.sqrt(1e7 / m) / (2 * math.pi),
                                                    rel=0.01) and r.passed


#: A disc-like rotor (I_p/I_t 1.10) on two AMBs at its ends, a PD like the derived PID
#: (k_eq = Ks/2, ζ = 0.95 on the cylindrical mode, no integral): at 200 Hz the gyroscopic
#: moments lift the forward conical mode (the nutation) out of the derivative's reach
#: while the cylindrical mode stays overdamped, an oscillating pole near 3.5 Hz.
DISK = (20.0, 0.9, 0.5)
KS, KI, FS, SPEED_HZ = 2.0e5, 100.0, 1.0e4, 200.0


def _gyroscopic_rig_and_pid(stage: str = ""):
    """The rigid rotor of :mod:`tests.rigid_rotor` on AMBs at 0 and L (sensors there too),
    its bending modes damped (ζ 0.05: they lie near 1 MHz and alias into the sampled
    loop's band), and the PID (kp, ti, td, eps) at 10 kHz with one sample of delay;
    ``stage`` is more of the rig file (a ``[[stage]]``)."""
    text = rotor_text("disc-like rigid rotor", *DISK, 4).replace(
        'name = "disc-like rigid rotor"', 'name = "disc-like rigid rotor"\nmodal_damping = 0.05')
    for name, z in (("A", 0.0), ("B", L)):
        text += (f'[[amb]]\nname = "{name}"\nposition = {z}\nsensor_position = {z}\n'
                 f"ki = {KI}\nks = {KS}\nbias_current = 5.0\ncurrent_limit = 10.0\n")
    text += (f"[controller]\nsample_rate_hz = {FS}\ndelay_samples = 1\n"
             f"[operating]\nspeed_rpm = {60 * SPEED_HZ}\n" + stage)
    m = inertia(*DISK)[0]
    k_eq = KS / 2
    kp = (KS + k_eq) / KI
    td = 2 * 0.95 * math.sqrt(k_eq * m / 2) / (KI * kp)  # ζ = 0.95 on m/2 per bearing
    eps = 1 / (2 * math.pi * 0.07 * FS * td)  # the derivative's corner at 0.07·fs
    return parse_rig(tomllib.loads(text)), (kp, 1e6, td, eps)


def _complex_sampled_loop(kp, ti, td, eps, q: float = 0.0):
    """Every eigenvalue λ = ln z/T (rad/s) of the sampled loop in complex coordinates
    r = x + jy, φ = θ_y − jθ_x of the rigid rotor (Genta, *Dynamics of Rotating Systems*,
    2005, §4.6): m r̈ = ΣF_b + jq r, I_t φ̈ − j I_p Ω φ̇ = Σ z_b F_b, F_b = Ks r_b + Ki i_b
    at r_b = r + z_b φ, the plant sampled by a zero-order hold, the PID by Tustin, i[k]
    the command of sample k − 1; ``q`` a cross-coupled stiffness k_xy = q, k_yx = −q at
    mid-span (f_x = −q y, f_y = q x: f = jq r). In these coordinates Im λ > 0 is a
    forward whirl, Im λ < 0 a backward one: the gyroscopic term stiffens the positive
    frequencies."""
    m, it, ip = inertia(*DISK)
    zb = np.array([-L / 2, L / 2])
    T = np.column_stack([np.ones(2), zb])  # r_b = T [r, φ]
    Minv = np.diag([1 / m, 1 / it])
    W = 2 * math.pi * SPEED_HZ
    A = np.block([[np.zeros((2, 2)), np.eye(2)],
                  [Minv @ (KS * T.T @ T + np.diag([1j * q, 0.0])),
                   Minv @ np.diag([0.0, 1j * ip * W])]])
    B = np.vstack([np.zeros((2, 2)), Minv @ (KI * T.T)])
    C = np.hstack([T, np.zeros((2, 2))])
    dt = 1 / FS
    E = sla.expm(np.block([[A, B], [np.zeros((2, 6))]]) * dt)
    Ad, Bd = E[:4, :4], E[:4, 4:]
    # K(s) = kp (1 + 1/(ti s) + td s/(eps td s + 1)) on each bearing, u = K y, i = −u
    tf = eps * td
    num = kp * np.array([tf + td, 1 + tf / ti, 1 / ti])
    ka, kb, kc, kd, _ = signal.cont2discrete(signal.tf2ss(num, [tf, 1.0, 0.0]), dt,
                                              method="bilinear")
    I2 = np.eye(2)
    Ka, Kb, Kc, Kd = (np.kron(I2, x) for x in (ka, kb, kc, kd))
    n, nk = 4, Ka.shape[0]
    # state [x; x_K; i]: x⁺ = Ad x + Bd i, x_K⁺ = Ka x_K + Kb C x, i⁺ = −(Kc x_K + Kd C x)
    L_ = np.block([[Ad, np.zeros((n, nk)), Bd],
                   [Kb @ C, Ka, np.zeros((nk, 2))],
                   [-Kd @ C, -Kc, np.zeros((2, 2))]])
    return np.log(sla.eigvals(L_).astype(complex)) / dt


def test_level2_grades_the_first_forward_resonant_mode_not_an_overdamped_pole():
    """A gyroscopic rigid rotor on a PID at 200 Hz, without sources: Level II grades API
    617's first forward *resonant* mode (AF = π/δ ≥ 2.5, API 684 §1.3.3's critical speed)
    — the nutation, its frequency and δ those of the lowest forward eigenvalue with
    δ ≤ π/2.5 of an independent eigen-analysis of the same sampled loop in complex
    coordinates (to 1e-4 in frequency, 1e-3 in δ; the FE shaft, 1e4 times stiffer than
    steel, is the rest) — not the lowest forward pole, which there is overdamped, and the
    table names its kind."""
    cfg, (kp, ti, td, eps) = _gyroscopic_rig_and_pid()
    K = pid_controller(kp, ti, td, eps, channel_names(cfg))
    dc = DigitalController(K, K, discrete_controller(K, 1 / FS, "tustin"), "tustin", None,
                           FS, 1)
    r = level2_analysis(cfg, dc)
    lam = _complex_sampled_loop(kp, ti, td, eps)
    lam = lam[np.abs(lam.imag) > 2 * math.pi * 0.1]  # oscillating
    fwd = lam[lam.imag > 0]
    fwd = fwd[np.argsort(fwd.imag)]
    delta = -2 * math.pi * fwd.real / fwd.imag
    sharp = np.flatnonzero(math.pi / delta >= 2.5)
    want = fwd[sharp[0]]
    # the check has teeth: the lowest forward pole, the cylindrical, is overdamped
    assert sharp[0] > 0 and -fwd[0].real / abs(fwd[0]) == pytest.approx(0.95, abs=0.01)
    assert [row.component for row in r.rows] == ["rotor and supports", "all sources"]
    last = r.rows[-1]
    assert last.frequency_hz == pytest.approx(want.imag / (2 * math.pi), rel=1e-4)
    assert last.log_dec == pytest.approx(delta[sharp[0]], rel=1e-3)
    assert last.kind == "rigid conical, forward whirl: the nutation" == r.kind
    assert r.to_dict()["mode"] == last.kind and r.passed

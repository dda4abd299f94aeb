"""API 684's undamped critical speed map (:mod:`ambseal.analysis.signoff.ucs_map`): the
rigid rotor on two springs against its closed form, and a PID's AMB stiffness at 1× as
it runs against Tustin's mapping evaluated by hand, with the criticals it meets against
the rigid rotor's closed form on that stiffness."""

from __future__ import annotations

import math
import tomllib

import numpy as np
import pytest
from scipy.optimize import brentq

from ambseal.analysis.signoff.ucs_map import ucs_map, undamped_criticals_hz
from ambseal.analysis.synchronous import amb_dynamic_stiffness
from ambseal.config import parse_rig
from ambseal.design.pid import pid_controller
from ambseal.errors import ModelError
from ambseal.model import channel_names
from ambseal.robust import discrete_controller
from ambseal.robust.digital import DigitalController

from ..rigid_rotor import L, inertia, rotor_text

DISK = (20.0, 0.9, 0.5)


def _on_springs(z1: float, z2: float) -> str:
    text = rotor_text("rigid rotor on springs", *DISK, 8)
    for i, z in enumerate((z1, z2)):
        # their own stiffness and damping: the map replaces both, a seal is left out
        text += (f'[[spring]]\nname = "S{i}"\nposition = {z}\nkxx = 3e6\nkyy = 1e6\n'
                 "cxx = 500.0\ncyy = 500.0\n")
    return text + '[[seal]]\nname = "eye"\nposition = 0.2\nk = 5e6\nK = 4e7\nC = 1e3\n'


@pytest.mark.parametrize("z1, z2", [(0.0, L), (0.0, 0.3)])
def test_rigid_rotor_on_two_springs_is_the_closed_form(z1, z2):
    """A rigid rotor (mass m, transverse inertia I_t about its centre at L/2) on two
    isotropic springs k at a = L/2 − z1 and b = z2 − L/2 from it, undamped, without
    gyroscopics: its two critical speeds solve det([[2k − mω², k(b − a)], [k(b − a),
    k(a² + b²) − I_t ω²]]) = 0 (Friswell et al., *Dynamics of Rotating Machines*, 2010,
    §3.5; on symmetric supports √(2k/m) and √(2k a²/I_t), cylindrical and conical). The
    map's two lowest, 1e5 to 1e7 N/m, within 1e-5: the shaft, 1e4 times stiffer than
    steel, bends by 1e-6 under 1e7 N/m, and its stiffness, 1e10 times the springs', costs
    the smallest eigenvalues a few 1e-6 of rounding. Its seal and the springs' own
    stiffness and damping play no part."""
    cfg = parse_rig(tomllib.loads(_on_springs(z1, z2)))
    m, it, _ = inertia(*DISK)
    a, b = L / 2 - z1, z2 - L / 2
    for k in (1e5, 1e6, 1e7):
        want = np.sort(np.roots([m * it, -(m * k * (a**2 + b**2) + it * 2 * k),
                                 k * k * (a + b) ** 2]).real)
        got = undamped_criticals_hz(cfg, k, n=2)
        np.testing.assert_allclose(got, np.sqrt(want) / (2 * math.pi), rtol=1e-5)
    if z2 == L:
        assert got == pytest.approx([math.sqrt(2e7 / m) / (2 * math.pi),
                                     math.sqrt(2e7 * a**2 / it) / (2 * math.pi)], rel=1e-5)
    with pytest.raises(ModelError, match="positive"):
        undamped_criticals_hz(cfg, [1e6, -1.0])


KS, KI, FS = 2.0e5, 100.0, 1.0e4


def _pid_rig():
    """The rigid rotor on AMBs at 0 and L, a PID (with integral) at 10 kHz, one sample of
    delay, a first-order amplifier at 2 kHz; 50–100 Hz, trip 110 Hz."""
    text = rotor_text("rigid rotor on AMBs", *DISK, 4).replace(
        'name = "rigid rotor on AMBs"', 'name = "rigid rotor on AMBs"\nmodal_damping = 0.05')
    for name, z in (("A", 0.0), ("B", L)):
        text += (f'[[amb]]\nname = "{name}"\nposition = {z}\nsensor_position = {z}\n'
                 f"ki = {KI}\nks = {KS}\nbias_current = 5.0\ncurrent_limit = 10.0\n")
    text += (f"[actuator]\nmodel = \"first_order\"\ncutoff_hz = 2000.0\n"
             f"[controller]\nsample_rate_hz = {FS}\ndelay_samples = 1\n"
             "[operating]\nspeed_rpm = 6000.0\nspeed_range_hz = [50.0, 100.0]\n"
             "trip_speed_hz = 110.0\n")
    kp, ti, td, eps = 3000.0, 0.5, 0.01, 0.02
    return parse_rig(tomllib.loads(text)), (kp, ti, td, eps)


def _k_eq_by_hand(w: float, kp, ti, td, eps) -> float:
    """K_i Re(H_a K(s′) e^{−jΩT} (1 − e^{−jΩT})/(jΩT)) − K_s: Tustin's controller at
    z = e^{jΩT} is the continuous one at s′ = (2/T)(z − 1)/(z + 1) = j(2/T) tan(ΩT/2)
    (Franklin, Powell & Workman, *Digital Control of Dynamic Systems*, 3rd ed., §6.3),
    one sample of delay z⁻¹, the hold's fundamental, the amplifier 1/(1 + jΩ/ω_c)."""
    T = 1 / FS
    s = 2j / T * math.tan(w * T / 2)
    K = kp * (1 + 1 / (ti * s) + td * s / (eps * td * s + 1))
    hold = (1 - np.exp(-1j * w * T)) / (1j * w * T)
    amp = 1 / (1 + 1j * w / (2 * math.pi * 2000.0))
    return float((KI * amp * K * np.exp(-1j * w * T) * hold).real - KS)


def test_amb_stiffness_at_1x_and_the_criticals_on_it():
    """The AMBs' k_eq(Ω) of a Tustin PID with its delay, hold and amplifier equals
    :func:`_k_eq_by_hand` to 1e-9 at every speed of the map (up to 1.25 × trip); the
    undamped criticals the map reports on it are the speeds where the rigid rotor's
    closed form on k_eq(Ω) equals Ω — cylindrical √(2k_eq/m) and conical √(2k_eq l²/I_t),
    found here by Brent's method on the hand values — to 1e-5 (the rigid shaft's rounding,
    as in the test above)."""
    cfg, p = _pid_rig()
    K = pid_controller(*p, channel_names(cfg))
    dc = DigitalController(K, K, discrete_controller(K, 1 / FS, "tustin"), "tustin", None,
                           FS, 1)
    u = ucs_map(cfg, [("pid", dc), ("none", None)])
    assert u.speeds_hz[-1] == pytest.approx(1.25 * 110.0) and len(u.curves) == 1
    c = u.curves[0]
    want = np.array([_k_eq_by_hand(2 * math.pi * f, *p) for f in u.speeds_hz])
    assert c.ambs == ("A", "B")
    np.testing.assert_allclose(c.k_eq, [want, want], rtol=1e-9)
    axes, D = amb_dynamic_stiffness(cfg, dc, u.speeds_hz[:3])
    assert axes == ("A_zeta", "A_eta", "B_zeta", "B_eta")
    np.testing.assert_allclose(D.real, np.repeat(want[:3, None], 4, axis=1), rtol=1e-9)
    m, it, _ = inertia(*DISK)

    def meets(factor):
        return lambda f: math.sqrt(max(factor * _k_eq_by_hand(2 * math.pi * f, *p), 0.0)) \
            / (2 * math.pi) - f

    g = [meets(2 / m), meets(2 * (L / 2) ** 2 / it)]
    found = [brentq(h, 1.0, u.speeds_hz[-1], xtol=1e-12) for h in g
             if h(1.0) * h(u.speeds_hz[-1]) < 0]
    assert len(found) == 2
    assert c.criticals_hz == pytest.approx(sorted(found), rel=1e-5)
    # the map itself: ±3 decades around k_eq at the maximum continuous speed
    e = int(math.log10(_k_eq_by_hand(2 * math.pi * 100.0, *p)))
    assert u.stiffness[0] == pytest.approx(10.0 ** (e - 3)) and \
        u.stiffness[-1] == pytest.approx(10.0 ** (e + 3))
    d = u.to_dict()
    assert d["controllers"][0]["critical_speeds_hz"] == list(c.criticals_hz)
    assert len(d["critical_speeds_hz"]) == 4 and len(d["stiffness_n_per_m"]) == 31

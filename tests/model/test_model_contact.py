"""The touchdown bearing's contact law (ambseal.model.contact) against Hertz's impact, the
measured restitution and the published one of each damping law, Palmgren's line contact
in its own units, and the ``[[touchdown]]`` table's refusals."""

from __future__ import annotations

import tomllib

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from ambseal.config import default_rig_path, parse_rig
from ambseal.errors import ConfigError
from ambseal.model.contact import (
    DAMPING_LAWS,
    N_LINE,
    N_POINT,
    ContactLaw,
    damping_coefficient,
    effective_modulus,
    friction_force,
    hertz_impact,
    impact_restitution,
    law_restitution,
    line_stiffness,
    normal_force,
    point_stiffness,
)

MASS, K_HERTZ = 2.0, 1.0e9


def _impact(law: ContactLaw | None, v0: float, mass: float = MASS,
            stiffness: float = K_HERTZ, exponent: float = N_POINT):
    """A mass striking F = K·δ^n·(1 + D·δ̇) at v₀ (D of ``law`` at v₀, no force where
    δ ≤ 0 or the bracket is negative), integrated (DOP853, tight tolerances) until it
    leaves: (rebound speed, largest penetration, contact time)."""
    D = 0.0 if law is None else law.damping(v0)
    if law is not None:
        stiffness, exponent = law.stiffness, law.exponent
    d_est, t_est = hertz_impact(mass, v0, stiffness, exponent)

    def rhs(t, s):
        d, v = s
        f = stiffness * d ** exponent * (1.0 + D * v) if d > 0 else 0.0
        return [v, -max(f, 0.0) / mass]

    def leaves(t, s):
        return s[0] + 1e-3 * d_est  # just past δ = 0 on the way out

    leaves.terminal, leaves.direction = True, -1
    r = solve_ivp(rhs, (0.0, 20 * t_est), [0.0, v0], events=leaves, method="DOP853",
                  rtol=1e-11, atol=1e-9 * d_est, max_step=t_est / 400, dense_output=True)
    t = np.linspace(0.0, r.t[-1], 20001)
    d = r.sol(t)[0]
    inside = t[d > 0]
    return -r.y_events[0][0][1], d.max(), inside[-1] - inside[0]


def test_hertz_impact_is_goldsmiths():
    """Without damping, δ_max = (5 m v₀²/(4K))^{2/5} and t_c = 2.943 δ_max/v₀ (Goldsmith,
    *Impact*, 1960: Hertz's impact solution), from the integrated impact within 1e-3 and
    from :func:`hertz_impact`'s closed form within 1e-4; the mass leaves at v₀."""
    v0 = 0.5
    d_max = (5 * MASS * v0**2 / (4 * K_HERTZ)) ** 0.4
    rebound, d, t_c = _impact(None, v0)
    assert d == pytest.approx(d_max, rel=1e-3)
    assert t_c == pytest.approx(2.943 * d_max / v0, rel=1e-3)
    assert rebound == pytest.approx(v0, rel=1e-6)
    d2, t2 = hertz_impact(MASS, v0, K_HERTZ)
    assert d2 == pytest.approx(d_max, rel=1e-12)
    assert t2 == pytest.approx(2.943 * d_max / v0, rel=1e-4)
    # a line contact (n = 10/9) by the same energy balance, integrated
    _, d_line, t_line = _impact(None, v0, stiffness=1e8, exponent=N_LINE)
    d3, t3 = hertz_impact(MASS, v0, 1e8, N_LINE)
    assert d_line == pytest.approx(d3, rel=1e-3) and t_line == pytest.approx(t3, rel=2e-3)


@pytest.mark.parametrize("law, achieved", [("hunt_crossley", 0.66),
                                           ("lankarani_nikravesh", 0.73),
                                           ("flores", 0.47)])
def test_each_damping_laws_restitution_is_the_published_one(law, achieved):
    """At its own e = 0.5 (``law_restitution``) the three laws' impacts rebound at
    markedly different speeds — about 0.66 (Hunt–Crossley), 0.73 (Lankarani–Nikravesh)
    and 0.47 (Flores) of v₀, as Flores et al. (2011) compare them — within 0.01, at two
    impact speeds alike (each law scales with v₀), and at Carvalho & Martins' (2019)
    exact restitution of their ζ within 1e-4; at e = 0.9 every law is within 1.5 % of
    0.9."""
    for v0 in (0.05, 2.0):
        c = ContactLaw(K_HERTZ, N_POINT, DAMPING_LAWS[law](0.5), 0.0, 1e-3)
        rebound, _, _ = _impact(c, v0)
        assert rebound / v0 == pytest.approx(achieved, abs=0.01)
        assert rebound / v0 == pytest.approx(c.restitution, rel=1e-4)
    near = ContactLaw(K_HERTZ, N_POINT, DAMPING_LAWS[law](0.9), 0.0, 1e-3)
    assert _impact(near, 1.0)[0] == pytest.approx(0.9, rel=0.015)


@pytest.mark.parametrize("e", [0.3, 0.6, 0.9])
def test_the_measured_restitution_is_the_impacts_for_every_law(e):
    """A ``[[touchdown]]`` table's ``restitution`` is the measured e: a mass striking its
    contact (line, and point) rebounds at e·v₀ within 1 %, at two speeds, integrated
    apart (one degree of freedom, DOP853). Each published law given the e that
    :func:`law_restitution` solves for (``damping_law`` with ``law_restitution``) does
    the same; where it finds none, even the law's strongest damping (its e → 0)
    rebounds faster than e (Hunt–Crossley and Lankarani–Nikravesh cannot damp that
    much)."""
    good = ('name = "TA"\nposition = 0.05\nradial_clearance = 2.5e-4\n'
            f"contact_length = 0.015\nrestitution = {e}\nfriction = 0.1\n")
    for text in (good, good.replace("contact_length = 0.015",
                                    'contact = "point"\ncontact_radius = 0.004')):
        law = ContactLaw.of(parse_rig(_rig_with(text)).touchdown[0])
        for v0 in (0.05, 2.0):
            assert _impact(law, v0)[0] / v0 == pytest.approx(e, rel=0.01)
    for name in DAMPING_LAWS:
        own = law_restitution(name, e)
        if own is None:
            strongest = ContactLaw(K_HERTZ, N_POINT, DAMPING_LAWS[name](1e-9), 0.0, 1e-3)
            assert _impact(strongest, 1.0)[0] > 1.01 * e
            continue
        text = good.replace(f"restitution = {e}",
                            f'damping_law = "{name}"\nlaw_restitution = {own!r}')
        law = ContactLaw.of(parse_rig(_rig_with(text)).touchdown[0])
        assert _impact(law, 0.5)[0] / 0.5 == pytest.approx(e, rel=0.01)


def test_point_stiffness_is_hertz_and_line_stiffness_palmgren():
    """Point contact: with E* = E/(2(1 − ν²)), the load that presses a sphere of radius R
    in by δ = a²/R has a contact radius a = (3FR/(4E*))^{1/3} (Johnson 1985, Eqs.
    4.22–4.23): the stiffness reproduces it. Line contact: δ = 3.84e-5·Q^0.9/l^0.8 in mm
    and N (Palmgren), evaluated in those units, at three loads."""
    E, nu, R = 2.075e11, 0.3, 0.01
    E_star = effective_modulus(E, nu)
    assert E_star == pytest.approx(1 / (2 * (1 - nu**2) / E))
    K = point_stiffness(E, nu, R)
    for F in (10.0, 1e3, 1e5):
        a = (3 * F * R / (4 * E_star)) ** (1 / 3)
        assert K * (a * a / R) ** 1.5 == pytest.approx(F, rel=1e-12)
    length = 0.02
    K = line_stiffness(length)
    for Q in (100.0, 5e3, 2e5):
        delta_mm = 3.84e-5 * Q**0.9 / (1e3 * length) ** 0.8
        assert K * (1e-3 * delta_mm) ** N_LINE == pytest.approx(Q, rel=1e-12)


def test_force_and_friction_laws():
    """No force out of contact nor pulling the surfaces together; friction bounded by μN,
    odd in the slip, μN·v/v_r for slips far below v_r and μN beyond."""
    assert normal_force(-1e-6, 1.0, 1e9, 1.5, 0.1) == 0.0
    assert normal_force(1e-6, -100.0, 1e9, 1.5, 0.1) == 0.0  # 1 + D·δ̇ < 0: no pull
    assert float(normal_force(1e-6, 0.0, 1e9, 1.5, 0.1)) == pytest.approx(1e9 * 1e-9)
    v = np.array([-50.0, -1e-6, 1e-6, 50.0])
    f = friction_force(0.2, 100.0, v, 1e-3)
    np.testing.assert_allclose(f, [-20.0, -0.02, 0.02, 20.0], rtol=1e-6)
    with pytest.raises(ValueError, match="restitution"):
        damping_coefficient("flores", 0.0, 1.0)
    with pytest.raises(ValueError, match="damping_law"):
        damping_coefficient("kelvin", 0.5, 1.0)
    assert set(DAMPING_LAWS) == {"hunt_crossley", "lankarani_nikravesh", "flores"}


def _rig_with(touchdown: str) -> dict:
    doc = tomllib.loads(default_rig_path().read_text())
    doc["touchdown"] = [tomllib.loads(touchdown)]
    return doc


def test_the_touchdown_table_is_read_and_refused_by_key():
    """A ``[[touchdown]]`` table gives its law (K from the length: Palmgren); a table
    without the restitution or the friction, off the shaft, a point contact without a
    radius, a line contact of another material without a stiffness, a support mass on a
    rigid support, a turning sleeve, both restitutions, or a damping law beside the
    measured restitution (which it would not read) are refused naming the key."""
    good = ('name = "TA"\nposition = 0.05\nradial_clearance = 2.5e-4\n'
            "contact_length = 0.015\nrestitution = 0.5\nfriction = 0.1\n")
    cfg = parse_rig(_rig_with(good))
    law = ContactLaw.of(cfg.touchdown[0])
    assert law.exponent == N_LINE and law.stiffness == pytest.approx(line_stiffness(0.015))
    for text, key in [
        (good.replace("restitution = 0.5\n", ""), "restitution"),
        (good + "law_restitution = 0.5\n", "restitution.*not both"),
        (good + 'damping_law = "hunt_crossley"\n', "damping_law"),
        (good.replace("friction = 0.1\n", ""), "friction"),
        (good.replace("position = 0.05", "position = 99.0"), "touchdown.0..position|"
         "touchdown\\[0\\].position"),
        (good.replace("contact_length = 0.015\n", 'contact = "point"\n'), "contact_radius"),
        (good + "E = 7.0e10\n", "contact_stiffness"),
        (good + "support_mass = 1.0\n", "support_mass"),
        (good + 'kind = "sleeve"\nrace_inertia = 1.0e-4\n', "race_inertia"),
    ]:
        with pytest.raises(ConfigError, match=key):
            parse_rig(_rig_with(text))
    point = parse_rig(_rig_with(good.replace("contact_length = 0.015\n",
                                             'contact = "point"\ncontact_radius = 0.004\n')))
    assert ContactLaw.of(point.touchdown[0]).stiffness == pytest.approx(
        point_stiffness(2.075e11, 0.3, 0.004))


def test_the_backup_clearance_is_the_nearest_touchdown_bearings_and_given_once():
    """The gap an AMB's backup bearing leaves is the ``radial_clearance`` of the
    ``[[touchdown]]`` bearing nearest the AMB; a rig without them keeps ``[[amb]]
    backup_clearance``; a rig giving both is refused, naming the AMB's key."""
    near = ('name = "TB"\nposition = 0.75\nradial_clearance = 3.0e-4\n'
            "contact_length = 0.015\nrestitution = 0.5\nfriction = 0.1\n")
    doc = _rig_with(near)
    doc["touchdown"].insert(0, tomllib.loads(near.replace('"TB"', '"TA"').replace(
        "0.75", "0.01").replace("3.0e-4", "2.0e-4")))
    cfg = parse_rig(doc)
    # AMB A at 0.17 m lies nearer TA (0.01 m), AMB B at 0.69 m nearer TB (0.75 m)
    assert [cfg.backup_clearance(a) for a in cfg.amb] == [2.0e-4, 3.0e-4]
    doc["amb"][1]["backup_clearance"] = 3.0e-4
    with pytest.raises(ConfigError, match=r"amb\[1\]\.backup_clearance.*\[\[touchdown\]\]"):
        parse_rig(doc)
    del doc["touchdown"]
    bare = parse_rig(doc)
    assert [bare.backup_clearance(a) for a in bare.amb] == [None, 3.0e-4]


def test_the_rated_contact_stress_is_iso76s_at_c0_and_hertzs_power_below():
    """ISO 76:2006 §3.1: C₀ gives 4 200 MPa in a ball bearing, 4 000 MPa in a roller
    bearing. Below it the stress follows the element's load as Hertz's closed forms do
    (Johnson 1985): a ball's p₀ = (6 Q E*²/(π³ R²))^{1/3}, a roller's
    p₀ = (Q E*/(π l R))^{1/2}, here evaluated at two loads for their ratio."""
    from ambseal.model import rated_contact_stress

    c0 = 2.0e4
    assert rated_contact_stress(c0, c0) == pytest.approx(4.2e9)
    assert rated_contact_stress(c0, c0, "roller") == pytest.approx(4.0e9)
    E = effective_modulus(2.075e11, 0.3)

    def ball(q):
        return (6 * q * E ** 2 / (np.pi ** 3 * 0.004 ** 2)) ** (1 / 3)

    def roller(q):
        return (q * E / (np.pi * 0.01 * 0.004)) ** 0.5

    for f in (0.01, 0.3, 0.77):
        assert rated_contact_stress(f * c0, c0) / 4.2e9 == pytest.approx(
            ball(f) / ball(1.0), rel=1e-12)
        assert rated_contact_stress(f * c0, c0, "roller") / 4.0e9 == pytest.approx(
            roller(f) / roller(1.0), rel=1e-12)
    for bad in ({"elements": "needle"}, {"static_rating": 0.0}):
        with pytest.raises(ValueError, match=next(iter(bad))):
            rated_contact_stress(1.0, **{"static_rating": c0, **bad})

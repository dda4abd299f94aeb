"""What an AMB can deliver (model/capacity.py) against the force law it must agree with and
closed forms of the amplifier's limits."""

import math

import numpy as np
import pytest

from ambseal.config import Amb
from ambseal.errors import ConfigError
from ambseal.model.amb import MU0, amb_factors
from ambseal.model.capacity import (amplifier_needs, amplifier_use, coil_inductance,
                                    force_capacity, load_capacity)

GEOMETRY = {"name": "a", "position": 0.1, "sensor_position": 0.1, "turns": 160,
            "pole_area": 6e-4, "air_gap": 4e-4, "bias_current": 2.5, "pole_angle_deg": 22.5}


def test_inductance_gives_the_force_law_by_virtual_work():
    """One magnet's force is ½ i² |dL/ds| cos α (virtual work on the coil's co-energy), L
    the coil's inductance as a function of the gap: the differential pair's dF/di at the
    bias is the force law's Ki, and its dF/dx at the centre its Ks, both to 1e-6
    (amb_factors, Schweitzer & Maslen Eqs. 3.27–3.30)."""
    amb = Amb(**GEOMETRY)
    cos = math.cos(math.radians(amb.pole_angle_deg))

    def dL_ds(s):
        h = 1e-4 * s
        at = [coil_inductance(Amb(**{**GEOMETRY, "air_gap": g})) for g in (s - h, s + h)]
        return (at[1] - at[0]) / (2 * h)

    def magnet(i, s):
        return 0.5 * i ** 2 * abs(dL_ds(s)) * cos

    i0, s0 = amb.bias_current, amb.air_gap
    di, dx = 1e-4 * i0, 1e-4 * s0
    ki = (magnet(i0 + di, s0) - magnet(i0 - di, s0) - magnet(i0 - di, s0)
          + magnet(i0 + di, s0)) / (2 * di)
    ks = (magnet(i0, s0 - dx) - magnet(i0, s0 + dx) - magnet(i0, s0 + dx)
          + magnet(i0, s0 - dx)) / (2 * dx)
    (ki_ref, _), (ks_ref, _) = amb_factors(amb)
    assert ki == pytest.approx(ki_ref, rel=1e-6)
    assert ks == pytest.approx(ks_ref, rel=1e-6)
    assert coil_inductance(Amb(**GEOMETRY, inductance=0.02)) == 0.02


def test_force_capacity_current_and_voltage_limits():
    """Ki·min(i0, i_lim, (V − R i0)/|R + jωL|) per axis, i_lim the amplifier's limit on
    the control current: at standstill the current bound, above the crossover
    ω_c = (V − R i0)/(L i_c) (R = 0) the slew-rate bound Ki V/(L ω), each axis with its
    own Ki; without a supply voltage the current bound at every frequency; a limit above
    the bias leaves the linear range i0 as the bound."""
    amb = Amb(**GEOMETRY, ki={"zeta": 100.0, "eta": 80.0}, current_limit=1.5,
              supply_voltage=150.0)
    L = coil_inductance(amb)
    ic = min(2.5, 1.5)
    wc = 150.0 / (L * ic)
    w = np.array([0.0, 0.5 * wc, wc, 4 * wc])
    f = force_capacity(amb, w)
    assert f.shape == (4, 2)
    np.testing.assert_allclose(f[:3, 0], 100.0 * ic, rtol=1e-12)
    np.testing.assert_allclose(f[3], [100.0 * 150.0 / (L * 4 * wc), 80.0 * 150.0 / (L * 4 * wc)],
                               rtol=1e-12)
    damped = Amb(**{**GEOMETRY, "resistance": 2.0}, current_limit=1.5, supply_voltage=150.0)
    ki = amb_factors(damped)[0][0]
    assert force_capacity(damped, [3 * wc])[0, 0] == pytest.approx(
        ki * (150.0 - 2.0 * 2.5) / math.hypot(2.0, 3 * wc * L), rel=1e-12)
    plain = Amb(**GEOMETRY, current_limit=1.5)
    free = force_capacity(plain, [0.0, 1e6])
    np.testing.assert_allclose(free[:, 0], amb_factors(plain)[0][0] * ic, rtol=1e-12)
    wide = Amb(**GEOMETRY, current_limit=6.0)
    assert force_capacity(wide, [0.0])[0, 0] == pytest.approx(amb_factors(wide)[0][0] * 2.5,
                                                               rel=1e-12)


def test_amplifier_use_is_the_current_and_voltage_against_their_limits():
    """Closed forms: a control current of amplitude i_c at ω uses i_c/i0 of the linear
    range, i_c/i_lim of the current limit and (R i0 + |R + jωL| i_c)/V of the supply; at
    the force capacity's current (:func:`force_capacity` / Ki) the binding limit is used
    exactly (1) and the others less; limits the rig file does not give are None."""
    amb = Amb(**{**GEOMETRY, "resistance": 2.0}, current_limit=1.5, supply_voltage=150.0)
    L, ki = coil_inductance(amb), amb_factors(amb)[0][0]
    w = np.array([0.0, 100.0, 2e3, 2e4])
    ic = force_capacity(amb, w)[:, 0] / ki
    use = amplifier_use(amb, w, ic)
    np.testing.assert_allclose(use["bias_used"], ic / 2.5, rtol=1e-12)
    np.testing.assert_allclose(use["current_used"], ic / 1.5, rtol=1e-12)
    np.testing.assert_allclose(use["voltage_used"],
                               (2.0 * 2.5 + np.hypot(2.0, w * L) * ic) / 150.0, rtol=1e-12)
    binding = np.maximum.reduce([use["bias_used"], use["current_used"], use["voltage_used"]])
    np.testing.assert_allclose(binding, 1.0, rtol=1e-12)
    assert use["current_used"][-1] < 1 and use["voltage_used"][0] < 1
    bare = amplifier_use(Amb(**GEOMETRY), [10.0], [1.0])
    assert bare["current_used"] is None and bare["voltage_used"] is None
    with pytest.raises(ConfigError, match="2 current amplitudes for 1"):
        amplifier_use(amb, [10.0], [1.0, 2.0])
    # what the amplifier must deliver, whatever its limits: i_c and R i0 + |R + jωL| i_c —
    # the supply voltage and current limit used to exactly 1 at the force capacity's
    need = amplifier_needs(amb, w, ic)
    np.testing.assert_allclose(need["current_a"], ic, rtol=1e-12)
    np.testing.assert_allclose(need["voltage_v"], use["voltage_used"] * 150.0, rtol=1e-12)
    bare = Amb(name="a", position=0.1, sensor_position=0.1, ki=100.0, ks=1e5,
               bias_current=2.5)  # no inductance, no geometry to derive it
    assert amplifier_needs(bare, [10.0], [1.0])["voltage_v"] is None


def test_load_capacity_is_the_force_law_at_saturation():
    """B_sat² A cos α / μ0: one magnet at the current that saturates its gaps (B = μ0 N i
    /(2 s0)), its opposite off — the force law f = k i²/s0², k = Ki s0²/(4 i0) of the
    differential pair's Ki (amb_factors) — at the default 1.2 T and at 1.6 T."""
    for b_sat in (None, 1.6):
        amb = Amb(**GEOMETRY, **({} if b_sat is None else {"saturation_flux_density": b_sat}))
        b = 1.2 if b_sat is None else b_sat
        i_sat = 2 * amb.air_gap * b / (MU0 * amb.turns)
        k = amb_factors(amb)[0][0] * amb.air_gap ** 2 / (4 * amb.bias_current)
        assert load_capacity(amb) == pytest.approx(k * i_sat ** 2 / amb.air_gap ** 2,
                                                   rel=1e-12)
    assert load_capacity(Amb(name="a", position=0.1, sensor_position=0.1, ki=50.0,
                             ks=1e5)) is None


@pytest.mark.parametrize(("extra", "match"), [
    ({"turns": None, "pole_area": None, "air_gap": None, "bias_current": None, "ki": 50.0,
      "ks": 1e5}, "needs bias_current"),
    ({"supply_voltage": 4.0, "resistance": 2.0}, "does not drive the bias current"),
    ({"turns": None, "pole_area": None, "air_gap": None, "ki": 50.0, "ks": 1e5,
      "supply_voltage": 100.0}, "needs the coil's inductance"),
])
def test_force_capacity_refuses_what_it_cannot_bound(extra, match):
    """Each missing or impossible limit is named: by the rig file's check when the AMB is
    read, and by the capacity on an AMB copied without that check."""
    if "supply_voltage" in extra:
        with pytest.raises(ValueError, match=match):
            Amb(**{**GEOMETRY, **extra})
    amb = Amb(**GEOMETRY).model_copy(update=extra)
    with pytest.raises(ConfigError, match=match):
        force_capacity(amb, [0.0, 100.0])
    with pytest.raises(ConfigError, match="frequencies ≥ 0"):
        force_capacity(Amb(**GEOMETRY), [-1.0])


def _amplifier_run(amb, omega, amplitude, periods=3, steps=4000):
    """A time simulation of the differential pair's two coils, each L di/dt + R i = u fed
    by a switching amplifier whose output u is held over each of ``steps`` samples of a
    period and clipped to ±supply_voltage; its current loop is deadbeat (the voltage that
    brings the coil exactly to the reference at the next sample, integrated exactly), the
    references i0 ± A sin ωt. Returns the largest tracking error of the control current
    over the last period (A), per amplitude, and the force amplitude of the force law
    f = k[(i0 + i)² − (i0 − i)²]/s0² at the centre (N)."""
    L, R, V, i0 = coil_inductance(amb), amb.resistance, amb.supply_voltage, amb.bias_current
    ts = 2 * np.pi / omega / steps
    a = math.exp(-R * ts / L)
    A = np.asarray(amplitude, float)[:, None] * np.array([1.0, -1.0])  # upper, lower coil
    i = np.full(A.shape, i0)
    err = np.zeros(A.shape[0])
    force = np.zeros(A.shape[0])
    k = amb_factors(amb)[0][0] * amb.air_gap ** 2 / (4 * i0)
    for n in range(periods * steps):
        ref = i0 + A * math.sin(omega * (n + 1) * ts)
        u = np.clip(R * (ref - a * i) / (1 - a), -V, V)
        i = a * i + (1 - a) * u / R
        if n >= (periods - 1) * steps:
            err = np.maximum(err, np.abs(i - ref).max(axis=1))
            f = k * (i[:, 0] ** 2 - i[:, 1] ** 2) / amb.air_gap ** 2
            force = np.maximum(force, np.abs(f))
    return err, force


def test_saturated_amplifier_reaches_the_force_capacity():
    """A time simulation of the voltage-limited amplifier and coil (``_amplifier_run``,
    written here from the circuit alone) holds a sinusoidal control current to 1 % below
    the amplitude :func:`force_capacity` predicts from (V − R i0)/|R + jωL| and not 1 %
    above it, at frequencies where the voltage binds — the force it reaches there is the
    predicted force capacity to 1 %."""
    amb = Amb(**{**GEOMETRY, "resistance": 1.5}, supply_voltage=120.0)
    L, ki = coil_inductance(amb), amb_factors(amb)[0][0]
    for w in (2e3, 8e3):  # both above the corner where the voltage, not i0, binds
        predicted = force_capacity(amb, [w])[0, 0] / ki
        assert predicted < amb.bias_current
        err, force = _amplifier_run(amb, w, predicted * np.array([0.99, 1.01]))
        assert err[0] < 1e-9 * predicted  # tracked to the sample: never clipped
        assert err[1] > 1e-3 * predicted  # clipped: the coil falls behind its reference
        assert force[0] == pytest.approx(ki * 0.99 * predicted, rel=1e-3)
        assert force[0] / (0.99 * ki * (120.0 - 1.5 * 2.5) / math.hypot(1.5, w * L)) \
            == pytest.approx(1.0, rel=1e-2)

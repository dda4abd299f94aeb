"""Tests of ambseal.machine.loop: the judged loop's plant response, taken from the modal
form of the continuous plant it was made from, against dense solves of the plant as closed
(delayed by the lag, or sampled by the zero-order hold)."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from ambseal.analysis.judge import judge_settings
from ambseal.design.specs import design_spec
from ambseal.machine.loop import judged_loop
from ambseal.model.rig import build_plant
from ambseal.robust.delay import loop_delay


def _dense(P, points):
    """C (pI − A)⁻¹ B + D by one LU solve per point: the reference."""
    A, B, C, D = (np.asarray(X, float) for X in (P.A, P.B, P.C, P.D))
    eye = np.eye(A.shape[0])
    return np.stack([C @ np.linalg.solve(p * eye - A, B) + D for p in points])


def _relative_error(H, ref):
    scale = np.max(np.abs(ref), axis=(1, 2))
    return float(np.max(np.max(np.abs(H - ref), axis=(1, 2)) / scale))


def test_judged_plant_response_equals_dense_solves_of_the_delayed_and_sampled_plant(
        testrig_cfg, testrig_designs, testrig_digital):
    """Reference: dense LU solves of the judged plant's own state space — the lag in series
    before the current inputs (:func:`ambseal.lti.interconnect.series_inputs`), or ``expm``'s
    zero-order hold — at frequencies up to Nyquist, force inputs included; the response
    from the continuous plant's modal form must agree to 1e-8 of the largest entry."""
    cfg = testrig_cfg
    settings = judge_settings(design_spec(cfg))
    plant = build_plant(cfg, pressure_bar=cfg.operating.pressure_bar,
                        speed_rpm=cfg.operating.speed_rpm,
                        force_positions=tuple(settings.force_positions_m))
    P, cur = plant.to_statespace(), plant.current_inputs()
    assert 0 < len(cur) < P.ninputs  # force inputs too
    fs = cfg.controller.sample_rate_hz
    w = 2 * np.pi * np.geomspace(1.0, 0.999 * fs / 2, 23)
    delay = loop_delay(fs, cfg.controller.delay_samples).system
    cont = judged_loop(P, testrig_designs["hinf"].K, cur, delay=delay)
    disc = judged_loop(P, testrig_digital["hinf"].statespace(delayed=True), cur)
    dt = disc.plant.dt
    H_cont, H_disc = cont.plant_response(w), disc.plant_response(w)
    assert _relative_error(H_cont, _dense(cont.plant, 1j * w)) < 1e-8
    assert _relative_error(H_disc, _dense(disc.plant, np.exp(1j * w * dt))) < 1e-8
    # the lag acts on the current inputs only, and changes them: a response without it
    # (or with it on the forces) is far from the reference
    undelayed = _dense(P, 1j * w)
    force = [j for j in range(P.ninputs) if j not in cur]
    assert _relative_error(H_cont[:, :, force], undelayed[:, :, force]) < 1e-8
    assert _relative_error(H_cont[:, :, cur], undelayed[:, :, cur]) > 0.1


def _numbers(d, path=""):
    """Every number and verdict of a case's dict, by key path."""
    if isinstance(d, dict):
        out = {}
        for k, v in d.items():
            out.update(_numbers(v, f"{path}.{k}"))
        return out
    if isinstance(d, (list, tuple)):
        out = {}
        for i, v in enumerate(d):
            out.update(_numbers(v, f"{path}[{i}]"))
        return out
    return {path: d}


@pytest.mark.heavy
def test_the_judged_case_equals_the_one_from_dense_solves(testrig_cfg, testrig_designs,
                                                          testrig_digital, monkeypatch):
    """Reference: the same judgement with every plant response taken by dense LU solves of
    the delayed or sampled plant itself (no modal form, no lag product, no probe): each
    verdict the same, each number within 1e-6 relative (μ at twice the nominal pressure
    drop, continuous and as it runs; the impulse response, which takes no plant response,
    left out)."""
    from ambseal.analysis.judge import OperatingPoint, judge
    from ambseal.machine.loop import JudgedLoop, sample_time

    cfg = testrig_cfg
    settings = judge_settings(design_spec(cfg))
    lo, hi, _ = settings.freq_hz  # a coarser grid: dense solves cost O(n³) a point
    settings = replace(settings, freq_hz=(lo, hi, 150))
    p0, rpm = cfg.operating.pressure_bar, cfg.operating.speed_rpm

    def cases():
        out = []
        for m, p in (("mu", 2 * p0),):
            pt = OperatingPoint(p, rpm, f"{p:g} bar", "low")
            case, _ = judge(cfg, testrig_designs[m].K, m, pt, settings, impulse=False,
                            discrete=testrig_digital[m].statespace(delayed=True))
            out.append(case.to_dict())
        return out

    fast = cases()

    def dense(self, w):
        dt = sample_time(self.plant)
        return _dense(self.plant, np.exp(1j * w * dt) if dt else 1j * w)

    monkeypatch.setattr(JudgedLoop, "plant_response", dense)
    slow = cases()
    compared = 0
    for a, b in zip(fast, slow):
        na, nb = _numbers(a), _numbers(b)
        assert na.keys() == nb.keys()
        for k, x in na.items():
            if isinstance(x, float) and isinstance(nb[k], float):
                assert x == pytest.approx(nb[k], rel=1e-6, abs=1e-300), k
                compared += 1
            else:
                assert x == nb[k], k
    assert compared > 10 and fast[0]["stable"] and fast[0]["discrete"]["stable"]

"""A judged case on a fine mesh from the plant's modal form — the loops' poles, the sampled
plant's response and the impulse responses, with no dense eigenvalue problem of a loop and
no ``expm`` of the plant or of a loop — against the same case with those structured paths
switched off (``STRUCTURED_STATES`` raised above the plant's order: dense eigenvalues, the
plant sampled by ``expm``, the loops stepped through their dense ZOH): the same verdicts,
zones and per-axis zones, every number within 1e-6 relative. The default mesh's H∞
controller and its digital form, judged at the rig's operating point on the embedded rig
refined to 100 beam elements (848 states), and to 230 (1 888 states) behind ``-m slow``."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

import ambseal.lti.freqresp as fr
import ambseal.lti.interconnect as ic
import ambseal.machine.loop as ml
from ambseal.analysis.judge import OperatingPoint, judge, judge_settings
from ambseal.config import load_rig
from ambseal.design.specs import design_spec

from ..finemesh import fine_rig_text


def _case(cfg, design, digital) -> dict:
    point = OperatingPoint(cfg.operating.pressure_bar, cfg.operating.speed_rpm, "operating",
                           "nominal")
    case, _ = judge(cfg, design.K, "hinf", point, judge_settings(design_spec(cfg)),
                    discrete=digital.statespace(delayed=True))
    return case.to_dict()


def _compare(fast, dense, path="") -> int:
    """Assert ``fast`` equals ``dense`` (numbers to 1e-6 relative); the numbers compared."""
    if isinstance(dense, dict):
        assert fast.keys() == dense.keys(), path
        return sum(_compare(fast[k], dense[k], f"{path}/{k}") for k in dense)
    if isinstance(dense, list):
        assert len(fast) == len(dense), path
        return sum(_compare(a, b, f"{path}[{i}]") for i, (a, b) in enumerate(zip(fast, dense)))
    if isinstance(dense, float) and not isinstance(dense, bool):
        assert math.isclose(fast, dense, rel_tol=1e-6, abs_tol=1e-300), (path, fast, dense)
        return 1
    assert fast == dense, (path, fast, dense)
    return 0


def _judged_both_ways(elements, tmp_path, testrig_designs, testrig_digital, monkeypatch):
    rig = tmp_path / f"fine{elements}.toml"
    rig.write_text(fine_rig_text(elements), encoding="utf-8")
    cfg = load_rig(rig)
    args = (cfg, testrig_designs["hinf"], testrig_digital["hinf"])
    fast = _case(*args)
    with monkeypatch.context() as m:
        for module in (fr, ic, ml):
            m.setattr(module, "STRUCTURED_STATES", 10**9)
        dense = _case(*args)
    assert fast["stable"] and fast["discrete"]["stable"]
    assert fast["impulse_peak_um"] is not None and fast["discrete"]["impulse_peak_um"] is not None
    assert _compare(fast, dense) >= 20


def test_judged_case_at_100_elements_equals_the_dense_path(tmp_path, testrig_designs,
                                                            testrig_digital, monkeypatch):
    _judged_both_ways(100, tmp_path, testrig_designs, testrig_digital, monkeypatch)


@pytest.mark.slow
def test_judged_case_at_230_elements_equals_the_dense_path(tmp_path, testrig_designs,
                                                            testrig_digital, monkeypatch):
    _judged_both_ways(230, tmp_path, testrig_designs, testrig_digital, monkeypatch)


@pytest.mark.parametrize("rig", ["pump", "b2b_compressor"])
def test_an_example_rigs_judged_case_from_its_modal_form_equals_the_dense_path(rig,
                                                                              monkeypatch):
    """Two example rigs (356 and 468 states, below the size where the structured paths
    start) judged with their derived PID from the plant's modal form — every loop's poles
    certified from the modal split (:func:`ambseal.lti.modal_loop.modal_loop_poles`, its
    strong part allowed up to the whole loop), the sampled plant from its modal form —
    against the dense path: the same verdicts and zones, σ̄(S_o) and every other number
    within 1e-6 relative."""
    import ambseal.lti.modal_loop as mloop
    from ambseal.design.recipes import design

    from ..conftest import _digital

    cfg = load_rig(Path(__file__).resolve().parents[2] / "examples" / f"{rig}.toml")
    pid = design(cfg, "pid")
    digital = _digital(cfg, {"pid": pid})["pid"]
    point = OperatingPoint(cfg.operating.pressure_bar, cfg.operating.speed_rpm, "operating",
                           "nominal")

    def judged() -> dict:
        case, _ = judge(cfg, pid.K, "pid", point, judge_settings(design_spec(cfg)),
                        discrete=digital.statespace(delayed=True))
        return case.to_dict()

    certified, modal_poles = [], ic._modal_poles

    def spy(*args):
        poles = modal_poles(*args)
        certified.append(poles is not None)
        return poles

    with monkeypatch.context() as m:
        for module in (fr, ic, ml):
            m.setattr(module, "STRUCTURED_STATES", 100)
        m.setattr(mloop, "_MAX_STRONG_FRACTION", 1.0)
        m.setattr(ic, "_modal_poles", spy)
        fast = judged()
    with monkeypatch.context() as m:
        for module in (fr, ic, ml):
            m.setattr(module, "STRUCTURED_STATES", 10**9)
        dense = judged()
    assert certified and all(certified)
    assert fast["stable"] and fast["discrete"]["stable"]
    assert fast["sensitivity_peak"] is not None
    assert _compare(fast, dense) >= 20

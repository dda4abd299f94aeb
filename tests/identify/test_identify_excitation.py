"""The identification excitations follow from the rig (ambseal.identify.excitation.plan)."""

import tomllib

import numpy as np
import pytest
from scipy.signal import welch

from ambseal.config import load_rig, parse_rig
from ambseal.design.specs import design_spec
from ambseal.errors import ConfigError
from ambseal.identify.excitation.plan import excitation_plan, welch_segment
from ambseal.identify.excitation.signals import impulse, prbs
from ambseal.model.amb import channel_names

from ..conftest import ROOT


def _runs(x: np.ndarray) -> np.ndarray:
    """Lengths (samples) of the runs of equal values of ``x``."""
    edges = np.flatnonzero(np.diff(x)) + 1
    return np.diff(np.concatenate(([0], edges, [x.size])))


def test_the_thesis_rig_gets_the_thesis_excitations(testrig_cfg):
    """Reference: the published settings on the test rig (6 A bias, 10 kHz): 0.05 A for
    10 ms from 0.05 s (P5 §3.3), a 0–150 Hz chirp (P4 §3.4, Figs. 9–10), and the run's
    1 ms, 1 s PRBS, 4 s chirp and 2–140 Hz / 2–200 Hz checks (exactly, so that
    ``ambseal run`` on the embedded rig identifies bit for bit with and without the rules' defaults spelt out)."""
    p = excitation_plan(testrig_cfg)
    assert (p.amplitude_a, p.impulse_s, p.impulse_start_s) == (0.05, 0.01, 0.05)
    assert (p.impulse_record_s, p.check_record_s) == (0.4, 0.25)
    assert (p.prbs_clock_s, p.prbs_duration_s) == (1e-3, 1.0)
    assert (p.chirp_hz, p.chirp_s) == ((1.0, 150.0), 4.0)
    assert (p.closed_loop_band_hz, p.plant_band_hz) == ((2.0, 140.0), (2.0, 200.0))
    spec = design_spec(testrig_cfg)  # the design judgement's impulse: the same rule
    assert (spec.impulse_a, spec.impulse_s) == (p.amplitude_a, p.impulse_s)


def test_the_excitations_scale_with_the_bias_and_the_sample_rate():
    """The blower (2 A bias, 20 kHz) and the test rig with a 50 A bias at 2 kHz: the signals
    built from the plan, read back sample by sample — PRBS levels ±i0/120 held for runs of
    whole 10-sample clocks, an impulse of i0/120 over 100 samples — so 0.05 A is neither
    noise on the large bias nor a saturating step on the small one, and the clock is no
    2-sample flicker at 2 kHz."""
    blower = load_rig(ROOT / "examples" / "blower.toml")
    data = tomllib.loads((ROOT / "src" / "ambseal" / "data" / "testrig.toml").read_text())
    for amb in data["amb"]:
        amb["bias_current"], amb["current_limit"] = 50.0, 100.0
    data.setdefault("controller", {})["sample_rate_hz"] = 2000.0
    big = parse_rig(data)
    for cfg, i0, fs in ((blower, 2.0, 20000.0), (big, 50.0, 2000.0)):
        p = excitation_plan(cfg)
        axes = channel_names(cfg)
        ex = prbs(amplitude_a=p.amplitude_a, clock_period_s=p.prbs_clock_s,
                  duration_s=p.prbs_duration_s, sample_rate_hz=fs, axes=axes, seed=3)
        col = ex.values_a[:, 0]
        assert set(np.round(np.abs(col) * 120 / i0, 12)) == {1.0}
        assert ex.n_samples == 10_000 and set(_runs(col) % 10) == {0}
        im = impulse(amplitude_a=p.amplitude_a, width_s=p.impulse_s,
                     start_s=p.impulse_start_s, duration_s=p.impulse_record_s,
                     sample_rate_hz=fs, axes=axes)
        on = np.flatnonzero(im.values_a[:, 0])
        assert on.size == 100 and on[0] == 500 and im.n_samples == 4000
        assert im.values_a[on[0], 0] == pytest.approx(i0 / 120, rel=1e-12)
        assert p.chirp_hz[1] == pytest.approx(0.75 * fs / 50, rel=1e-12)


def test_the_impulse_key_sets_the_identification_amplitude_and_length(testrig_cfg):
    """``[design.impulse]`` sets the identification's amplitude and impulse as well as the
    judgement's (one key, one rule); the impulse's record follows its length."""
    cfg = load_rig(overrides=["design.impulse.amplitude_a=0.2",
                              "design.impulse.duration_s=0.004"])
    p = excitation_plan(cfg)
    assert (p.amplitude_a, p.impulse_s) == (0.2, 0.004)
    assert p.impulse_record_s == pytest.approx(40 * 0.004)
    assert design_spec(cfg).impulse_a == 0.2


def test_a_rig_without_bias_or_limit_is_told_to_set_the_amplitude():
    data = tomllib.loads((ROOT / "src" / "ambseal" / "data" / "testrig.toml").read_text())
    for amb in data["amb"]:
        amb.pop("bias_current"), amb.pop("current_limit")
    with pytest.raises(ConfigError, match=r"design\.impulse\.amplitude_a"):
        excitation_plan(parse_rig(data))


def test_the_prbs_is_flat_to_its_stated_band():
    """Reference: a PRBS of clock T_c has the spectrum sinc²(f T_c) (held white noise), so
    f_P = 0.2/T_c is 0.58 dB below its low-frequency level; measured by Welch on a long
    record with the plan's segment rule (≥ 7 averages)."""
    fs, clock = 10_000.0, 1e-3
    ex = prbs(amplitude_a=1.0, clock_period_s=clock, duration_s=200.0, sample_rate_hz=fs,
              axes=("x",), seed=1)
    n = welch_segment(ex.n_samples // 100)
    f, P = welch(ex.values_a[:, 0], fs=fs, nperseg=n)
    low = P[(f > 5) & (f < 40)].mean()
    at = np.interp(0.2 / clock, f, P)
    assert at / low == pytest.approx(np.sinc(0.2) ** 2, abs=0.03)
    assert 10 * np.log10(np.sinc(0.2) ** 2) == pytest.approx(-0.58, abs=0.01)


@pytest.mark.parametrize("n, seg", [(10_000, 2048), (40_000, 8192), (8192, 2048), (64, 16)])
def test_welch_segments_average_at_least_seven_times(n, seg):
    assert welch_segment(n) == seg
    assert (n - seg) // (seg // 2) + 1 >= 7

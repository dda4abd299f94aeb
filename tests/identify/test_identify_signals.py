"""Tests of ambseal.identify.excitation.signals: PRBS, stepped sine, chirp and impulse excitations."""

from __future__ import annotations

import json
import subprocess
import sys

import numpy as np
import pytest

from ambseal.identify.excitation.signals import DEFAULT_AXES, Excitation, chirp, impulse, prbs, stepped_sine

FS = 10_000.0


def _xcorr(a: np.ndarray, b: np.ndarray, max_lag: int) -> np.ndarray:
    """Normalised cross-correlation of two ±1 sequences at lags -max_lag..max_lag."""
    a, b = np.ascontiguousarray(a, dtype=float), np.ascontiguousarray(b, dtype=float)
    n = a.size
    # elementwise products, not np.dot: BLAS threading is slow on a loaded 2-core machine
    return np.array([np.sum(a[max(0, -k) : n - max(0, k)] * b[max(0, k) : n - max(0, -k)]) / n
                     for k in range(-max_lag, max_lag + 1)])


# --------------------------------------------------------------------------- PRBS
def test_prbs_levels_and_unexcited_axes_zero():
    """Reference: P2 §4.2 / P4 §3.4 — a binary current perturbation of ±amplitude on the
    excited axes (here the two ζ axes), nothing on the others."""
    ex = prbs(amplitude_a=0.1, clock_period_s=1e-3, duration_s=0.5, sample_rate_hz=FS,
              excited=("A_zeta", "B_zeta"), seed=3)
    assert isinstance(ex, Excitation) and ex.kind == "prbs"
    assert ex.axes == DEFAULT_AXES and ex.values_a.shape == (5000, 4)
    np.testing.assert_allclose(ex.time_s, np.arange(5000) / FS)
    for a in ("A_zeta", "B_zeta"):
        assert set(np.round(ex.column(a), 15)) == {-0.1, 0.1}
    for a in ("A_eta", "B_eta"):
        assert np.all(ex.column(a) == 0)
    assert not ex.values_a.flags.writeable
    json.dumps(ex.params)  # JSON-safe metadata
    assert ex.params["excited"] == {"A_zeta": 1.0, "B_zeta": 1.0}
    assert json.loads(json.dumps(ex.to_dict()))["kind"] == "prbs"


@pytest.mark.parametrize("method", ["random", "mls"])
def test_prbs_clock_levels_change_only_on_clock_edges(method):
    """Reference: PRBS definition — the level is held for one clock period, so changes happen
    only at sample indices that are multiples of clock·fs (here 7 samples)."""
    clk = 7 / FS
    ex = prbs(amplitude_a=1.0, clock_period_s=clk, duration_s=0.3, sample_rate_hz=FS, seed=5, method=method)
    for j in range(4):
        x = ex.values_a[:, j]
        change = np.flatnonzero(np.diff(x) != 0) + 1
        assert change.size > 50
        assert np.all(change % 7 == 0)


def test_prbs_zero_mean_and_independent_axes():
    """Reference: independent fair ±1 draws — sample mean and cross-correlation of N clock
    values are ~N(0, 1/N) (central limit theorem), so |·| < 4.5/√N at every lag tested,
    while the autocorrelation at lag 0 is exactly 1."""
    n_clk = 20_000
    ex = prbs(amplitude_a=1.0, clock_period_s=1 / FS, duration_s=n_clk / FS, sample_rate_hz=FS, seed=11)
    V = np.ascontiguousarray(ex.values_a.T)  # rows = axes
    bound = 4.5 / np.sqrt(n_clk)
    assert np.all(np.abs(V.mean(axis=1)) < bound)
    for i in range(4):
        assert np.dot(V[i], V[i]) / n_clk == pytest.approx(1.0)
        for j in range(i + 1, 4):
            assert np.max(np.abs(_xcorr(V[i], V[j], 40))) < bound


def test_prbs_reproducible_by_seed():
    """Reference: numpy SeedSequence.spawn contract — same seed, same sequences; another
    seed, other sequences; axis j's sequence does not depend on which other axes are excited."""
    kw = dict(amplitude_a=0.2, clock_period_s=5e-4, duration_s=0.2, sample_rate_hz=FS)
    a = prbs(seed=42, **kw)
    b = prbs(seed=42, **kw)
    c = prbs(seed=43, **kw)
    np.testing.assert_array_equal(a.values_a, b.values_a)
    assert np.mean(a.values_a == c.values_a) < 0.8
    only_b = prbs(seed=42, excited=["B_zeta"], **kw)
    np.testing.assert_array_equal(only_b.column("B_zeta"), a.column("B_zeta"))
    gains = prbs(seed=42, excited={"A_zeta": 1.0, "B_zeta": -0.5}, **kw)
    np.testing.assert_allclose(gains.column("B_zeta"), -0.5 * a.column("B_zeta"))


def test_prbs_mls_properties():
    """Reference: Golomb's m-sequence properties — period 2^m − 1, balance (one more +1 than
    −1 per period), two-valued circular autocorrelation (1 at lag 0, −1/N elsewhere); the
    axes are distinct shifts, so their zero-lag correlation is −1/N."""
    n_clk = 1023  # exactly one period of a 10-bit register
    ex = prbs(amplitude_a=1.0, clock_period_s=1 / FS, duration_s=n_clk / FS, sample_rate_hz=FS,
              method="mls", seed=0)
    assert ex.params["lfsr_bits"] == 10 and ex.params["lfsr_period"] == 1023
    V = ex.values_a
    assert np.all(V.sum(axis=0) == 1.0)
    x = V[:, 0]
    circ = np.array([np.dot(x, np.roll(x, k)) for k in range(n_clk)]) / n_clk
    assert circ[0] == pytest.approx(1.0)
    np.testing.assert_allclose(circ[1:], -1.0 / n_clk, atol=1e-12)
    for j in range(1, 4):
        assert np.dot(V[:, 0], V[:, j]) / n_clk == pytest.approx(-1.0 / n_clk)


# --------------------------------------------------------------------------- stepped sine
def test_stepped_sine_windows_hold_whole_cycles():
    """Reference: P4 §3.5.1 stepped sine 5–200 Hz in 10 Hz steps (5, 15, …, 195 Hz); each
    analysis window holds `cycles` periods (to within half a sample), so the sine fitted over
    it by least squares returns the amplitude and zero phase; windows follow the settling
    cycles and tile the record with the steps."""
    freqs = np.arange(5.0, 200.0, 10.0)
    amp, cycles, settle = 0.05, 10, 3
    ex = stepped_sine(frequencies_hz=freqs, amplitude_a=amp, cycles=cycles, settling_cycles=settle,
                      sample_rate_hz=FS, excited={"A_zeta": 1.0, "B_zeta": 1.0})
    assert ex.kind == "stepped_sine" and len(ex.windows) == freqs.size
    step_start = 0
    for (f, start, stop), fw in zip(ex.windows, freqs):
        assert f == fw
        assert (stop - start) * f / FS == pytest.approx(cycles, abs=0.5 * f / FS)
        assert (start - step_start) * f / FS == pytest.approx(settle, abs=0.5 * f / FS)
        t = np.arange(start, stop) / FS - ex.time_s[step_start]
        x = ex.column("A_zeta")[start:stop]
        M = np.column_stack([np.sin(2 * np.pi * f * t), np.cos(2 * np.pi * f * t)])
        s, c = np.linalg.lstsq(M, x, rcond=None)[0]
        assert s == pytest.approx(amp, rel=1e-9) and abs(c) < 1e-9
        assert abs(x.mean()) < 0.01 * amp  # whole cycles average to ~0
        step_start = stop
    assert step_start == ex.n_samples
    np.testing.assert_array_equal(ex.column("A_zeta"), ex.column("B_zeta"))
    assert np.all(ex.column("A_eta") == 0)
    assert ex.params["windows"][0] == list(ex.windows[0])
    json.dumps(ex.params)


# --------------------------------------------------------------------------- chirp
@pytest.mark.parametrize("method", ["linear", "logarithmic"])
def test_chirp_instantaneous_frequency(method):
    """Reference: scipy.signal.chirp closed forms — f(t) = f0 + (f1−f0)t/T (linear),
    f0 (f1/f0)^(t/T) (logarithmic); the samples equal A·sin(2π∫f dt) of the closed form, and
    the local frequency 1/(2·half-period) from successive zero crossings matches f(t) within
    1 %. P4 Figs. 9–10 use a linear chirp."""
    f0, f1, T = 2.0, 150.0, 4.0
    ex = chirp(f0_hz=f0, f1_hz=f1, duration_s=T, amplitude_a=0.1, sample_rate_hz=FS, method=method,
               excited=["A_eta"])
    x = ex.column("A_eta")
    t = ex.time_s
    # closed-form phase: x = A sin(2π ∫ f dt)
    if method == "linear":
        phase = 2 * np.pi * (f0 * t + (f1 - f0) * t**2 / (2 * T))
        f_of = lambda tt: f0 + (f1 - f0) * tt / T  # noqa: E731
    else:
        k = (f1 / f0) ** (1 / T)
        phase = 2 * np.pi * f0 * (k**t - 1) / np.log(k)
        f_of = lambda tt: f0 * (f1 / f0) ** (tt / T)  # noqa: E731
    np.testing.assert_allclose(x, 0.1 * np.sin(phase), atol=1e-9)
    # independent check: local frequency from successive zero crossings (half periods)
    i = np.flatnonzero(np.sign(x[:-1]) * np.sign(x[1:]) < 0)
    tz = t[i] - x[i] * (t[i + 1] - t[i]) / (x[i + 1] - x[i])
    f_est = 1.0 / (2.0 * np.diff(tz))
    t_mid = 0.5 * (tz[1:] + tz[:-1])
    np.testing.assert_allclose(f_est, f_of(t_mid), rtol=0.01)
    assert ex.params["method"] == method


# --------------------------------------------------------------------------- impulse
def test_impulse_area_and_timing_p5():
    """Reference: P5 §3.3 — 0.05 A for 10 ms from 0.05 s to 0.06 s on both bearings in ζ;
    area Σ i Δt = amplitude · duration = 5e-4 A·s."""
    ex = impulse(amplitude_a=0.05, width_s=0.01, start_s=0.05, duration_s=0.3, sample_rate_hz=FS,
                 excited=("A_zeta", "B_zeta"))
    for a in ("A_zeta", "B_zeta"):
        x = ex.column(a)
        assert x.sum() / FS == pytest.approx(0.05 * 0.01, rel=1e-12)
        on = np.flatnonzero(x)
        assert ex.time_s[on[0]] == pytest.approx(0.05) and ex.time_s[on[-1]] == pytest.approx(0.06 - 1 / FS)
        assert np.all(x[on] == 0.05)
    assert np.all(ex.column("A_eta") == 0) and np.all(ex.column("B_eta") == 0)


# --------------------------------------------------------------------------- validation
@pytest.mark.parametrize(
    "func, kwargs, name",
    [
        (prbs, dict(amplitude_a=0, clock_period_s=1e-3, duration_s=1, sample_rate_hz=FS), "amplitude_a"),
        (prbs, dict(amplitude_a=0.1, clock_period_s=1e-5, duration_s=1, sample_rate_hz=FS), "clock_period_s"),
        (prbs, dict(amplitude_a=0.1, clock_period_s=1e-3, duration_s=-1, sample_rate_hz=FS), "duration_s"),
        (prbs, dict(amplitude_a=0.1, clock_period_s=1e-3, duration_s=1, sample_rate_hz=FS, method="x"), "method"),
        (prbs, dict(amplitude_a=0.1, clock_period_s=1e-3, duration_s=1, sample_rate_hz=FS, seed=-1), "seed"),
        (prbs, dict(amplitude_a=0.1, clock_period_s=1e-3, duration_s=1, sample_rate_hz=FS, excited=["C_x"]), "excited"),
        (prbs, dict(amplitude_a=0.1, clock_period_s=1e-3, duration_s=1, sample_rate_hz=FS, axes=["a", "a"]), "axes"),
        (prbs, dict(amplitude_a=0.1, clock_period_s=1e-3, duration_s=1, sample_rate_hz=float("nan")), "sample_rate_hz"),
        (stepped_sine, dict(frequencies_hz=[], amplitude_a=1, cycles=2, settling_cycles=1, sample_rate_hz=FS), "frequencies_hz"),
        (stepped_sine, dict(frequencies_hz=[4000.0], amplitude_a=1, cycles=2, settling_cycles=1, sample_rate_hz=FS), "frequencies_hz"),
        (stepped_sine, dict(frequencies_hz=[5.0], amplitude_a=1, cycles=0, settling_cycles=1, sample_rate_hz=FS), "cycles"),
        (stepped_sine, dict(frequencies_hz=[5.0], amplitude_a=1, cycles=2, settling_cycles=1.5, sample_rate_hz=FS), "settling_cycles"),
        (chirp, dict(f0_hz=0, f1_hz=100, duration_s=1, amplitude_a=1, sample_rate_hz=FS, method="logarithmic"), "f0_hz"),
        (chirp, dict(f0_hz=1, f1_hz=6000, duration_s=1, amplitude_a=1, sample_rate_hz=FS), "f1_hz"),
        (chirp, dict(f0_hz=1, f1_hz=100, duration_s=1, amplitude_a=1, sample_rate_hz=FS, method="quad"), "method"),
        (impulse, dict(amplitude_a=0.05, width_s=1.5e-4, start_s=0.05, duration_s=0.3, sample_rate_hz=FS), "width_s"),
        (impulse, dict(amplitude_a=0.05, width_s=0.01, start_s=0.295, duration_s=0.3, sample_rate_hz=FS), "start_s"),
        (impulse, dict(amplitude_a=0.0, width_s=0.01, start_s=0.05, duration_s=0.3, sample_rate_hz=FS), "amplitude_a"),
    ],
)
def test_invalid_arguments_raise_valueerror_naming_argument(func, kwargs, name):
    """Reference: interface contract — ValueError whose message starts with the argument name."""
    with pytest.raises(ValueError, match=rf"^{name}"):
        func(**kwargs)


def test_excitation_module_is_light():
    """Reference: DESIGN.md 'light imports' (no plotting at import) — importing the module
    in a fresh interpreter loads neither matplotlib nor the numerics stack it does not need
    (python-control, scipy, cvxopt); checked on sys.modules of a subprocess."""
    code = ("import sys, ambseal.identify.excitation.signals\n"
            "heavy = [m for m in ('matplotlib', 'control', 'scipy', 'cvxopt')\n"
            "         if any(k == m or k.startswith(m + '.') for k in sys.modules)]\n"
            "assert not heavy, heavy\n")
    subprocess.run([sys.executable, "-c", code], check=True)

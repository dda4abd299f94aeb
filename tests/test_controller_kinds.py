"""Every kind of controller file ambseal writes — fixed discrete, continuous, scheduled on the
speed, scheduled on a seal coefficient — through every command that takes ``--controller``:
used at each condition as it is scheduled, or refused in one line.

References: the interpolation law every export states (linear in θ between table entries,
:func:`ambseal.machine.scheduled_digital.interpolation_law`), applied here by hand — a
scheduled table at a condition is the fixed controller of the matrices interpolated at that
condition's θ (the speed, or the seal's k at the pressure drop by the rig file's affine law);
and python-control's Tustin discretisation of a continuous file.
"""

import csv
import json
import math
import re
from pathlib import Path

import control
import numpy as np
import pytest

from ambseal.cli import main
from ambseal.config import default_rig_path, load_rig
from ambseal.export import load_controller
from ambseal.export.controller_files import export_controller
from ambseal.machine import SPEED, ScheduledDigital
from ambseal.model import seal_values

RIG = str(default_rig_path())
#: the table's second entry: the first with its output (current) scaled by this
GAIN = 1.25


def _table(K, grid, parameter) -> ScheduledDigital:
    """A two-entry table of the digital controller ``K``: K at ``grid[0]``, K with its
    currents scaled by GAIN at ``grid[1]`` (C and D scale alike in every form)."""
    def stack(ss):
        A, B, C, D = (np.asarray(X, float) for X in (ss.A, ss.B, ss.C, ss.D))
        return (np.stack([A, A]), np.stack([B, B]), np.stack([C, GAIN * C]),
                np.stack([D, GAIN * D]))

    return ScheduledDigital(
        grid=np.asarray(grid, float), continuous=stack(K.continuous),
        reduced=stack(K.reduced), discrete=stack(K.discrete), inputs=tuple(K.inputs),
        outputs=tuple(K.outputs), method=K.method, prewarp_hz=K.prewarp_hz,
        sample_rate_hz=K.sample_rate_hz, delay_samples=K.delay_samples,
        name="K_table", parameter=parameter)


def _fixed(K, t: float, path):
    """The continuous controller file of the table's matrices at fraction ``t`` of the
    way from its first entry to its second (the interpolation law by hand)."""
    Kc = K.continuous
    s = (1 - t) + t * GAIN
    doc = {"kind": "continuous", "Ts": 0.0, "name": "K_fixed", "inputs": list(K.inputs),
           "outputs": list(K.outputs), "A": np.asarray(Kc.A).tolist(),
           "B": np.asarray(Kc.B).tolist(), "C": (s * np.asarray(Kc.C)).tolist(),
           "D": (s * np.asarray(Kc.D)).tolist()}
    path.write_text(json.dumps(doc))
    return path


@pytest.fixture(scope="module")
def kinds(tmp_path_factory):
    """The embedded rig's reference PID as ``ambseal design`` writes it (with the JSON line
    it printed), and from it a continuous file and two tables: on the speed over 0–100 Hz
    and on the seal's k from 0 bar to 3× the nominal pressure drop."""
    import contextlib
    import io

    out = tmp_path_factory.mktemp("kinds")
    printed = io.StringIO()
    with contextlib.redirect_stdout(printed):
        assert main(["design", RIG, "--method", "pid", "--out", str(out),
                     "--allow-unstable"]) == 0
    digital = out / "controller_pid.json"
    K = load_controller(digital)
    cfg = load_rig(RIG)
    p0 = cfg.operating.pressure_bar
    k_name = next(n for n in seal_values(cfg.seal, p0) if n.endswith(".k"))
    k_ends = [seal_values(cfg.seal, p)[k_name] for p in (0.0, 3.0 * p0)]
    speed = export_controller(_table(K, [0.0, 2 * math.pi * 100.0], SPEED),
                              out / "table_speed.json")
    seal = export_controller(_table(K, k_ends, k_name), out / "table_seal.json")
    cont = _fixed(K, 0.0, out / "continuous.json")
    return {"K": K, "cfg": cfg, "p0": p0, "k_name": k_name, "k_ends": k_ends, "dir": out,
            "printed": json.loads(printed.getvalue()), "files": {"digital": digital, "continuous": cont, "speed": speed, "seal": seal}}


def _cli(capsys, argv) -> tuple[int, str, list[str]]:
    code = main([str(a) for a in argv])
    cap = capsys.readouterr()
    return code, cap.out, [ln for ln in cap.err.splitlines() if ln.startswith("ambseal: error")]


def test_every_kind_through_every_command(kinds, tmp_path, capsys):
    """``sweep``, ``export``, ``campbell`` and ``modes`` take each kind: exit 0 with their
    JSON on stdout, no error line; the tables read back as what was written."""
    files = kinds["files"]
    assert isinstance(load_controller(files["speed"]), ScheduledDigital)
    assert load_controller(files["seal"]).parameter == kinds["k_name"]
    for kind, path in files.items():
        for cmd in (["sweep", RIG, "--pressure-bar", "1", "--speed-hz", "50",
                     "--workers", "1", "--out", tmp_path / f"sw_{kind}"],
                    # the test rig's PID family loses 4.08 bar: exported as asked
                    ["export", RIG, "--out", tmp_path / f"ex_{kind}", "--allow-unstable"],
                    ["campbell", RIG, "--speed-hz", "50", "--out", tmp_path / f"cb_{kind}"],
                    ["modes", RIG, "--json"]):
            code, out, errors = _cli(capsys, cmd + ["--controller", path])
            assert code == 0 and not errors, (kind, cmd[0], errors)
            json.loads(out)


def _same_row(a: dict, b: dict, what) -> None:
    """Two sweep rows with the same results (a number within 1e-7, or both empty where the
    loop is unstable)."""
    for key in ("stable", "max_real_pole", "sensitivity_peak", "lowest_log_dec"):
        if a[key] in ("", "True", "False"):
            assert a[key] == b[key], (what, key)
        else:
            assert float(a[key]) == pytest.approx(float(b[key]), rel=1e-7), (what, key)


def _modes(capsys, path, pressure_bar, speed_hz=0.0) -> dict:
    code, out, errors = _cli(capsys, ["modes", RIG, "--json", "--controller", path,
                                      "--pressure-bar", pressure_bar,
                                      "--speed-rpm", 60.0 * speed_hz])
    assert code == 0, errors
    return json.loads(out)


def _same_modes(a: dict, b: dict) -> None:
    for key in ("natural_frequencies_hz", "log_decrements"):
        np.testing.assert_allclose(a[key], b[key], rtol=1e-7, atol=1e-9, err_msg=key)


def test_a_table_on_the_seal_runs_at_the_seals_k(kinds, tmp_path, capsys):
    """At the nominal pressure drop (k a third of the way along the table) and at 3× it
    (the table's end), ``modes`` and ``sweep`` with the table on the seal's k give the
    numbers of the fixed controller interpolated there by hand — and not those of the
    table's first entry (what a table taken at the speed's value would give)."""
    K, cfg, k_name, (k0, k1) = kinds["K"], kinds["cfg"], kinds["k_name"], kinds["k_ends"]
    seal = kinds["files"]["seal"]
    first = _modes(capsys, _fixed(K, 0.0, tmp_path / "first.json"), kinds["p0"])
    for p in (kinds["p0"], 3.0 * kinds["p0"]):
        t = (seal_values(cfg.seal, p)[k_name] - k0) / (k1 - k0)
        assert 0.3 < t <= 1.0
        ref = _fixed(K, t, tmp_path / f"fixed_{p:g}.json")
        got = _modes(capsys, seal, p)
        _same_modes(got, _modes(capsys, ref, p))
        assert min(got["log_decrements"]) != pytest.approx(min(first["log_decrements"]),
                                                          rel=1e-3)
        rows = []
        for path in (seal, ref):
            out = tmp_path / f"sw_{path.stem}_{p:g}"
            code, _, errors = _cli(capsys, ["sweep", RIG, "--pressure-bar", p, "--speed-hz",
                                            "20", "--workers", "1", "--out", out,
                                            "--controller", path])
            assert code == 0, errors
            rows.append(next(csv.DictReader((out / "sweep.csv").open())))
        _same_row(*rows, p)


def test_a_table_on_the_speed_runs_at_each_speed(kinds, tmp_path, capsys):
    """``sweep`` over 20 and 80 Hz with the speed table gives at each speed the row of the
    fixed controller interpolated at that speed (t = 0.2 and 0.8), and ``modes`` at 80 Hz
    the same modes."""
    K, path = kinds["K"], kinds["files"]["speed"]
    out = tmp_path / "sw"
    code, _, errors = _cli(capsys, ["sweep", RIG, "--pressure-bar", "1", "--speed-hz",
                                    "20:80:2", "--workers", "1", "--out", out,
                                    "--controller", path])
    assert code == 0, errors
    rows = list(csv.DictReader((out / "sweep.csv").open()))
    for row, f in zip(rows, (20.0, 80.0)):
        ref = _fixed(K, f / 100.0, tmp_path / f"fixed_{f:g}.json")
        o = tmp_path / f"sw_{f:g}"
        assert _cli(capsys, ["sweep", RIG, "--pressure-bar", "1", "--speed-hz", f,
                             "--workers", "1", "--out", o, "--controller", ref])[0] == 0
        want = next(csv.DictReader((o / "sweep.csv").open()))
        assert float(row["speed_hz"]) == f
        _same_row(row, want, f)
    _same_modes(_modes(capsys, path, 1.0, 80.0),
                _modes(capsys, _fixed(K, 0.8, tmp_path / "m80.json"), 1.0, 80.0))


def _c_matrices(path) -> dict:
    """The A_ … D_ arrays of a generated C module."""
    text = path.read_text()
    return {k: np.array([float(x) for x in re.findall(
        r"[-+0-9.e]+", re.search(rf"{k}_\[\d+\] = \{{(.*?)\}};", text, re.S).group(1))])
        for k in "ABCD"}


def test_export_discretises_a_continuous_file_as_python_control_does(kinds, tmp_path,
                                                                     capsys):
    """``export --controller continuous.json`` writes C and says how it discretised it;
    the module's step matrices have the frequency response of python-control's
    ``sample_system`` with that method at the rig's rate (Tustin or ZOH), within 1e-9 of
    its peak."""
    K = kinds["K"]
    code, out, errors = _cli(capsys, ["export", RIG, "--controller",  # loses 4.08 bar
                                      kinds["files"]["continuous"], "--out", tmp_path,
                                      "--allow-unstable"])
    assert code == 0, errors
    done = json.loads(out)["discretised"]
    fs = done["sample_rate_hz"]
    assert fs == kinds["cfg"].controller.sample_rate_hz
    c = next(p for p in map(Path, json.loads(out)["files"]) if p.suffix == ".c")
    m = _c_matrices(c)
    ny, nu = len(K.inputs), len(K.outputs)
    n = m["B"].size // ny
    Kd = control.ss(m["A"].reshape(n, n), m["B"].reshape(n, ny), m["C"].reshape(nu, n),
                    m["D"].reshape(nu, ny), 1.0 / fs)
    method = {"tustin": "bilinear", "zoh": "zoh"}[done["method"]]
    ref = control.sample_system(control.ss(K.continuous.A, K.continuous.B, K.continuous.C,
                                           K.continuous.D), 1.0 / fs, method=method)
    w = 2 * np.pi * np.logspace(0, math.log10(0.45 * fs), 40)
    a, b = (np.moveaxis(s.frequency_response(w).complex, -1, 0) for s in (Kd, ref))
    assert np.max(np.abs(a - b)) < 1e-9 * np.max(np.abs(b))


def test_signoff_refuses_a_continuous_file_in_one_line(kinds, tmp_path, capsys):
    """The sign-off judges the discrete controller as it runs: a continuous file is refused
    in one line naming it (on a rig with stages: the b2b compressor example)."""
    b2b = Path(__file__).resolve().parents[1] / "examples" / "b2b_compressor.toml"
    code, _, errors = _cli(capsys, ["signoff", b2b, "--controller",
                                    kinds["files"]["continuous"], "--out", tmp_path / "so"])
    assert code == 2 and len(errors) == 1
    assert "continuous" in errors[0]


def test_a_table_on_the_seal_runs_as_the_sign_off_takes_it(kinds):
    """The discrete controller as it runs (the sign-off's and the API 617 unbalance
    response's, :func:`ambseal.machine.controller_as_runs`) of the table on the seal's k at
    the nominal pressure drop is the digital PID with its currents scaled as the
    interpolation law says there; without the seal's values it is refused, not taken at
    the speed."""
    from dataclasses import replace

    from ambseal.errors import ModelError
    from ambseal.machine import controller_as_runs

    K, cfg, (k0, k1) = kinds["K"], kinds["cfg"], kinds["k_ends"]
    table = load_controller(kinds["files"]["seal"])
    values = seal_values(cfg.seal, kinds["p0"])
    s = 1 + (GAIN - 1) * (values[kinds["k_name"]] - k0) / (k1 - k0)
    d = K.discrete
    ref = controller_as_runs(replace(K, discrete=replace(d, C=s * d.C, D=s * d.D)), 0.0)
    got = controller_as_runs(table, 2 * math.pi * 20.0, values)
    for key in "ABCD":
        np.testing.assert_allclose(getattr(got, key), getattr(ref, key), rtol=1e-12,
                                   atol=1e-12 * np.abs(getattr(ref, key)).max())
    with pytest.raises(ModelError, match=kinds["k_name"]):
        controller_as_runs(table, 2 * math.pi * 20.0)


def test_a_scheduled_table_runs_on_the_virtual_facility(kinds, tmp_path):
    """``run --truth`` runs every delivered controller on the virtual facility
    (:func:`ambseal.app.commands.facility_impulses`): a table on the speed runs its entry
    at the operating speed and a table on the seal's k its entry at each pressure drop's k
    — the impulse responses of the digital PID with its currents scaled as the
    interpolation law says there, sample for sample (the facility's noise is seeded)."""
    from dataclasses import replace
    from types import SimpleNamespace

    from ambseal.app.commands import Identified, facility_impulses
    from ambseal.app.pipeline import default_truth_path
    from ambseal.config import load_truth

    K, cfg, (k0, k1) = kinds["K"], kinds["cfg"], kinds["k_ends"]
    truth = load_truth(default_truth_path())
    f_op = cfg.operating.speed_rpm / 60.0
    pressures = sorted({0.0, kinds["p0"]})
    d = K.discrete
    refs = {}
    for p in pressures:
        t = (seal_values(cfg.seal, p)[kinds["k_name"]] - k0) / (k1 - k0)
        refs[("seal", p)] = replace(K, discrete=replace(d, C=(1 + (GAIN - 1) * t) * d.C,
                                                        D=(1 + (GAIN - 1) * t) * d.D))
        refs[("speed", p)] = replace(K, discrete=replace(
            d, C=(1 + (GAIN - 1) * f_op / 100.0) * d.C, D=(1 + (GAIN - 1) * f_op / 100.0) * d.D))

    def checks(digitals):
        ident = Identified(summary={"design": {"designed_on": "rig file", "reason": "test"}},
                           figs=[], sections=[], result=SimpleNamespace(identified=cfg),
                           design_cfg=cfg, truth_cfg=cfg)
        facility_impulses(cfg, truth, ident, digitals, tmp_path)
        return {(c["controller"], c["pressure_bar"]): c for c in ident.summary["facility_impulse"]}

    got = checks({"speed": load_controller(kinds["files"]["speed"]),
                  "seal": load_controller(kinds["files"]["seal"])})
    first = checks({"pid": K})
    for (kind, p), ref in refs.items():
        want, a = checks({kind: ref})[(kind, p)], got[(kind, p)]
        # the identified model's response is exact; the facility's quantised sensors may
        # round a sample the other way where the currents differ in their last digits
        assert a["peak_model_um"] == pytest.approx(want["peak_model_um"], rel=1e-9)
        assert a["peak_facility_um"] == pytest.approx(want["peak_facility_um"], rel=1e-3)
        for ax, fit in want["nrmse_fit_pct"].items():
            assert a["nrmse_fit_pct"][ax] == pytest.approx(fit, abs=0.1), (kind, p, ax)
        if ref.discrete.D[0, 0] != d.D[0, 0]:  # not the first entry: not its response
            assert a["peak_model_um"] != pytest.approx(first[("pid", p)]["peak_model_um"],
                                                       rel=1e-3), (kind, p)


def test_design_prints_the_verdict_its_file_holds(kinds):
    """``design --method pid --allow-unstable`` on the embedded rig, whose reference PID
    loses the full-order loop at 3× the nominal pressure drop: the JSON line on stdout
    says ``kept_unstable`` and gives the full-order check exactly as
    ``design_pid.json`` does."""
    printed = kinds["printed"]
    written = json.loads((kinds["dir"] / "design_pid.json").read_text())
    assert written["kept_unstable"] is True and not written["full_order"]["stable"]
    assert printed["kept_unstable"] is True
    assert printed["full_order"] == written["full_order"]


def test_the_drop_runs_a_digital_controller_as_it_runs(kinds, tmp_path, capsys):
    """``ambseal drop --controller FILE`` with ``ambseal design``'s digital PID runs it
    sampled, with its delay (drop.json's ``controller_runs``, and the page), and its
    continuous design (the continuous file of the same PID) gives another orbit after
    the same overload."""
    docs = {}
    for kind in ("digital", "continuous"):
        code, out, errors = _cli(capsys, [
            "--quiet", "drop", RIG, "--controller", kinds["files"][kind], "--event",
            "overload", "--overload-n", "200", "--start", "rest", "--duration-s", "0.01",
            "--out", tmp_path / kind, "--json"])
        assert code in (0, 1) and not errors
        docs[kind] = json.loads(out)
    K = kinds["K"]
    assert docs["digital"]["controller_runs"] == (
        f"digital at {K.sample_rate_hz:g} Hz, {K.delay_samples} sample(s) of computation "
        "delay")
    assert docs["continuous"]["controller_runs"] == "continuous"
    assert docs["digital"]["controller_runs"] in (tmp_path / "digital" / "drop.html").read_text()
    a, b = (docs[k]["watched_max_m"]["amb:A"] for k in ("digital", "continuous"))
    assert abs(a - b) > 1e-3 * b

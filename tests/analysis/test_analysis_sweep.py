"""Stability maps and the case executor (analysis/sweep.py), serial and on Dask."""

from __future__ import annotations

import json
import os
import pickle
import sys
from pathlib import Path

import numpy as np
import pytest

from ambseal.analysis.cases import CaseError, run_cases
from ambseal.analysis.judge import judge_settings
from ambseal.analysis.sweep import parse_range, stability_boundary, sweep, sweep_case
from ambseal.design.specs import design_spec


def test_pid_loses_the_embedded_rig_between_nominal_and_twice_nominal(testrig_cfg,
                                                                       testrig_designs):
    """Thesis P5 §4.4.2 (Fig. 13): the reference PID is stable at 0 and at the nominal
    2.04 bar and unstable at 4.08 bar; the sweep's boundary at standstill lies between, and
    each case's stability agrees with python-control's ``feedback(G L, K)`` poles (peer
    library) on the same full-order plant with the digital controller's 150 µs delay as
    python-control's own order-4 Padé lag L (``control.pade``) on each current."""
    import control

    from ambseal.model.rig import build_plant

    K = testrig_designs["pid"].K
    fs, nd = testrig_cfg.controller.sample_rate_hz, testrig_cfg.controller.delay_samples
    L1 = control.ss(control.tf(*control.pade((nd + 0.5) / fs, 4)))
    L = control.append(*[L1] * 4)
    rows = sweep(testrig_cfg, {"pid": K}, [0.0, 2.04, 4.08], [0.0], workers=1,
                 settings=judge_settings(design_spec(testrig_cfg)))
    assert [r["stable"] for r in rows] == [True, True, False]
    (edge,) = stability_boundary(rows)
    assert 2.04 < edge["boundary_pressure_bar"] < 4.08
    for r in rows:
        plant = build_plant(testrig_cfg, pressure_bar=r["pressure_bar"])
        G = plant.select_inputs(plant.input_names[:4]).to_statespace()
        ref = control.feedback(control.series(L, G), K, sign=-1).poles().real.max()
        # python-control's companion form of the Padé lag (coefficients from τ⁴ ≈ 5e-16 to
        # 1) costs digits: the two agree to ~1e-7 (1e-8 without the lag)
        assert r["max_real_pole"] == pytest.approx(ref, rel=1e-6, abs=1e-9)
    assert rows[0]["iso_zone_A_zeta"] in "ABCD" and rows[2]["unbalance_peak_um"] is None
    assert rows[2]["lowest_log_dec"] < 0 < rows[1]["lowest_log_dec"]  # δ < 0: growing
    # the sign-off's limit on the log decrement, beside the zones: a row says whether its
    # least damped mode meets it
    limit = testrig_cfg.signoff.log_dec_min
    assert [r["log_dec_ok"] for r in rows] == [r["lowest_log_dec"] >= limit for r in rows]
    assert rows[2]["log_dec_ok"] is False


#: the tiny rig's controller: 1 MHz, one sample of computation delay (τ = 1.5 µs)
TINY_FS, TINY_TAU = 1e6, 1.5e-6


def _tiny_rig() -> dict:
    """A rigid rotor (shaft 10⁵ times stiffer than its supports, 16.17 kg) on two AMBs
    closed by proportional gains into k = 10⁶ N/m each, with a seal at mid-span; a 1 MHz
    controller, so that its delay barely moves the continuous-controller closed forms."""
    return {"controller": {"sample_rate_hz": TINY_FS, "delay_samples": 1},
            "materials": {"m": {"E": 2e16, "rho": 7850.0, "nu": 0.3}},
            "shaft": [{"length": 0.4, "outer_diameter": 0.05, "material": "m",
                       "elements": 2}],
            "disk": [{"position": 0.2, "mass": 10.0, "Ip": 0.05, "Id": 0.1}],
            "amb": [{"name": n, "position": z, "sensor_position": z, "ki": 100.0,
                     "ks": 1e5} for n, z in (("A", 0.0), ("B", 0.4))],
            "seal": [{"name": "s", "position": 0.2, "k": {"at_zero": 0.0, "per_bar": 1e5},
                      "C": 300.0}],
            "spring": [{"position": z, "kxx": 0.0, "kyy": 0.0, "cxx": 300.0, "cyy": 300.0}
                       for z in (0.0, 0.4)]}


def test_the_same_rows_on_a_dask_scheduler_by_address_and_a_failed_case_kept():
    """A LocalCluster started here, reached by its address: the rows equal the serial run's
    bit for bit and come back in input order; a case that raises is a CaseError with its
    message and the cases after it still run. Reference: a Jeffcott rotor's cross-coupled
    stiffness k destabilises its translation mode where k > c·ω_n (Childs, *Turbomachinery
    Rotordynamics*, 1993, §1.5): c = 900 N·s/m in all, ω_n = √(2·10⁶/16.2 kg) = 352 rad/s,
    so k = 1e5 N/m per bar crosses at 3.2 bar: stable at 0 and 2.5, unstable at 4 bar."""
    distributed = pytest.importorskip("distributed")
    import control

    from ambseal.config import parse_rig

    cfg = parse_rig(_tiny_rig())
    K = control.ss([], [], [], (1e6 + 1e5) / 100.0 * np.eye(4))
    shared = {"rig": cfg.model_dump(exclude_none=True),
              "controllers": {"p": (np.zeros((0, 0)), np.zeros((0, 4)), np.zeros((4, 0)),
                                    np.asarray(K.D))}, "max_hz": 2000.0,
              "settings": judge_settings(design_spec(cfg))}
    pickle.loads(pickle.dumps(shared))  # plain, picklable inputs
    cases = [{"controller": "p", "pressure_bar": p, "speed_hz": 0.0, "params": {}}
             for p in (0.0, 2.5, 4.0)]
    cases.insert(1, {"controller": "missing", "pressure_bar": 1.0, "speed_hz": 0.0,
                     "params": {}})
    serial = run_cases(sweep_case, cases, shared=shared, workers=1)
    with distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=False,
                                  dashboard_address=None) as cluster:
        seen = []
        on_dask = run_cases(sweep_case, cases, shared=shared,
                            scheduler=cluster.scheduler_address,
                            on_done=lambda i, r: seen.append(i))
    assert sorted(seen) == [0, 1, 2, 3]
    assert isinstance(serial[1], CaseError) and "KeyError" in serial[1].error
    assert isinstance(on_dask[1], CaseError) and on_dask[1].error == serial[1].error
    for i in (0, 2, 3):
        assert json.dumps(serial[i]) == json.dumps(on_dask[i])
    assert [serial[i]["stable"] for i in (0, 2, 3)] == [True, True, False]


def test_local_worker_processes_give_the_serial_rows():
    """``workers=2``: a local cluster of two worker processes (forked on Linux) returns the
    serial run's rows bit for bit, in input order. Reference: the serial run, and the
    Jeffcott threshold of the test above (stable at 0 and 2.5 bar, unstable at 4 bar)."""
    pytest.importorskip("distributed")
    import control

    from ambseal.config import parse_rig

    cfg = parse_rig(_tiny_rig())
    K = {"p": control.ss([], [], [], (1e6 + 1e5) / 100.0 * np.eye(4))}
    settings = judge_settings(design_spec(cfg))
    serial = sweep(cfg, K, [0.0, 2.5, 4.0], [0.0, 5.0], workers=1, settings=settings)
    forked = sweep(cfg, K, [0.0, 2.5, 4.0], [0.0, 5.0], workers=2, settings=settings)
    assert json.dumps(serial) == json.dumps(forked)
    assert [r["stable"] for r in serial if r["speed_hz"] == 0.0] == [True, True, False]


def test_ranges_and_bad_input():
    """``a:b:n`` is numpy's linspace; anything else is one ConfigError naming the option;
    an unreachable scheduler is a ConfigError too."""
    from ambseal.errors import AmbsealError, ConfigError

    assert parse_range("0:4.08:3", "--p") == pytest.approx([0.0, 2.04, 4.08])
    assert parse_range("2", "--p") == pytest.approx([2.0])
    for bad in ("0:4", "a:b:3", "0:1:0", "0:1:2.5"):
        with pytest.raises(ConfigError, match="--p"):
            parse_range(bad, "--p")
    with pytest.raises(AmbsealError):
        run_cases(lambda case: 1 / 0, [{}], raise_errors=True, workers=1)


def test_cli_sweep_writes_table_boundary_and_map_and_keeps_failed_cases(tmp_path, capsys):
    """``ambseal sweep`` on the rigid rotor with a controller file: the table has every
    case in order, the grid brackets and the bisection finds the Jeffcott threshold
    k = c·ω_n (Childs 1993, §1.5: m s² + c s + K − jk = 0 has a root on the imaginary axis
    where k = c·√(K/m)) to 1e-4 relative, the map is written; ``--param`` values the rig format
    refuses (a negative eddy-current lag) fail every case, each kept in the table with its
    error, and the command still ends normally; a parameter name the rig does not have is
    refused before any case."""
    import csv

    import control

    from ambseal.cli import main
    from ambseal.config import dump_rig, parse_rig
    from ambseal.export.controller_files import export_controller

    from ambseal.model.amb import channel_names

    rig = tmp_path / "rig.toml"
    cfg = parse_rig(_tiny_rig())
    rig.write_text(dump_rig(cfg))
    ch = channel_names(cfg)
    kfile = export_controller(control.ss([], [], [], 1.1e4 * np.eye(4),
                                         inputs=[f"y_{c}" for c in ch],
                                         outputs=[f"i_{c}" for c in ch]), tmp_path / "P.json")
    out = tmp_path / "sw"
    args = ["sweep", str(rig), "--pressure-bar", "0:4:3", "--controller", str(kfile),
            "--out", str(out), "--workers", "1", "--tol-bar", "1e-5"]
    assert main(args) == 0
    summary = json.loads(capsys.readouterr().out)
    rows = list(csv.DictReader((out / "sweep.csv").open()))
    assert [float(r["pressure_bar"]) for r in rows] == [0.0, 2.0, 4.0]
    assert [r["stable"] for r in rows] == ["True", "True", "False"]
    (edge,) = summary["boundary"]
    assert edge["last_stable_bar"] == 2.0 and edge["first_unstable_bar"] == 4.0
    m = 10.0 + 7850.0 * np.pi * 0.05**2 / 4 * 0.4
    # c: two dampers and the seal's C, less the controller delay's k_c·τ per support
    # (k_c = Ki·K = 1.1e6 N/m, e^{−jωτ} ≈ 1 − jωτ); K: two supports
    k_crit = (900.0 - 2 * 1.1e6 * TINY_TAU) * np.sqrt(2e6 / m)
    assert edge["boundary_pressure_bar"] == pytest.approx(k_crit / 1e5, rel=1e-4)
    assert (out / "stability_map.png").stat().st_size > 10_000
    assert main(args + ["--param", "tau_e=-2:-1:2"]) == 0  # no rig has a negative lag
    summary = json.loads(capsys.readouterr().out)
    assert summary["cases"] == 6 and summary["failed"] == 6
    rows = list(csv.DictReader((out / "sweep.csv").open()))
    assert all("eddy_time_constant" in r["error"] for r in rows)
    # a name the rig does not have: refused before any case, naming the rig's names
    assert main(args + ["--param", "nope.k=0:1:2"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "unknown parameter 'nope.k'" in err[0] and "s.k" in err[0]


def test_cli_sweep_takes_the_rigs_pressure_without_pressure_bar(tmp_path, capsys):
    """``ambseal sweep RIG --speed-hz ...`` without ``--pressure-bar``: the sweep runs at
    the rig's own ``[operating] pressure_bar`` (a rig without seals has no other), as
    ``--help`` says. Reference: the Jeffcott threshold k = c·ω_n (Childs 1993, §1.5) of the
    rigid rotor, k = 10⁵ N/m per bar crossing at 3.2 bar: stable at the rig's 2 bar,
    unstable at its 4 bar, at every speed of the range."""
    import csv

    import control

    from ambseal.cli import main
    from ambseal.config import dump_rig, parse_rig
    from ambseal.export.controller_files import export_controller
    from ambseal.model.amb import channel_names

    kfile = None
    for p_bar, stable in ((2.0, "True"), (4.0, "False")):
        cfg = parse_rig({**_tiny_rig(), "operating": {"pressure_bar": p_bar}})
        rig = tmp_path / f"rig{p_bar:g}.toml"
        rig.write_text(dump_rig(cfg))
        if kfile is None:
            ch = channel_names(cfg)
            kfile = export_controller(
                control.ss([], [], [], 1.1e4 * np.eye(4), inputs=[f"y_{c}" for c in ch],
                           outputs=[f"i_{c}" for c in ch]), tmp_path / "P.json")
        out = tmp_path / f"sw{p_bar:g}"
        assert main(["sweep", str(rig), "--speed-hz", "0:20:3", "--controller", str(kfile),
                     "--out", str(out), "--workers", "1"]) == 0, capsys.readouterr().err
        assert json.loads(capsys.readouterr().out)["cases"] == 3
        rows = list(csv.DictReader((out / "sweep.csv").open()))
        assert [float(r["pressure_bar"]) for r in rows] == [p_bar] * 3
        assert [r["stable"] for r in rows] == [stable] * 3
    with pytest.raises(SystemExit):
        main(["sweep", "--help"])
    assert "default the rig's [operating] pressure_bar" in " ".join(
        capsys.readouterr().out.split())


def test_a_scheduler_that_never_answers_is_refused_in_time(silent_peer, tmp_path, capsys,
                                                           monkeypatch):
    """A Dask scheduler address whose peer accepts and stays silent: ``run_cases`` and
    ``ambseal sweep --scheduler`` end within the deadline (here 1 s) in one error naming
    the address, the sweep before any design (distributed's Client alone waits without
    end); a real scheduler answers the same probe."""
    import time

    distributed = pytest.importorskip("distributed")
    from ambseal.analysis import cases
    from ambseal.cli import main
    from ambseal.config import default_rig_path
    from ambseal.errors import ConfigError

    monkeypatch.setattr(cases, "SCHEDULER_TIMEOUT_S", 1.0)
    t0 = time.monotonic()
    with pytest.raises(ConfigError, match="no answer within 1 s"):
        cases.run_cases(sweep_case, [{}], scheduler=silent_peer)
    t1 = time.monotonic()
    assert main(["sweep", str(default_rig_path()), "--pressure-bar", "1", "--scheduler",
                 silent_peer, "--out", str(tmp_path / "o")]) == 2
    t2 = time.monotonic()
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("ambseal: error: "), err
    assert silent_peer in err[0] and "no answer" in err[0] and "Traceback" not in err[0]
    assert t1 - t0 < 5.0 and t2 - t1 < 5.0
    with distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=False,
                                  dashboard_address=None) as cluster:
        cases.probe_scheduler(cluster.scheduler_address)


def _inside_a_worker(case: dict) -> dict:
    """What a case sees of its cluster from inside a worker: the scheduler's protocol,
    the scratch folder, every listening TCP port of the main process and of the worker,
    and whether another client gets in — plain, or with TLS credentials of its own, as
    another local user would make."""
    import stat

    import psutil
    from distributed import Client, get_worker
    from distributed.security import Security

    w = get_worker()

    def listening(p):
        return sorted(c.laddr.port for c in p.net_connections("tcp")
                      if c.status == psutil.CONN_LISTEN)
    intruder = []
    plain = "tcp://" + w.scheduler.address.split("://", 1)[1]
    for address, security in ((plain, None), (w.scheduler.address, Security.temporary())):
        try:
            with Client(address, security=security, timeout="3s"):
                intruder.append("connected")
        except Exception as exc:  # whatever the refusal looks like
            intruder.append(type(exc).__name__)
    top = Path(w.local_directory)
    while not top.name.startswith("ambseal-dask-") and top != top.parent:
        top = top.parent
    return {"scheduler": w.scheduler.address, "address": w.address, "scratch": str(top),
            "mode": stat.S_IMODE(top.stat().st_mode),
            "main": listening(psutil.Process(case["main"])),
            "worker": listening(psutil.Process()), "intruder": intruder}


def test_the_local_cluster_is_private():
    """``workers=2``: the scheduler speaks TLS with credentials of its own (a client with
    other credentials is refused), the workers' scratch is a fresh 0700 folder of
    ambseal's, removed afterwards; the main process listens on the TLS comms of the
    scheduler and of the two workers' nannies only, and each worker on its own comm: no HTTP
    server (Dask starts one, on 8787 for the scheduler, even without a dashboard)."""
    pytest.importorskip("distributed")
    import cloudpickle

    cloudpickle.register_pickle_by_value(sys.modules[__name__])
    try:
        seen = run_cases(_inside_a_worker, [{"main": os.getpid()}] * 2, workers=2)
    finally:
        cloudpickle.unregister_pickle_by_value(sys.modules[__name__])
    for s in seen:
        assert s["scheduler"].startswith("tls://"), s
        assert "connected" not in s["intruder"], s
        assert Path(s["scratch"]).name.startswith("ambseal-dask-") and s["mode"] == 0o700
        assert not Path(s["scratch"]).exists()
        port = int(s["scheduler"].rsplit(":", 1)[1])
        assert port in s["main"] and len(s["main"]) == 1 + 2, s
        assert s["worker"] == [int(s["address"].rsplit(":", 1)[1])], s


def test_a_controller_that_runs_on_a_target_is_swept_as_it_runs(testrig_cfg):
    """Reference: the judgement of ``ambseal run`` at the same condition — a controller
    file's digital controller (the PID as ``ambseal design`` exports it) in a sweep gives,
    beside the continuous columns, the loop as it runs (discrete controller with its delay
    on the sampled plant): stable, max |z|, σ̄(S_o) peak and zones, unbalance peak, equal
    to :func:`~ambseal.analysis.judge.judge`'s ``discrete`` block there (1e-9); a
    controller without one gets no such column."""
    from ambseal.analysis.judge import OperatingPoint, judge
    from ambseal.app.commands import digital_for
    from ambseal.design import design

    cfg = testrig_cfg
    res = design(cfg, "pid")
    s = judge_settings(design_spec(cfg))
    p = cfg.operating.pressure_bar
    point = OperatingPoint(p, 0.0, "")
    digital = digital_for(cfg, "pid", res.K, res, [point])
    rows = sweep(cfg, {"pid": res.K, "plain": res.K}, [p], [0.0], settings=s, workers=1,
                 digitals={"pid": digital})
    ref = judge(cfg, res.K, "pid", point, s, impulse=False,
                discrete=digital.statespace(delayed=True))[0].discrete
    row, plain = rows
    assert row["stable_as_runs"] is ref.stable is True
    assert row["max_abs_pole_z"] == pytest.approx(ref.max_abs_pole_z, rel=1e-9)
    assert row["sensitivity_peak_as_runs"] == pytest.approx(ref.sensitivity_peak, rel=1e-9)
    assert row["iso_zone_as_runs"] == ref.iso_zone
    assert {k: v for k, v in row.items() if k.startswith("iso_zone_") and k.endswith(
        "_as_runs") and k != "iso_zone_as_runs"} == {
        f"iso_zone_{ax}_as_runs": z for ax, z in ref.iso_zone_per_axis.items()}
    assert row["unbalance_peak_um_as_runs"] == pytest.approx(ref.unbalance_peak_um, rel=1e-9)
    assert not any(k.endswith("_as_runs") for k in plain)
    # the loop as it runs is a result, not a parameter of the map's boundary
    (edge,) = [b for b in stability_boundary(rows) if b["controller"] == "pid"]
    assert not any(k.endswith("_as_runs") or k == "max_abs_pole_z" for k in edge)

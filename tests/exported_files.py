"""The files ``ambseal run`` exports, read back and checked by python-control, for the
tests' references: a controller file's matrices at a speed, and the unbalance force
rejection exported beside each delivered controller."""

from pathlib import Path

import control
import numpy as np
import pytest
import scipy.linalg

from ambseal.config import load_rig
from ambseal.export import load_notch
from ambseal.model import build_plant

from .freq_at import at

#: ISO 14839-3 zone B's upper limit of the sensitivity function's peak (Annex A, 12 dB)
ZONE_B_LIMIT = 4.0


def file_at(f, hz: float) -> list[np.ndarray]:
    """An exported controller file's A, B, C, D at ``hz``: a scheduled one's table linear
    between its speeds (rad/s) as the file says, held at its ends."""
    mats = [np.asarray(f[k], float) for k in "ABCD"]
    if mats[0].ndim == 3:
        w = np.clip(2 * np.pi * hz, f["grid"][0], f["grid"][-1])
        j = min(int(np.searchsorted(f["grid"], w, side="right")) - 1, len(f["grid"]) - 2)
        t = (w - f["grid"][j]) / (f["grid"][j + 1] - f["grid"][j])
        mats = [(1 - t) * M[j] + t * M[j + 1] for M in mats]
    return mats


def rejection_held_by_python_control(rig: Path, metrics: dict, out: Path) -> None:
    """The exported unbalance force rejection checked as tests/test_examples.py's
    ``_held_by_python_control`` checks the controllers: each delivered controller's file
    (a scheduled one at the condition's speed) with its notch read back from
    ``rejection_<m>.json`` — the controller after python-control's loop ``q = y − N q``
    (``control.feedback``), then its delay, for each delivered controller that runs with
    one — closed on the full-order plant sampled by
    python-control at every condition the run judged where the notch is on:
    every pole inside the unit circle, and the current from forces at the bearings at
    the rotational frequency below 1 % of the controller's alone."""
    cfg = load_rig(rig)
    delivered = set(metrics["controllers"]) - set(metrics["failed"]) - set(metrics["cannot_run"])
    # those that run with a notch: every one where the rig asks for it, else those whose
    # amplifier the run found saturated alone
    delivered = {m for m in delivered
                 if (metrics["controllers"][m].get("rejection") or {}).get("files")}
    assert delivered, "no delivered controller runs with an unbalance force rejection"
    conditions = {(c["pressure_bar"], c["speed_hz"]) for c in metrics["stability"]} | {
        (c["pressure_bar"], c["speed_hz"]) for c in metrics["cases"]}
    for m in sorted(delivered):
        notch = load_notch(out / "controllers" / f"rejection_{m}.json")
        f = np.load(out / "controllers" / f"controller_{m}.npz", allow_pickle=False)
        Ts, d = float(f["Ts"]), int(f["delay_samples"])
        assert Ts == notch.dt
        delay = control.tf([1], [1] + [0] * d, Ts)
        for p, hz in sorted(c for c in conditions if notch.is_on(2 * np.pi * c[1])):
            w = 2 * np.pi * hz
            K = control.ss(*file_at(f, hz), Ts)
            A, B, C = notch.matrices_at(w)
            N = control.ss(A, B, C, np.zeros((C.shape[0], C.shape[0])), Ts)
            Kn = K * control.feedback(control.ss([], [], [], np.eye(C.shape[0]), Ts), N)
            plant = build_plant(cfg, pressure_bar=p, speed_rpm=60.0 * hz,
                                force_positions=tuple(a.position for a in cfg.amb))
            cur = plant.current_inputs()
            frc = [j for j in range(plant.B.shape[1]) if j not in cur]
            G = control.sample_system(control.ss(plant.A, plant.B, plant.C, plant.D), Ts,
                                      "zoh")
            z = np.exp(1j * w * Ts)
            gains = []
            for Kx in (K * delay, Kn * delay):
                Gi = control.ss(G.A, G.B[:, cur], G.C, G.D[:, cur], Ts)
                Gf = control.ss(G.A, G.B[:, frc], G.C, G.D[:, frc], Ts)
                loop = control.feedback(Gi, Kx)
                assert np.abs(loop.poles()).max() < 1, (rig.stem, m, p, hz)
                # current from the forces: i = −K (I + G K)⁻¹ G_f, at z
                Gz, Gfz, Kz = at(Gi, z), at(Gf, z), at(Kx, z)
                gains.append(np.abs(Kz @ np.linalg.solve(np.eye(Gz.shape[0]) + Gz @ Kz,
                                                         Gfz)).max())
            assert gains[1] < 1e-2 * gains[0], (rig.stem, m, p, hz, gains)


def _frf(A, B, C, D, z: np.ndarray) -> np.ndarray:
    """C (zI − A)⁻¹ B + D at each z, by dense solves (python-control's own evaluation of a
    delayed discrete loop is not the reference, tests/freq_at.py)."""
    n = A.shape[0]
    return np.stack([C @ np.linalg.solve(zk * np.eye(n) - A, B) + D for zk in z])


def _per_point(F: np.ndarray) -> np.ndarray:
    """Each point's largest entry of a stack of matrices, for errors relative to it."""
    return np.abs(F).max(axis=(1, 2))


def _modal_frf(A, B, C, D, z: np.ndarray) -> np.ndarray:
    """:func:`_frf` in the eigenbasis of A, O(n) a point instead of an n³ solve, for the
    full-order sampled plant at 2 000 points. A is first balanced by LAPACK's diagonal
    scaling (powers of two: exact): the ZOH-sampled rotor mixes metres with metres a
    second, ‖A‖ near 1e9, where a basis change alone loses the answer's digits. Every
    50th point is checked against the dense solves, to 1e-6 of the point's largest
    entry; the callers take their peaks from dense solves as well."""
    Ab, T = scipy.linalg.matrix_balance(A, permute=False)
    d = np.diag(T)
    lam, V = np.linalg.eig(Ab)
    CV, VB = (C * d) @ V, np.linalg.solve(V, B / d[:, None])
    F = np.einsum("pn,fn,nm->fpm", CV, 1.0 / (z[:, None] - lam), VB) + D
    every = np.arange(0, z.size, 50)
    dense = _frf(A, B, C, D, z[every])
    assert (_per_point(F[every] - dense) <= 1e-6 * _per_point(dense)).all()
    return F


def _sensitivity(Gz: np.ndarray, Kz: np.ndarray) -> np.ndarray:
    """S = (I + G K)⁻¹ at each point."""
    eye = np.eye(Gz.shape[1])
    return np.linalg.solve(eye + Gz @ Kz, np.broadcast_to(eye, Gz.shape))


def runs_from_standstill_to_the_top_speed(rig: Path, metrics: dict, out: Path, method: str):
    """The run's ``method`` controller, scheduled on speed, is delivered and holds the rig
    as exported: the file's table (interpolated as it says, with its delay) closed on the
    full-order plant sampled by python-control (zero-order hold) at 17 speeds from
    standstill to the top speed and at the judged ones, every pole inside the unit
    circle; at the judged speeds the sensitivity function of the same loop, on 2 000
    frequencies up to Nyquist (in the plant's eigenbasis, :func:`_modal_frf`), its peaks
    by dense solves, below ISO 14839-3 zone B's 4 on every axis and within 5 % of the
    run's own as-runs peaks; the run's orbits inside the backup clearance (the air gap
    on a rig without one)."""
    assert method in metrics["controllers"], metrics["failed"]
    assert method not in metrics["failed"] and method not in metrics["cannot_run"]
    cfg = load_rig(rig)
    top_hz = max(cfg.operating.speed_rpm / 60.0, cfg.operating.speed_range_hz[1])
    f = np.load(out / "controllers" / f"controller_{method}.npz", allow_pickle=False)
    Ts, d = float(f["Ts"]), int(f["delay_samples"])
    assert (Ts, d) == (1 / cfg.controller.sample_rate_hz, cfg.controller.delay_samples)
    rows = [r for r in [*metrics["cases"], *metrics["stability"]]
            if r["controller"] == method]
    judged = sorted({r["speed_hz"] for r in rows})
    assert judged[0] == 0.0 and judged[-1] == pytest.approx(top_hz)
    # its files say where it was judged: the design speed and the speed range
    assert str(f["loop_holds"]) == "yes"
    assert f"{len(rows)}: 0 bar, 0–{top_hz:g} Hz" in str(f["verdict"])
    w = np.pi / Ts * np.logspace(-4, 0, 2000)[:-1]
    z = np.exp(1j * w * Ts)
    for hz in sorted({*np.linspace(0.0, top_hz, 17), *judged}):
        K = control.ss(*file_at(f, hz), Ts) * control.tf([1], [1] + [0] * d, Ts)
        plant = build_plant(cfg, speed_rpm=60.0 * hz)
        cur = plant.current_inputs()
        G = control.sample_system(control.ss(plant.A, plant.B[:, cur], plant.C,
                                             plant.D[:, cur]), Ts, "zoh")
        poles = control.feedback(G, K).poles()
        assert np.abs(poles).max() < 1, (hz, np.abs(poles).max())
        if hz not in judged:
            continue
        Gd = [np.asarray(X, float) for X in (G.A, G.B, G.C, G.D)]
        Kz = _frf(*file_at(f, hz), z) * (z ** -d)[:, None, None]
        S = _sensitivity(_modal_frf(*Gd, z), Kz)
        # each axis's peak point, its value by dense solves
        at_peak = np.abs(np.diagonal(S, axis1=1, axis2=2)).argmax(axis=0)
        S_peak = _sensitivity(_frf(*Gd, z[at_peak]), Kz[at_peak])
        per_axis = np.abs(np.diagonal(S_peak, axis1=1, axis2=2)).diagonal()
        assert per_axis.max() < ZONE_B_LIMIT, (hz, per_axis)
        row = next(r for r in rows if r["speed_hz"] == hz)
        ours = np.array(list(row["discrete"]["sensitivity_peak_per_axis"].values()))
        np.testing.assert_allclose(per_axis, ours, rtol=0.05)
        assert set(row["discrete"]["iso_zone_per_axis"].values()) <= {"A", "A/B", "B"}, row
    # the backup bearing's clearance, else (a rig that gives none) the air gap
    backup_um = min([c for c in map(cfg.backup_clearance, cfg.amb) if c is not None]
                    or [a.air_gap for a in cfg.amb]) * 1e6
    for r in (r for r in metrics["cases"] if r["controller"] == method):
        assert r["discrete"]["unbalance_peak_um"] < backup_um, r["discrete"]

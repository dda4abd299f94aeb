"""The files ``ambseal run`` exports, read back and checked by python-control, for the
tests' references: a controller file's matrices at a speed, and the unbalance force
rejection exported beside each delivered controller."""

from pathlib import Path

import control
import numpy as np

from ambseal.config import load_rig
from ambseal.export import load_notch
from ambseal.model import build_plant

from .freq_at import at


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

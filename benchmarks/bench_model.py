"""Benchmark: ambseal against ROSS on the same 40-element rotor, in one process.

Cases (one JSON line each on stdout; progress and ROSS's own chatter go to stderr):

``build_modal`` (at 0 and at 3000 rpm): the 8 lowest modes, both sides by ARPACK.
    Ours: ``parse_rig(dict)`` → ``build_system(cfg, speed_rpm=...)`` →
    ``modes(sys, n_modes=8)`` (shift-invert ARPACK on the quadratic pencil).
    ROSS: elements → ``rs.Rotor(...)`` → ``rotor.run_modal(speed, num_modes=N)`` (ARPACK,
    shift-invert at σ = 1, k = 2N eigenvalues), with N the smallest value for which ROSS
    returns 8 lateral modes (found once, untimed, in the warm-up; its model also carries
    axial and torsional DOFs, whose rigid-body eigenvalues take some of the k slots).
    Check: max relative difference of the 8 lowest damped natural frequencies (rad/s);
    ROSS's torsional/axial modes are left out by their eigenvectors.
``build_modal_all`` (at 0 and at 3000 rpm): every mode, both sides dense.
    Ours: ``modes(sys)`` (``scipy.linalg.eig`` of the state matrix). ROSS:
    ``rotor.run_modal(speed, sparse=False)`` (``scipy.linalg.eig`` of its state matrix).
    Same check.
``freq_response_1000``
    A 1000-point FRF (1–500 Hz) from the forces at the two bearing nodes to the
    displacements there (4×4). Ours: ``build_plant(cfg)`` → ``freqresp((A, B, C, D), ω)``.
    ROSS: elements → ``rs.Rotor(...)`` → ``rotor.run_freq_response(speed_range=ω,
    free_free=True)``, which solves the full 246-DOF dynamic stiffness per frequency (ROSS has
    no option to restrict the DOFs). ``free_free=True`` is ROSS's switch for a fixed spin
    speed of 0 with the bearings kept; its default (``free_free=False``) sets the spin speed
    equal to each excitation frequency, which is a different quantity. Check: max relative
    difference of |H| over the grid, entries with |H| ≥ 1e-3·max|H| only.

The rotor: uniform steel shaft, 1.5 m, Ø 50 mm, 40 Timoshenko elements (Cowper's shear
coefficient on both sides), two rigid disks (20 kg, Id 0.1, Ip 0.2 kg·m²) at nodes 13 and 27,
two bearings (k = 1e6 N/m, c = 1e3 N·s/m in x and y) at nodes 4 and 36. In ambseal each
bearing is an ``[[amb]]`` with ``ki = 1`` (input in N), ``ks = 0``, axes at 0°, collocated
sensor, plus a ``[[spring]]`` with the bearing coefficients.

Both sides are timed end to end (model build included), each repeat on a freshly built
model (ROSS caches ``run_modal``/``run_freq_response`` per rotor instance), after one
untimed warm-up call; the calls of the two tools alternate (so both see the same load on
a shared machine) and the medians are reported. BLAS runs single-threaded by default
(``--threads``): on a small, busy machine multi-threaded OpenBLAS spends most of its time
spinning, which makes every timing meaningless.

The fine-mesh cases (``--only fine``; also after the cases above by default) take the
embedded test facility (``ambseal/data/testrig.toml``) with its three ``[[shaft]]``
sections refined to 230 beam elements in all (13 + 204 + 13; 234 after the component
splits, 1 880 states):

``fine_modes_cli``
    ``ambseal modes RIG --json`` as a child process, wall and CPU time, interpreter start
    included; goal 10 s. Its first six modes against the default 34-element mesh's
    (``max_rel_diff_default_mesh``: the mesh's convergence).
``fine_modes``
    The same command's numerics in this process (CPU time): ours is what ``modes`` runs
    now — ``modes(sys)`` (dense eigenvalues of the state matrix, for every unstable pole)
    and ``open_loop_modes`` (the modes up to the limit and their shapes from the
    shift-invert path); the baseline is what it ran before, ``modes(sys)`` and
    ``modes_of_state_matrix`` (a second, dense eig with eigenvectors). ``max_rel_diff``:
    largest relative difference of the listed frequencies.
``fine_reduced_plant``
    ``build_plant(cfg, reduced=True, states=12)`` (the μ design's model), ours with the
    lowest eigenpairs by shift-invert (``ambseal.lti.lowest``), the baseline with the
    dense eig with left and right eigenvectors it used before (forced by
    ``DENSE_STATES``). ``max_rel_diff``: of the two reduced plants' frequency responses
    over 0.5 Hz–2 kHz.
``fine_ross``
    The same 230-element rotor on two plain bearings (1e6/0.8e6 N/m, 150/90 N·s/m) at the
    AMBs' positions, no seal, coupling or modal damping, at 0 and 6000 rpm: ours
    ``build_system`` → ``modes(sys)`` → ``open_loop_modes``; ROSS elements on the same
    mesh → ``rs.Rotor`` → ``_eigen(speed, num_modes=12, sparse=True)`` (its dense eig of
    2 800 states takes about a minute). ``max_rel_diff``: largest |Δλ|/|λ| of the first
    six modes.

``--fine-design`` adds ``fine_design_mu``: ``design(cfg, "mu")`` at 230 and 400 elements
(CPU time, with μ and the full-order verdict; minutes).

Run: ``PYTHONPATH=src python benchmarks/bench_model.py [--quick] [--threads N]
[--only coarse|fine] [--fine-design]``.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time


def _args() -> argparse.Namespace:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--quick", action="store_true", help="fewer repeats (smoke run)")
    ap.add_argument("--threads", type=int, default=1,
                    help="BLAS threads for both tools (default 1; 0 keeps the environment's)")
    ap.add_argument("--only", choices=("coarse", "fine"), default=None,
                    help="only the 40-element cases or only the fine-mesh ones")
    ap.add_argument("--fine-design", action="store_true",
                    help="also the μ design at 230 and 400 elements (minutes)")
    return ap.parse_args()


ARGS = _args()
if ARGS.threads > 0:  # must happen before numpy is imported
    for var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
        os.environ[var] = str(ARGS.threads)

# stdout carries only the JSON lines: keep a handle on the real stdout, then send file
# descriptor 1 (C-level prints, e.g. CoolProp's REFPROP notice on `import ross`) and
# Python's sys.stdout to stderr.
_OUT = os.fdopen(os.dup(1), "w", buffering=1)
os.dup2(2, 1)
sys.stdout = sys.stderr

import resource  # noqa: E402
import statistics  # noqa: E402
import subprocess  # noqa: E402
import tempfile  # noqa: E402
import tomllib  # noqa: E402
import warnings  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

# the fine-mesh rig and its ROSS twin are the tests' (tests/finemesh.py), imported from the
# repository root
sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from tests.finemesh import fine_bearing_data, fine_rig_text, fine_ross_rotor  # noqa: E402

# ---------------------------------------------------------------- the rotor (both sides)
N_EL = 40
LENGTH = 1.5  # m
DIAMETER = 0.05  # m
E, RHO, G_S = 211e9, 7810.0, 81.2e9  # Pa, kg/m³, Pa
DISK_NODES = (13, 27)
DISK_M, DISK_ID, DISK_IP = 20.0, 0.1, 0.2  # kg, kg·m², kg·m²
BRG_NODES = (4, 36)
KB, CB = 1e6, 1e3  # N/m, N·s/m
OMEGA = 2 * np.pi * np.linspace(1.0, 500.0, 1000)  # rad/s (ω = 0 is singular in ROSS: free axial/torsion)
MODAL_SPEEDS_RPM = (0.0, 3000.0)
N_FREQ = 8  # natural frequencies compared

EL_LEN = LENGTH / N_EL


def rig_dict() -> dict:
    """The rotor as an ambseal rig (dict, as read from TOML)."""
    zb = [n * EL_LEN for n in BRG_NODES]
    return {
        "rotor": {"beam": "timoshenko", "name": "bench40"},
        "materials": {"steel": {"E": E, "rho": RHO, "G": G_S}},
        "shaft": [{"length": LENGTH, "outer_diameter": DIAMETER, "material": "steel",
                   "elements": N_EL}],
        "disk": [{"position": n * EL_LEN, "mass": DISK_M, "Ip": DISK_IP, "Id": DISK_ID}
                 for n in DISK_NODES],
        "amb": [{"name": name, "position": z, "sensor_position": z, "axes_angle_deg": 0.0,
                 "ki": 1.0, "ks": 0.0} for name, z in zip(("A", "B"), zb)],
        "spring": [{"position": z, "kxx": KB, "kyy": KB, "cxx": CB, "cyy": CB} for z in zb],
    }


def ross_rotor(rs):
    """The same rotor in ROSS."""
    steel = rs.Material(name="bench_steel", rho=RHO, E=E, G_s=G_S)
    shaft = [rs.ShaftElement(L=EL_LEN, idl=0.0, odl=DIAMETER, material=steel, n=i,
                             shear_method_calc="cowper") for i in range(N_EL)]
    disks = [rs.DiskElement(n=n, m=DISK_M, Id=DISK_ID, Ip=DISK_IP) for n in DISK_NODES]
    brgs = [rs.BearingElement(n=n, kxx=KB, kyy=KB, cxx=CB, cyy=CB) for n in BRG_NODES]
    return rs.Rotor(shaft, disks, brgs)


# ---------------------------------------------------------------- the calls being timed
def ours_modal(speed_rpm: float, n_modes: int | None = N_FREQ):
    """Build and compute the ``n_modes`` lowest modes (every mode, dense, if None)."""
    from ambseal.config import parse_rig
    from ambseal.model.modes import modes
    from ambseal.model.rig import build_system

    return modes(build_system(parse_rig(rig_dict()), speed_rpm=speed_rpm), n_modes=n_modes)


def ross_modal(rs, speed_rpm: float, num_modes: int | None):
    """Build and run ROSS's modal analysis: ARPACK with ``num_modes``, dense if None."""
    speed = speed_rpm * np.pi / 30
    if num_modes is None:
        return ross_rotor(rs).run_modal(speed, sparse=False)
    return ross_rotor(rs).run_modal(speed, num_modes=num_modes)


def ross_num_modes(rs) -> int:
    """Smallest ``num_modes`` for which ROSS returns N_FREQ lateral modes at every speed."""
    rotor = ross_rotor(rs)
    for nm in range(N_FREQ, 4 * N_FREQ):
        if all(ross_lateral_wd(ross_modal(rs, rpm, nm), rotor.ndof, rotor.number_dof).size
               >= N_FREQ for rpm in MODAL_SPEEDS_RPM):
            return nm
    raise RuntimeError(f"ROSS returned fewer than {N_FREQ} lateral modes")


def ours_frf(omega: np.ndarray, **kw) -> np.ndarray:
    """(n_w, 4, 4): outputs A_x, A_y, B_x, B_y per input force at A, B (N)."""
    from ambseal.config import parse_rig
    from ambseal.lti.freqresp import freqresp
    from ambseal.model.rig import build_plant

    p = build_plant(parse_rig(rig_dict()), speed_rpm=0.0)
    return freqresp((p.A, p.B, p.C, p.D), omega, **kw)


def ross_frf(rs, omega: np.ndarray) -> np.ndarray:
    rotor = ross_rotor(rs)
    res = rotor.run_freq_response(speed_range=omega, free_free=True)
    nd = rotor.number_dof  # 6 per node in ROSS 2.x: [x, y, z, α, β, θ]
    idx = [nd * n + d for n in BRG_NODES for d in (0, 1)]
    return res.freq_resp[np.ix_(idx, idx)].transpose(2, 0, 1)


# ---------------------------------------------------------------- helpers
def log(msg: str) -> None:
    print(msg, file=sys.stderr, flush=True)


def timed(ours, rep_ours: int, base, rep_base: int):
    """Median wall times of ``ours()`` and ``base()`` and their last results.

    The calls alternate (ours, base, ours, base, ...; the side with more repeats finishes
    alone) so that both see the same load on a shared machine.
    """
    times: dict[str, list[float]] = {"ours": [], "ross": []}
    outs = {}
    for k in range(max(rep_ours, rep_base)):
        for label, fn, reps in (("ours", ours, rep_ours), ("ross", base, rep_base)):
            if k >= reps:
                continue
            t0 = time.perf_counter()
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                outs[label] = fn()
            times[label].append(time.perf_counter() - t0)
            log(f"  {label}: run {k + 1}/{reps}: {times[label][-1]:.4f} s")
    return (statistics.median(times["ours"]), outs["ours"],
            statistics.median(times["ross"]), outs["ross"])


def ross_lateral_wd(modal, ndof: int, number_dof: int) -> np.ndarray:
    """Damped natural frequencies (rad/s, ascending) of ROSS's lateral modes.

    ROSS 2.x nodes carry [x, y, z, α, β, θ]; a mode counts as lateral when most of its
    displacement-part energy lies on x, y, α, β (leaves out torsional and axial modes).
    """
    lam, vec = np.asarray(modal.evalues), np.asarray(modal.evectors)[:ndof]
    lat = np.array([i for i in range(ndof) if i % number_dof in (0, 1, 3, 4)])
    frac = np.sum(np.abs(vec[lat]) ** 2, axis=0) / np.sum(np.abs(vec) ** 2, axis=0)
    keep = (lam.imag > 1e-6) & (frac > 0.5)
    return np.sort(lam.imag[keep])


def modal_diff(rs, m, mr) -> dict:
    """Agreement of the N_FREQ lowest damped natural frequencies of ours and ROSS's."""
    rotor = ross_rotor(rs)
    wd_ours = 2 * np.pi * np.asarray(m.natural_frequencies_hz[:N_FREQ])
    wd_ross = ross_lateral_wd(mr, rotor.ndof, rotor.number_dof)[:N_FREQ]
    n = min(wd_ours.size, wd_ross.size)
    diff = float(np.max(np.abs(wd_ours[:n] - wd_ross[:n]) / wd_ross[:n]))
    return {"max_rel_diff": diff, "n_compared": n,
            "lowest_hz": [round(x / (2 * np.pi), 4) for x in wd_ross[:n]]}


def frf_diff(ours: np.ndarray, base: np.ndarray, floor: float = 1e-3) -> float:
    """max | |H_ours| − |H_base| | / |H_base| over entries with |H_base| ≥ floor·max|H_base|."""
    a, b = np.abs(ours), np.abs(base)
    mask = b >= floor * b.max()
    return float(np.max(np.abs(a[mask] - b[mask]) / b[mask]))


def emit(rec: dict) -> None:
    _OUT.write(json.dumps(rec) + "\n")
    _OUT.flush()


# ---------------------------------------------------------------- the fine mesh
FINE_ELEMENTS = 230
FINE_SPEEDS_RPM = (0.0, 6000.0)
N_FINE = 6  # modes compared


def fine_bearing_cfg(total: int):
    """The fine rotor on plain bearings at the AMBs' positions (the ROSS comparison)."""
    from ambseal.config import parse_rig

    return parse_rig(fine_bearing_data(total))


#: 1.25× the test rig's third free–free bending frequency: the limit ``modes`` lists to.
FINE_MAX_HZ = 2931.0


def ours_open_loop(sys_, before: bool = False):
    """What ``ambseal modes`` computes without a controller (``before``: the dense eig
    with eigenvectors it used until the fine-mesh change)."""
    from ambseal.analysis.campbell import modes_of_state_matrix, open_loop_modes
    from ambseal.model.modes import modes

    res = modes(sys_)
    kw = {"speed_hz": sys_.speed / (2 * np.pi), "pressure_bar": 0.0, "max_hz": FINE_MAX_HZ}
    if before:
        return modes_of_state_matrix(sys_.state_matrices()[0], sys_.mesh, **kw)
    return open_loop_modes(sys_, judged_poles=res.poles, **kw)


def cpu_timed(fn, reps: int):
    """Median CPU time (this process) of ``fn()`` and its last result."""
    times, out = [], None
    for _ in range(reps):
        t0 = time.process_time()
        out = fn()
        times.append(time.process_time() - t0)
    return statistics.median(times), out


def child_timed(args: list[str], reps: int):
    """Median wall and CPU time (children's user + system) of a child process."""
    walls, cpus, out = [], [], None
    for _ in range(reps):
        r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
        t0 = time.perf_counter()
        proc = subprocess.run(args, capture_output=True, text=True, check=True)
        walls.append(time.perf_counter() - t0)
        r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
        cpus.append(r1.ru_utime - r0.ru_utime + r1.ru_stime - r0.ru_stime)
        out = proc.stdout
    return statistics.median(walls), statistics.median(cpus), out


def fine_cases(reps: int) -> None:
    import ambseal.lti.lowest as low
    from ambseal.config import default_rig_path, load_rig, parse_rig
    from ambseal.lti.freqresp import freqresp
    from ambseal.model.rig import build_plant, build_system

    common = {"n_elements": FINE_ELEMENTS, "blas_threads": ARGS.threads or None}
    with tempfile.TemporaryDirectory() as tmp:
        rig = Path(tmp) / f"testrig_{FINE_ELEMENTS}.toml"
        rig.write_text(fine_rig_text(FINE_ELEMENTS), encoding="utf-8")
        log(f"case fine_modes_cli ({FINE_ELEMENTS} elements)")
        cmd = [sys.executable, "-m", "ambseal.cli", "modes"]
        wall, cpu, out = child_timed(cmd + [str(rig), "--json"], reps)
        fine = json.loads(out)["natural_frequencies_hz"][:N_FINE]
        _, _, out = child_timed(cmd + [str(default_rig_path()), "--json"], 1)
        coarse = json.loads(out)["natural_frequencies_hz"][:N_FINE]
        emit({"case": "fine_modes_cli", "ours_s": wall, "ours_cpu_s": cpu, "goal_s": 10.0,
              "meets_goal": wall < 10.0, "call": "ambseal modes RIG --json",
              "max_rel_diff_default_mesh": float(np.max(np.abs(np.subtract(fine, coarse))
                                                        / np.abs(coarse))),
              "first_modes_hz": [round(x, 4) for x in fine], **common})
        cfg = load_rig(rig)

    log("case fine_modes (in process, CPU)")
    sys_ = build_system(cfg)
    t_ours, m = cpu_timed(lambda: ours_open_loop(sys_), reps)
    t_base, mb = cpu_timed(lambda: ours_open_loop(sys_, before=True), reps)
    emit({"case": "fine_modes", "ours_s": t_ours, "baseline": "ambseal before (dense eig "
          "with eigenvectors)", "baseline_s": t_base, "ratio": t_base / t_ours,
          "max_rel_diff": float(np.max(np.abs(m.frequency_hz - mb.frequency_hz)
                                       / mb.frequency_hz)),
          "n_modes": int(m.frequency_hz.size), "max_hz": FINE_MAX_HZ, **common})

    log("case fine_reduced_plant (CPU)")
    w = 2 * np.pi * np.logspace(np.log10(0.5), np.log10(2000.0), 200)
    t_ours, p = cpu_timed(lambda: build_plant(cfg, reduced=True, states=12), reps)
    dense_states, low.DENSE_STATES = low.DENSE_STATES, 10**9
    try:
        t_base, pb = cpu_timed(lambda: build_plant(cfg, reduced=True, states=12), reps)
    finally:
        low.DENSE_STATES = dense_states
    H, Hb = (freqresp((q.A, q.B, q.C, q.D), w) for q in (p, pb))
    emit({"case": "fine_reduced_plant", "ours_s": t_ours,
          "baseline": "ambseal before (dense eig, left and right eigenvectors)",
          "baseline_s": t_base, "ratio": t_base / t_ours,
          "max_rel_diff": float(np.max(np.abs(H - Hb)) / np.max(np.abs(Hb))),
          "states": 12, **common})

    log("case fine_ross")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        import ross as rs
    baseline = "ross " + ".".join(rs.__version__.split(".")[:2])
    bcfg = fine_bearing_cfg(FINE_ELEMENTS)
    for rpm in FINE_SPEEDS_RPM:
        def ours():
            return ours_open_loop(build_system(bcfg, speed_rpm=rpm))

        def ross():
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                return fine_ross_rotor(rs, bcfg)[0]._eigen(rpm * np.pi / 30, num_modes=12,
                                                         sparse=True)[0]

        t_ours, m, t_base, ref = timed(ours, max(1, reps // 2), ross, 1)
        lam = m.poles[:N_FINE]
        ref = np.asarray(ref)
        near = ref[np.abs(ref[None, :] - lam[:, None]).argmin(axis=1)]
        emit({"case": "fine_ross", "speed_rpm": rpm, "ours_s": t_ours, "baseline": baseline,
              "baseline_s": t_base, "ratio": t_base / t_ours,
              "max_rel_diff": float(np.max(np.abs(lam - near) / np.abs(near))),
              "first_modes_hz": [round(float(x), 4) for x in lam.imag / (2 * np.pi)],
              "baseline_call": "_eigen(speed, num_modes=12, sparse=True)", **common})

    if ARGS.fine_design:
        from ambseal.design.recipes import design

        for n in (FINE_ELEMENTS, 400):
            log(f"case fine_design_mu ({n} elements)")
            c = parse_rig(tomllib.loads(fine_rig_text(n)))
            t, r = cpu_timed(lambda: design(c, "mu"), 1)
            emit({"case": "fine_design_mu", "n_elements": n, "ours_s": t, "mu": r.mu,
                  "mu_full": (r.reduction or {}).get("mu_full"),
                  "full_order_stable": r.full_order["stable"],
                  "blas_threads": ARGS.threads or None})


# ---------------------------------------------------------------- main
def main() -> int:
    rep_ours = 3 if ARGS.quick else 9
    if ARGS.only != "fine":
        coarse_cases(rep_ours)
    if ARGS.only != "coarse":
        fine_cases(1 if ARGS.quick else 3)
    return 0


def coarse_cases(rep_ours: int) -> None:
    rep_modal = 3 if ARGS.quick else 9
    rep_frf = 1 if ARGS.quick else 3

    t0 = time.perf_counter()
    import ambseal.config  # noqa: F401
    import ambseal.lti.freqresp  # noqa: F401
    import ambseal.model.modes  # noqa: F401
    import ambseal.model.rig  # noqa: F401
    log(f"import ambseal (model, modes, freqresp): {time.perf_counter() - t0:.2f} s")
    t0 = time.perf_counter()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        import ross as rs
    log(f"import ross {rs.__version__}: {time.perf_counter() - t0:.2f} s")
    baseline = "ross " + ".".join(rs.__version__.split(".")[:2])
    common = {"n_elements": N_EL, "blas_threads": ARGS.threads or None,
              "repeats_ours": rep_ours}

    # warm-up (first calls pay for lazy imports and caches), untimed
    t0 = time.perf_counter()
    ours_modal(0.0)
    ours_modal(0.0, None)
    ours_frf(OMEGA[:5])
    log(f"warm-up ours: {time.perf_counter() - t0:.2f} s")
    t0 = time.perf_counter()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        num_modes = ross_num_modes(rs)
        ross_modal(rs, 0.0, None)
        ross_frf(rs, OMEGA[:5])
    log(f"warm-up ROSS: {time.perf_counter() - t0:.2f} s (num_modes={num_modes})")

    for case, n_ours, n_ross, call in [
        ("build_modal", N_FREQ, num_modes, f"run_modal(speed, num_modes={num_modes})"),
        ("build_modal_all", None, None, "run_modal(speed, sparse=False)"),
    ]:
        for rpm in MODAL_SPEEDS_RPM:
            log(f"case {case} at {rpm:g} rpm")
            t_ours, m, t_base, mr = timed(lambda: ours_modal(rpm, n_ours), rep_ours,
                                          lambda: ross_modal(rs, rpm, n_ross), rep_modal)
            emit({"case": case, "speed_rpm": rpm, "ours_s": t_ours, "baseline": baseline,
                  "baseline_s": t_base, "ratio": t_base / t_ours,
                  **modal_diff(rs, m, mr), "ours_call": f"modes(sys, n_modes={n_ours})",
                  "baseline_call": call, "repeats_baseline": rep_modal, **common})

    log("case freq_response_1000")
    t_ours, H, t_base, Hr = timed(lambda: ours_frf(OMEGA), rep_ours,
                                  lambda: ross_frf(rs, OMEGA), rep_frf)
    # the same comparison with ambseal's modal evaluation forced (untimed, diagnostic)
    H_modal = ours_frf(OMEGA, method="modal")
    emit({"case": "freq_response_1000", "ours_s": t_ours, "baseline": baseline,
          "baseline_s": t_base, "ratio": t_base / t_ours, "max_rel_diff": frf_diff(H, Hr),
          "max_rel_diff_method_modal": frf_diff(H_modal, Hr),
          "n_freq": int(OMEGA.size), "f_hz": [1.0, 500.0], "shape": list(H.shape),
          "baseline_call": "run_freq_response(speed_range=w, free_free=True)",
          "repeats_baseline": rep_frf, **common})


if __name__ == "__main__":
    sys.exit(main())

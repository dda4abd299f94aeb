"""Ki by static loading (thesis P2 §5), and its use beside the closed-loop fit.

The rotor is levitated at its reference position and known static forces are applied (a
load cell on a calibration clamp, or known masses); in static equilibrium the integral
action holds the sensors at zero, so the rotor does not move, the Ks·x term vanishes and
the bearing forces are Ki·i alone. Summing forces and moments on the rotor (four equations
per load step: force and moment in x and in y; here the FE model's statics, which reduce
to them for a rigid rotor: :func:`static_ki`) gives A·Ki = b, solved by least squares
(P2 §5: "A is a 4n × 4 matrix of measured control currents ... b a 4n × 1 vector containing
the external forces"). The interval is the cluster-robust (sandwich) one, clustered by load
step (Liang & Zeger, *Biometrika* 73, 1986; Cameron & Miller, *J. Human Resources* 50,
2015): a load-cell error enters all four equations of its step at once, and scales every Ki
the step loads alike (the currents fix the Ki's ratios, the force only their scale), so the
ordinary σ̂²(AᵀA)⁻¹ of independent equations would be wrong. On the test rig's virtual
facility it reported A's Ki interval half the spread over repeated programmes and the ζ and η
Ki as uncorrelated, where they move together (correlation 1.00 over 60 programmes).

Joined with the closed-loop fit (:func:`join_static`): the two estimates are independent,
so their joint estimate is the generalised least-squares combination, the Gauss–Newton
step of the joint cost at the dynamic optimum (Bard, *Nonlinear Parameter Estimation*,
1974, §7-5: prior information), written in the covariance (Kalman) form so that directions
the static test fixes exactly (the Ki's ratios, on the noise-free currents of the virtual
facility) need no inverse. The dynamic fit cannot separate Ki from Ks with the controller
known (a change of Ki looks like a change of the loop gain that Ks almost mimics, P4 Table
2: −0.95); the static Ki, which does not involve Ks at all, fixes Ki and so lowers that
correlation, by as much as its precision allows: for one Ki–Ks pair of correlation ρ, a
static Ki r times more precise than the dynamic one leaves ρ/√(1 + (1 − ρ²) r²).
:func:`programme_repeats` sizes the programme from that.

Record file (CSV, one row per load step, each the mean over its hold): ``position_m``,
``force_x_n``, ``force_y_n`` and ``current_<axis>_a`` for every actuator axis
(``current_A_zeta_a``, ...): the control-current change from the unloaded state (A).
"""

from __future__ import annotations

import io
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from ambseal.config import RigConfig, TruthSection
from ambseal.errors import ConfigError, DataError
from ambseal.files import atomic_write, read_text
from ambseal.identify.fitting.fit import FitResult
from ambseal.identify.facility.rig_sim import true_rig
from ambseal.model import (
    amb_factors,
    build_system,
    channel_names,
    coefficient_value,
    mechanical_plant,
)

__all__ = ["StaticLoadResult", "static_ki", "load_steps", "virtual_static_load", "load_static_record",
           "save_static_record", "join_static", "with_static", "with_static_record",
           "programme_repeats"]


@dataclass(frozen=True)
class StaticLoadResult:
    """Ki per actuator axis from static loading.

    Attributes
    ----------
    names : tuple of str
        ``{amb}.Ki_{axis}``.
    estimate, std_error : ndarray (4 per AMB,)
        N/A.
    correlation : ndarray
    residual_std_m : float
        Standard deviation of the equilibrium residuals, as sensor displacement (m) the
        loads and currents leave unexplained.
    steps : int
        Load steps.
    """

    names: tuple[str, ...]
    estimate: np.ndarray
    std_error: np.ndarray
    correlation: np.ndarray
    residual_std_m: float
    steps: int

    def to_dict(self) -> dict:
        return {"method": "static load (P2 §5)", "steps": self.steps,
                "residual_std_m": self.residual_std_m,
                "parameters": {n: {"estimate": float(e), "std_error": float(s),
                                   "ci95": [float(e - 1.96 * s), float(e + 1.96 * s)]}
                               for n, e, s in zip(self.names, self.estimate, self.std_error)},
                "correlation": self.correlation.tolist()}


def static_ki(cfg: RigConfig, position_m: np.ndarray, force_xy_n: np.ndarray,
              current_a: np.ndarray, *, values: dict | None = None,
              source: str = "static load") -> StaticLoadResult:
    """Ki of every actuator axis from load steps in static equilibrium (P2 §5).

    The thesis sums forces and moments on a rigid rotor (Ks·x = 0). Here the same four
    equations per step come from the rig's FE model in statics: with the sensors held at
    zero, y = Σ_j Ki_j g_j i_j + G_F F = 0, g_j the static sensor response to a unit force
    along axis j at its bearing and G_F to the load, both −C A⁻¹ B of the full-order
    model (rigid-body balance for a rigid rotor; with the shaft's bending under the load
    the bearings move a little, and Ks and the coupling then carry some of it: on the test
    rig the rigid-body balance reads Ki 0.7 % low, the FE statics 0.01 %).

    Parameters
    ----------
    cfg : RigConfig
        The rig (geometry; Ks, coupling and other stiffnesses as in ``values``).
    position_m : ndarray (n,)
        Axial position of each step's load (m).
    force_xy_n : ndarray (n, 2)
        Applied force in x, y (N).
    current_a : ndarray (n, n_axes)
        Control-current change per axis (A), in :func:`~ambseal.model.amb.channel_names`
        order.
    values : dict, optional
        Parameter values (SI) found earlier, e.g. the closed-loop fit's Ks and coupling
        stiffness (Ki's and τ_e in it are ignored).
    source : str
        Where the loads come from, named in errors.

    Returns
    -------
    StaticLoadResult
        Ki (N/A) per axis with its cluster-robust standard errors (clustered by load step)
        and correlation, and the residual of the equilibrium equations (m).

    Raises
    ------
    DataError
        Mismatched shapes, or loads that leave an axis' Ki undetermined.
    """

    axes = channel_names(cfg)
    k = len(axes)
    z = np.asarray(position_m, float)
    F = np.asarray(force_xy_n, float)
    i = np.asarray(current_a, float)
    n = z.size
    if F.shape != (n, 2) or i.shape != (n, k):
        raise DataError(f"{source}: expected forces (n, 2) and currents (n, {k}), got "
                        f"{F.shape} and {i.shape}")
    names = tuple(f"{a.rsplit('_', 1)[0]}.Ki_{a.rsplit('_', 1)[1]}" for a in axes)
    rows_A, rows_b = [], []
    for pos in np.unique(z):
        plant = mechanical_plant(build_system(cfg, pressure_bar=0.0, speed_rpm=0.0,
                                              force_positions=(float(pos),)))
        keep = {m: v for m, v in (values or {}).items()
                if m in plant.parameters and ".Ki_" not in m}
        plant = plant.with_values(keep)
        G = -plant.C @ np.linalg.solve(plant.A, plant.B)  # static gain (k, k + 2)
        g = G[:, :k] / np.array([plant.parameter(m).nominal for m in names])
        for s in np.flatnonzero(z == pos):
            rows_A.append(g * i[s])
            rows_b.append(-G[:, k:k + 2] @ F[s])
    A, b = np.stack(rows_A), np.stack(rows_b)  # (steps, equations, k), (steps, equations)
    scale = np.abs(b).max() or 1.0
    A, b = A / scale, b / scale
    Af, bf = A.reshape(-1, k), b.reshape(-1)
    if n < 2 or np.linalg.matrix_rank(Af) < k:
        raise DataError(f"{source}: the load steps leave some Ki undetermined (load every "
                        "actuator axis, in both directions)")
    est, *_ = np.linalg.lstsq(Af, bf, rcond=None)
    r = b - A @ est
    bread = np.linalg.inv(Af.T @ Af)
    u = np.einsum("sek,se->sk", A, r)  # each step's score: its equations' errors together
    cov = bread @ (u.T @ u) @ bread * n / (n - 1)
    se = np.sqrt(np.diag(cov))
    return StaticLoadResult(names, est, se, cov / np.outer(se, se),
                            float(np.sqrt(float(r.ravel() @ r.ravel()) / max(r.size - k, 1))
                                  * scale), n)


def load_steps(cfg: RigConfig, steps_per_direction: int = 5, position_m: float | None = None
               ) -> tuple[np.ndarray, np.ndarray]:
    """The thesis's load programme: ``steps_per_direction`` steps up and back down in each of
    the four directions ±x, ±y (P2 §5: "spanning both increasing and decreasing external
    loads in all four loading directions"), at the mid-point between the bearings (the
    calibration clamp at the shaft's centre, P2 Fig. 1d) unless ``position_m`` is given.
    With more than two AMBs the programme runs at the mid-point of each pair of
    neighbouring AMBs in turn: loads at one position fix only two of three bearing forces
    in a plane (force and moment balance), loads at two positions fix all of them.

    The largest load is the force both AMBs make together with a quarter of the smallest
    bias current (or current limit) of the rig file, with its smallest Ki: well within the
    linear range, the calibration's own (P2 §5 loads with 6–10 A bias).
    """
    ki = min(min(amb_factors(a)[0]) for a in cfg.amb)
    i_ref = [a.bias_current or a.current_limit for a in cfg.amb
             if (a.bias_current or a.current_limit)]
    if not i_ref:
        raise ConfigError("amb: bias_current or current_limit is needed to size the static "
                          "loads")
    f_max = 0.25 * min(i_ref) * ki * len(cfg.amb)
    up = np.linspace(f_max / steps_per_direction, f_max, steps_per_direction)
    levels = np.concatenate([up, up[::-1][1:]])
    F = []
    for d in (np.array([1.0, 0]), np.array([-1.0, 0]), np.array([0, 1.0]), np.array([0, -1.0])):
        F += [lv * d for lv in levels]
    if position_m is not None:
        zs = [float(position_m)]
    else:
        at = sorted(a.position for a in cfg.amb)
        zs = [0.5 * (a + b) for a, b in zip(at[:-1], at[1:])] or [float(at[0])]
    F = np.array(F)
    return np.repeat(zs, len(F)), np.tile(F, (len(zs), 1))


def virtual_static_load(cfg: RigConfig, truth: TruthSection, *, seed: int = 0,
                        force_noise_fraction: float = 0.005, steps_per_direction: int = 5,
                        repeats: int = 5, position_m: float | None = None
                        ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Static load steps on the virtual facility: the full-order FE rotor with the truth's
    values, in equilibrium with each load and the sensors held at zero (integral action).

    The forces are as a load cell reads them (Gaussian error of ``force_noise_fraction`` of
    the reading; 0.5 % is a class-0.5 transducer) and the currents as the amplifiers'
    sensors average them over a one-second hold (the truth's ``current_noise_a`` over
    √(sample rate) samples). The programme of :func:`load_steps` runs ``repeats`` times
    (P2 §5 repeats it five times).

    Parameters
    ----------
    cfg : RigConfig
        The rig file.
    truth : TruthSection
        The facility's truth.
    seed : int, optional
        Seed of the noise.
    force_noise_fraction : float, optional
        Standard deviation of the load cell's error, as a fraction of the reading.
    steps_per_direction : int, optional
        Load steps in each direction (:func:`load_steps`).
    repeats : int, optional
        Runs of the programme.
    position_m : float, optional
        Axial position of the load (m); default: mid-way between the bearings
        (:func:`load_steps`).

    Returns
    -------
    position_m : numpy.ndarray, shape (n,)
        Axial position of each load (m).
    force_xy_n : numpy.ndarray, shape (n, 2)
        The load as read, x and y (N).
    current_a : numpy.ndarray, shape (n, n_axes)
        The mean coil current of each axis (A).
    """

    z, F = load_steps(cfg, steps_per_direction, position_m)
    z, F = np.tile(z, repeats), np.tile(F, (repeats, 1))
    rng = np.random.default_rng(seed)
    cfg_t = true_rig(cfg, truth)
    k = 2 * len(cfg.amb)
    out = np.zeros((len(z), k))
    values = {n: coefficient_value(v, 0.0) for n, v in truth.parameters.items()}
    for pos in np.unique(z):
        plant = mechanical_plant(build_system(cfg_t, pressure_bar=0.0, speed_rpm=0.0,
                                              force_positions=(float(pos),)))
        plant = plant.with_values(values)
        A, B, C = plant.A, plant.B, plant.C
        # [A B_i; C 0] [x; i] = [-B_F F; 0]: equilibrium with the sensors at zero
        M = np.block([[A, B[:, :k]], [C, np.zeros((C.shape[0], k))]])
        rows = np.flatnonzero(z == pos)
        rhs = np.vstack([-B[:, k:k + 2] @ F[rows].T, np.zeros((C.shape[0], rows.size))])
        out[rows] = np.linalg.solve(M, rhs)[-k:].T
    fs = cfg.controller.sample_rate_hz
    out += rng.standard_normal(out.shape) * truth.current_noise_a / np.sqrt(fs)
    F_meas = F * (1.0 + force_noise_fraction * rng.standard_normal(F.shape))
    return z, F_meas, out


def save_static_record(path: str | Path, cfg: RigConfig, position_m, force_xy_n, current_a
                       ) -> Path:
    """Write load steps as the CSV :func:`load_static_record` reads (temp name, rename).

    Parameters
    ----------
    path : str or Path
        The CSV file.
    cfg : RigConfig
        The rig (its axes name the current columns).
    position_m : array_like, shape (n,)
        Axial position of each load (m).
    force_xy_n : array_like, shape (n, 2)
        The load, x and y (N).
    current_a : array_like, shape (n, n_axes)
        The mean coil current of each axis (A).

    Returns
    -------
    Path
        The file written.
    """
    axes = channel_names(cfg)
    head = ["position_m", "force_x_n", "force_y_n"] + [f"current_{a}_a" for a in axes]
    data = np.column_stack([position_m, force_xy_n, current_a])
    buf = io.StringIO()
    np.savetxt(buf, data, delimiter=",", header=",".join(head), comments="", fmt="%.10g")
    return atomic_write(path, lambda f: f.write(buf.getvalue().encode()))


def load_static_record(path: str | Path, cfg: RigConfig
                       ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Read a static-load CSV (module docstring); DataError naming the file and column."""
    text = read_text(path, "static-load record")
    lines = [ln for ln in text.splitlines() if ln.strip()]
    if not lines:
        raise DataError(f"{path}: empty static-load record")
    head = [h.strip() for h in lines[0].split(",")]
    need = ["position_m", "force_x_n", "force_y_n"] + [f"current_{a}_a"
                                                       for a in channel_names(cfg)]
    missing = [c for c in need if c not in head]
    if missing:
        raise DataError(f"{path}: column(s) {', '.join(missing)} missing (expected "
                        f"{', '.join(need)})")
    try:
        data = np.array([[float(x) for x in ln.split(",")] for ln in lines[1:]], ndmin=2)
    except ValueError as exc:
        raise DataError(f"{path}: {exc}") from None
    if data.size == 0 or not np.all(np.isfinite(data)):
        raise DataError(f"{path}: expected finite numbers in every row")
    col = {h: j for j, h in enumerate(head)}
    pick = lambda names: data[:, [col[c] for c in names]]  # noqa: E731
    return (pick(["position_m"])[:, 0], pick(["force_x_n", "force_y_n"]), pick(need[3:]))


def join_static(dynamic: FitResult, static: StaticLoadResult) -> FitResult:
    """The closed-loop fit joined with the static Ki (module docstring): generalised least
    squares of the two independent estimates, in covariance form θ = θ_d + K (k_s − H θ_d),
    P = Σ_d − K H Σ_d, K = Σ_d Hᵀ (H Σ_d Hᵀ + Σ_s)⁻¹, H selecting the Ki's from θ (equal to
    P = (Σ_d⁻¹ + Hᵀ Σ_s⁻¹ H)⁻¹ where Σ_s is invertible; valid where it is not). Parameters
    the fit does not have are ignored; the result's intervals and correlation are P's."""
    names = list(dynamic.names)
    use = [j for j, n in enumerate(static.names) if n in names]
    if not use:
        return dynamic
    H = np.zeros((len(use), len(names)))
    for r, j in enumerate(use):
        H[r, names.index(static.names[j])] = 1.0
    Sd = dynamic.correlation * np.outer(dynamic.std_error, dynamic.std_error)
    Ss = (static.correlation * np.outer(static.std_error, static.std_error))[np.ix_(use, use)]
    gain = np.linalg.solve(H @ Sd @ H.T + Ss, H @ Sd).T
    est = dynamic.estimate + gain @ (static.estimate[use] - H @ dynamic.estimate)
    P = Sd - gain @ H @ Sd
    P = (P + P.T) / 2
    se = np.sqrt(np.diag(P))
    return replace(dynamic, estimate=est, std_error=se, ci95_low=est - 1.96 * se,
                   ci95_high=est + 1.96 * se, correlation=P / np.outer(se, se))


def programme_repeats(dynamic: FitResult, static: StaticLoadResult, repeats: int, *,
                      precision_ratio: float = 2.0, max_repeats: int = 100) -> int:
    """How many times to run the load programme so that every static Ki is
    ``precision_ratio`` times more precise than the closed-loop fit's (``static`` is the
    result of ``repeats`` programmes; its errors fall as 1/√repeats).

    The rule: with r = σ_dynamic/σ_static ≥ 2 the static Ki carries at least 4/5 of the
    joined Ki's weight, and for a single Ki–Ks pair a correlation ρ of the closed-loop fit
    falls to ρ/√(1 + 4(1 − ρ²)) (module docstring): 0.93 → 0.75, 0.95 → 0.80. (With the
    static Ki's moving together, a little less: on the test rig B ζ 0.93 → 0.78.) A larger
    load range does not help where the load cell's error is a fraction of the reading (P2 §5
    loads within the linear range); only more readings do. Capped at ``max_repeats``.

    Returns
    -------
    int
        Programmes to run, at least ``repeats``.
    """
    n = list(dynamic.names)
    worst = max((static.std_error[j] / dynamic.std_error[n.index(m)]) ** 2
                for j, m in enumerate(static.names) if m in n)
    return int(min(max_repeats, max(repeats, np.ceil(repeats * worst * precision_ratio**2))))


def with_static(dynamic: FitResult, static: StaticLoadResult) -> tuple[FitResult, dict]:
    """:func:`join_static`, and a JSON summary: the static result with the Ki–Ks
    correlation of each axis in the closed-loop fit alone and joined."""
    joined = join_static(dynamic, static)

    def ki_ks(res: FitResult) -> dict:
        n = list(res.names)
        return {k: float(res.correlation[n.index(k), n.index(k.replace(".Ki_", ".Ks_"))])
                for k in static.names if k in n and k.replace(".Ki_", ".Ks_") in n}

    return joined, {**static.to_dict(), "ki_ks_correlation_dynamic": ki_ks(dynamic),
                    "ki_ks_correlation_joined": ki_ks(joined)}


def with_static_record(cfg: RigConfig, dynamic: FitResult, path: str | Path
                       ) -> tuple[FitResult, dict]:
    """:func:`with_static` of the load steps in ``path`` (:func:`load_static_record`),
    Ki found by :func:`static_ki` at the closed-loop fit's values of the other parameters.

    Parameters
    ----------
    cfg : RigConfig
        The rig.
    dynamic : FitResult
        The closed-loop fit.
    path : str or Path
        The static-load CSV.

    Returns
    -------
    joined : FitResult
        The closed-loop fit with the static Ki joined.
    summary : dict
        The static result and the Ki–Ks correlations, alone and joined (JSON-ready).
    """
    return with_static(dynamic, static_ki(cfg, *load_static_record(path, cfg),
                                          values=dict(zip(dynamic.names, dynamic.estimate)),
                                          source=str(path)))

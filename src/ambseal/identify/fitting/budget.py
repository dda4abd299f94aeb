"""The parameters a fit holds fixed: their stated uncertainty and the error budget they add.

A fit of θ depends on every other value of the model — a coupling stiffness, the seal's
coefficients, τ_e when it is not fitted — held at the rig file's number. If such a value φ is
off by Δφ, the estimate moves by the sensitivity

    ∂θ̂/∂φ = −(JᵀJ)⁻¹ Jᵀ J_φ,

J = ∂r/∂θ and J_φ = ∂r/∂φ the residuals' Jacobians at the optimum (the implicit-function
theorem on the normal equations Jᵀr(θ̂, φ) = 0 in the Gauss–Newton approximation: the
first-order bias of a least-squares estimate with a wrong fixed input). With a relative 1σ uncertainty σ_φ per fixed value, the estimate carries the
added covariance G diag(σ_φ²) Gᵀ, G = ∂θ̂/∂(φ/φ₀), which enters the reported intervals
beside the noise covariance. Each fixed value's share of a parameter's variance is its
error budget.

Which fixed value is wrong — the data's answer
----------------------------------------------
The budget is a prior statement: it names the values whose *stated* uncertainty matters,
right or wrong. Whether the data disagree with a fixed value is a separate question, the
score (Lagrange-multiplier) test: the cost's gradient in φ_j at the optimum with θ free,
g_j = J_φ⊥ᵀ r (J_φ projected off the columns of J), over its standard deviation from the
residuals' long-run covariance — N(0, 1) when the fixed value is right — and the one-step
estimate −g_j / ‖J_φ⊥,j‖² of the offset the data suggest. Fixed values beyond the
Bonferroni bound at 1 % are ``disputed`` and named first.

Where the σ_φ come from
-----------------------
An ``uncertainty = { key = σ }`` table beside the values in the rig file (σ relative, e.g.
``[[spring]] … uncertainty = { kxx = 0.04, kyy = 0.04 }``; keys: an AMB's ``Ki_zeta``,
``Ki_eta``, ``Ks_zeta``, ``Ks_eta`` or ``Ki``/``Ks`` for both axes; a spring's
``kxx, kyy, kxy, kyx, cxx, cyy``; a seal's ``K, k, C, c``; ``[actuator]``'s
``eddy_time_constant``), else :data:`DEFAULT_UNCERTAINTY` per kind. A value of zero carries
no uncertainty in this relative form (a seal's pressure-driven K, k at 0 bar, say).

Values an earlier fit found (``known`` of :func:`ambseal.identify.fitting.stages.identify` with
that fit's result, as the procedure of ``ambseal run`` does from stage to stage) carry that
fit's standard errors *and correlations*: their block of the fixed values' covariance is the
earlier fit's, C = diag(σ) R diag(σ), and the added covariance is G C Gᵀ. The shares below
use the diagonal (each value's σ alone). Such a value is disputed when the offset the data
suggest is beyond its own interval: the score statistic over √(se² + σ²) of the offset.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.stats import norm

from ambseal.errors import ConfigError

__all__ = ["DEFAULT_UNCERTAINTY", "ErrorBudget", "fixed_uncertainty", "propagate", "kind_of"]

#: Relative 1σ of a value the fit holds fixed, per kind, when the rig file states none.
#:
#: - ``force_factor`` (Ki, Ks not fitted) 5 %: the thesis's repeated tests scatter by
#:   1.1–2.4 % (P2 Table 2), and a value from the AMB's geometry misses saturation and
#:   leakage by more;
#: - ``spring_stiffness`` 5 %: a coupling's catalogue or bench value (the thesis identifies
#:   it in closed loop, P4 Table 3, because the catalogue value does not hold in place);
#: - ``spring_damping`` 50 %: rarely measured at all;
#: - ``seal`` 30 %: seal coefficients come from bulk-flow predictions that commonly differ
#:   from measured ones by tens of per cent, which is why the thesis identifies them
#:   (P4 §3.5, P5 §3.3);
#: - ``tau_e`` 50 %: the eddy-current lag is an identified, not a designed, quantity (P2 §4).
DEFAULT_UNCERTAINTY = {"force_factor": 0.05, "spring_stiffness": 0.05, "spring_damping": 0.5,
                       "seal": 0.30, "tau_e": 0.50}

_SPRING_KEYS = ("kxx", "kyy", "kxy", "kyx", "cxx", "cyy")
_SEAL_KEYS = ("K", "k", "C", "c")


def kind_of(cfg, name: str) -> str:
    """The kind of parameter ``name`` (a key of :data:`DEFAULT_UNCERTAINTY`)."""
    if name == "tau_e":
        return "tau_e"
    owner, _, key = name.rpartition(".")
    if owner in {s.name for s in cfg.seal}:
        return "seal"
    if key in _SPRING_KEYS:
        return "spring_damping" if key.startswith("c") else "spring_stiffness"
    return "force_factor"


def _stated(cfg) -> dict[str, tuple[float, str]]:
    """{parameter name: (σ, where stated)} from the rig file's ``uncertainty`` tables;
    ConfigError naming an unknown key."""
    out = {}

    def take(table, where: str, owner: str, keys: tuple, alias=None):
        for key, sigma in (table or {}).items():
            names = (alias or {}).get(key, (key,) if key in keys else ())
            if not names:
                raise ConfigError(f"{where}.uncertainty.{key}: unknown value; expected one "
                                  f"of {', '.join(keys + tuple(alias or ()))}")
            for n in names:
                out[f"{owner}.{n}" if owner else n] = (float(sigma), f"{where}.uncertainty")

    for a in cfg.amb:
        keys = tuple(f"{q}_{x}" for q in ("Ki", "Ks") for x in ("zeta", "eta"))
        take(a.uncertainty, f"amb[{a.name}]", a.name, keys,
             {"Ki": ("Ki_zeta", "Ki_eta"), "Ks": ("Ks_zeta", "Ks_eta")})
    for i, s in enumerate(cfg.spring):
        name = s.name or f"spring{i}"
        take(s.uncertainty, f"spring[{name}]", name, _SPRING_KEYS)
    for s in cfg.seal:
        take(s.uncertainty, f"seal[{s.name}]", s.name, _SEAL_KEYS)
    take(cfg.actuator.uncertainty, "actuator", "", ("eddy_time_constant",),
         {"eddy_time_constant": ("tau_e",)})
    return out


def fixed_uncertainty(cfg, parameter_names, fitted) -> dict[str, tuple[float, str]]:
    """Relative 1σ of every model parameter the fit holds fixed.

    Parameters
    ----------
    cfg : RigConfig
    parameter_names : iterable of str
        The model's parameters (e.g. ``Plant.parameters``), plus ``"tau_e"`` if the model
        has an eddy-current lag.
    fitted : iterable of str
        The parameters being fitted (left out).

    Returns
    -------
    dict
        ``{name: (σ relative, source)}``, source ``"<component>.uncertainty"`` or
        ``"default (<kind>)"``.

    Raises
    ------
    ConfigError
        An ``uncertainty`` key that names no value of its component.
    """
    stated = _stated(cfg)
    fitted = set(fitted)
    out = {}
    for n in parameter_names:
        if n in fitted:
            continue
        kind = kind_of(cfg, n)
        out[n] = stated.get(n, (DEFAULT_UNCERTAINTY[kind], f"default ({kind})"))
    return out


@dataclass(frozen=True)
class ErrorBudget:
    """What the fixed parameters' uncertainty adds to each estimate.

    Attributes
    ----------
    fitted : tuple of str
    fixed : tuple of str
        The fixed parameters with a non-zero effect.
    sigma_rel : ndarray (q,)
        Their relative 1σ.
    source : tuple of str
        Where each σ comes from.
    sensitivity : ndarray (p, q)
        ∂θ̂_i/∂(φ_j/φ_j0), SI units of θ_i per unit relative change of φ_j.
    covariance : ndarray (p, p)
        G diag(σ²) Gᵀ (SI).
    noise_variance : ndarray (p,)
        The estimates' noise variance (SI), for the shares.
    score_z : ndarray (q,) or None
        Score test of each fixed value against the data (N(0, 1) when it is right).
    offset_rel, offset_rel_se : ndarray (q,) or None
        The relative offset φ/φ₀ − 1 the data suggest for each fixed value (one
        Gauss–Newton step with θ free), and its standard error.
    correlation : ndarray (q, q) or None
        Correlation of the fixed values' errors (None: independent); non-zero off the
        diagonal between values an earlier fit estimated together.
    estimated : ndarray (q,) of bool or None
        Which fixed values are an earlier fit's estimates (σ its standard error).
    """

    fitted: tuple[str, ...]
    fixed: tuple[str, ...]
    sigma_rel: np.ndarray
    source: tuple[str, ...]
    sensitivity: np.ndarray
    covariance: np.ndarray
    noise_variance: np.ndarray
    score_z: np.ndarray | None = None
    offset_rel: np.ndarray | None = None
    offset_rel_se: np.ndarray | None = None
    correlation: np.ndarray | None = None
    estimated: np.ndarray | None = None

    def test_z(self) -> np.ndarray | None:
        """The statistic :meth:`disputed` compares: the score z of a value held as exact;
        for an earlier fit's estimate, its suggested offset over √(se² + σ²) (module
        docstring)."""
        if self.score_z is None:
            return None
        if self.estimated is None or not np.any(self.estimated):
            return np.asarray(self.score_z, float)
        with np.errstate(invalid="ignore", divide="ignore"):
            adj = self.offset_rel / np.hypot(self.offset_rel_se, self.sigma_rel)
        return np.where(self.estimated, adj, self.score_z)

    def disputed(self, level: float = 0.01) -> list[str]:
        """Fixed values the data reject at ``level`` (two-sided, Bonferroni over the
        fixed values tested), largest |z| first."""
        if self.score_z is None:
            return []

        z = np.abs(np.nan_to_num(self.test_z()))
        crit = norm.isf(level / (2 * max(len(self.fixed), 1)))
        return [self.fixed[j] for j in np.argsort(-z) if z[j] > crit]

    def contribution(self) -> np.ndarray:
        """Standard-error contribution (SI) of each fixed parameter to each estimate (p, q)."""
        return np.abs(self.sensitivity) * self.sigma_rel

    def shares(self) -> np.ndarray:
        """Each fixed parameter's share of each estimate's total variance (p, q)."""
        c2 = self.contribution() ** 2
        tot = c2.sum(axis=1, keepdims=True) + self.noise_variance[:, None]
        return np.where(tot > 0, c2 / np.where(tot > 0, tot, 1.0), 0.0)

    def dominant(self, share: float = 0.3) -> list[str]:
        """Fixed parameters that make at least ``share`` of some estimate's variance,
        largest first."""
        frac = self.shares()
        return [self.fixed[j] for j in np.argsort(-frac.max(axis=0)) if frac[:, j].max() >= share]

    def to_dict(self) -> dict:
        c = self.contribution()
        return {
            "fixed": {n: {"sigma_rel": float(s), "source": src}
                      for n, s, src in zip(self.fixed, self.sigma_rel, self.source)},
            "std_error_contribution": {
                p: {n: float(c[i, j]) for j, n in enumerate(self.fixed)}
                for i, p in enumerate(self.fitted)},
            "variance_share": {
                p: {n: float(f) for n, f in zip(self.fixed, row)}
                for p, row in zip(self.fitted, self.shares())},
            "dominant": self.dominant(),
            **({"score_test": {
                n: {"z": float(z), "offset_rel": float(o), "offset_rel_se": float(e)}
                for n, z, o, e in zip(self.fixed, self.test_z(), self.offset_rel,
                                      self.offset_rel_se)},
                "disputed": self.disputed()} if self.score_z is not None else {}),
        }


def propagate(J: np.ndarray, J_fixed: np.ndarray, scale: np.ndarray, fitted, fixed,
              sigma_rel, source, noise_variance, score=None, correlation=None,
              estimated=None) -> ErrorBudget:
    """The error budget from the Jacobians at the optimum (module docstring).

    Parameters
    ----------
    J : ndarray (n, p)
        ∂r/∂x of the fit, x the scaled parameters (θ = θ₀ + x·scale).
    J_fixed : ndarray (n, q)
        ∂r/∂(φ/φ₀) of each fixed parameter.
    scale : ndarray (p,)
    noise_variance : ndarray (p,)
        The estimates' noise variance (SI).
    score : (z, offset_rel, offset_rel_se), optional
        The fixed values' score tests.
    correlation : ndarray (q, q), optional
        Correlation of the fixed values' errors (default: independent).
    estimated : ndarray (q,) of bool, optional
        Which fixed values are an earlier fit's estimates.
    """
    G = -np.linalg.lstsq(J, J_fixed, rcond=None)[0] * np.asarray(scale)[:, None]
    sig = np.asarray(sigma_rel, dtype=float)
    C = np.diag(sig**2) if correlation is None else np.outer(sig, sig) * correlation
    cov = G @ C @ G.T
    return ErrorBudget(tuple(fitted), tuple(fixed), sig, tuple(source), G, cov,
                       np.asarray(noise_variance, dtype=float), *(score or (None,) * 3),
                       correlation, None if estimated is None else np.asarray(estimated, bool))


def _estimated(budget: ErrorBudget, j: int) -> bool:
    return budget.estimated is not None and bool(budget.estimated[j])


def advice(budget: ErrorBudget | None, cfg, fitted, pressures_bar, share: float = 0.3
           ) -> list[str]:
    """Warnings for the user: fixed values that dominate the budget (fit them, or add a record
    that separates them), and seal coefficients held fixed at a non-zero pressure drop.

    Parameters
    ----------
    budget : ErrorBudget or None
        The fit's error budget; None gives only the seal warning.
    cfg : RigConfig
        The rig fitted (its seals).
    fitted : iterable of str
        The fitted parameters.
    pressures_bar : iterable of float
        The records' pressure drops (bar).
    share : float
        Share of an estimate's variance above which a fixed value dominates it.

    Returns
    -------
    list of str
        One sentence per warning; empty when there is none.
    """
    out = []
    if budget is not None:
        for name in budget.disputed():
            j = budget.fixed.index(name)
            out.append(
                f"the data disagree with the fixed value of {name} (score test z = "
                f"{budget.test_z()[j]:+.1f}; they suggest {100 * budget.offset_rel[j]:+.2g} ± "
                f"{100 * budget.offset_rel_se[j]:.2g} % from "
                f"{'the earlier estimate' if _estimated(budget, j) else 'the rig file'}"
                "'s): fit it, on records that separate it")
        frac = budget.shares()
        for name in budget.dominant(share):
            j = budget.fixed.index(name)
            worst = int(np.argmax(frac[:, j]))
            out.append(
                f"{name} (held fixed, {budget.source[j]}: σ = {100 * budget.sigma_rel[j]:.3g} "
                f"%) makes {100 * frac[worst, j]:.0f} % of the variance of "
                f"{budget.fitted[worst]}: fit it too (--params ...,{name}) on records that "
                "separate it — a second record, or one at another operating point or "
                "excitation — or state its uncertainty in the rig file")
    seals = {s.name for s in cfg.seal}
    held = sorted(f"{s}.{q}" for s in seals for q in ("K", "k", "C", "c")
                  if f"{s}.{q}" not in set(fitted))
    p = [float(x) for x in pressures_bar if float(x) > 0]
    if held and p:
        out.append(
            f"seal coefficients {', '.join(held)} are held at the rig file's values on a "
            f"record at {', '.join(f'{x:g}' for x in sorted(set(p)))} bar: they depend on the "
            "pressure drop and are rarely known well (thesis P5 §3.3); fit the AMB at 0 bar, "
            "then the seal at pressure (ambseal run's procedure), or fit them here")
    return out

"""Statistics of identified coefficients: regression lines against pressure (P5 Fig. 7)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ambseal.errors import IdentificationError

__all__ = ["Regression", "linear_regression", "jacobian_correlation"]


@dataclass(frozen=True)
class Regression:
    """y ≈ intercept + slope·x with standard errors and the 95 % band of the line.

    Attributes
    ----------
    intercept, slope : float
    intercept_se, slope_se, covariance : float, float, ndarray (2, 2)
    x, y, y_se : ndarray
        The points and their standard errors (NaN if none were given).
    """

    intercept: float
    slope: float
    intercept_se: float
    slope_se: float
    covariance: np.ndarray
    x: np.ndarray
    y: np.ndarray
    y_se: np.ndarray

    def predict(self, x) -> tuple[np.ndarray, np.ndarray]:
        """Line and its standard error at ``x``: (ŷ, se(ŷ))."""
        x = np.asarray(x, dtype=float)
        X = np.stack([np.ones_like(x), x], axis=-1)
        yhat = X @ np.array([self.intercept, self.slope])
        se = np.sqrt(np.einsum("...i,ij,...j->...", X, self.covariance, X))
        return yhat, se

    def to_dict(self) -> dict:
        return {"intercept": self.intercept, "slope": self.slope,
                "intercept_se": self.intercept_se, "slope_se": self.slope_se}


def linear_regression(x, y, y_se=None) -> Regression:
    """Weighted least-squares line through (x, y).

    With standard errors ``y_se`` the weights are 1/se² and the covariance is scaled by the
    reduced χ² when that exceeds 1 (scatter larger than the stated errors); without them,
    ordinary least squares with the residual variance (Draper & Smith, *Applied Regression
    Analysis*, 3rd ed., §1.4 and §9.2).

    Raises
    ------
    IdentificationError
        Fewer than three points, or all x equal.
    """
    x, y = np.asarray(x, float), np.asarray(y, float)
    if x.size < 3 or np.ptp(x) == 0:
        raise IdentificationError("regression: expected at least three points at distinct x")
    if y_se is None:
        w = np.ones_like(x)
        se_in = np.full_like(x, np.nan)
    else:
        se_in = np.asarray(y_se, float)
        w = 1.0 / np.where(np.isfinite(se_in) & (se_in > 0), se_in, np.inf) ** 2
        if not np.any(w > 0):
            w = np.ones_like(x)
    X = np.stack([np.ones_like(x), x], axis=1)
    W = np.diag(w)
    cov = np.linalg.inv(X.T @ W @ X)
    beta = cov @ X.T @ W @ y
    r = y - X @ beta
    chi2 = float(r @ W @ r) / (x.size - 2)
    if y_se is None:
        cov = cov * chi2
    elif chi2 > 1:
        cov = cov * chi2
    return Regression(float(beta[0]), float(beta[1]), float(np.sqrt(cov[0, 0])),
                      float(np.sqrt(cov[1, 1])), cov, x, y, se_in)


def jacobian_correlation(J: np.ndarray) -> np.ndarray:
    """Correlation of (JᵀJ)⁻¹ (NaN when singular): P4 Tables 2 and 4."""
    try:
        H = np.linalg.inv(J.T @ J)
    except np.linalg.LinAlgError:
        return np.full((J.shape[1], J.shape[1]), np.nan)
    d = np.sqrt(np.abs(np.diag(H)))
    with np.errstate(invalid="ignore", divide="ignore"):
        return H / np.outer(d, d)

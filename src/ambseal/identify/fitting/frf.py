"""Frequency-domain verification: measured closed-loop and plant FRFs, and model FRFs.

The thesis checks an identified model against the rig in the frequency domain (P4 §3.4,
Figs. 9–10, and §3.5.2, Figs. 13–15: amplitude, phase and coherence of the response to a
chirp excitation). This module estimates such FRFs from time records with Welch averaging
(Hann window, ``nperseg`` samples per segment, ``noverlap`` overlap, per-segment mean removed
— the conventions of :func:`scipy.signal.csd`) and evaluates a state-space model on the same
grid.

Estimators, per frequency bin, with ``Φ_ab = E[a b^H]`` the averaged cross-spectral matrix of
the segment spectra:

* **H1, SISO** (``method="siso"``): ``H_ij = S_{u_j y_i} / S_{u_j u_j}`` for every
  (excitation ``u_j``, response ``y_i``) pair, with the ordinary coherence
  ``γ²_ij = |S_{u_j y_i}|² / (S_{u_j u_j} S_{y_i y_i})``. Right when one excitation runs at a
  time, or when several axes carry the *same* signal (the parallel excitation of P4 Fig. 9:
  then pass that signal as the one input);
* **H1, MIMO** (``method="mimo"``): ``H = Φ_yu Φ_uu⁻¹`` when several *independent*
  excitations run at once (the two PRBS of P4 §3.4), with the multiple coherence
  ``γ²_i = (H Φ_uu H^H)_ii / Φ_yy,ii`` per response besides the ordinary ones.

H1 is unbiased by noise on the response, not on the excitation — the excitation is the
computer-generated ``i_e``, noise-free by construction, which is why the closed-loop FRFs
are taken *from the excitation* (P2 §1: in closed loop the measurement noise is correlated
with the plant input, so the plant cannot be estimated from current to displacement
directly). The unstable plant's FRF then follows from two closed-loop FRFs with the same
excitation (:func:`plant_frf`): with ``y = G i`` and both ``y`` and ``i`` driven by ``e``,
``T_ye = G T_ie``, so ``G = T_ye T_ie⁻¹`` (MIMO, square ``T_ie``) or, per excitation axis
``j`` and its own current, ``G_ij ≈ T_ye,ij / T_ie,jj`` (SISO; exact for a decoupled axis).

Frequencies are in Hz at this module's edges (``frequency_hz``), as in the thesis figures.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Sequence

import control
import numpy as np
import scipy.signal

from ambseal.errors import DataError, IdentificationError
from ambseal.lti import freqresp_at

__all__ = [
    "FRF",
    "estimate_frf",
    "closed_loop_frf",
    "plant_frf",
    "model_frf",
]

_RESPONSES = {
    "displacement": ("displacement_m", "m"),
    "current": ("current_a", "A"),
    "current_ref": ("current_ref_a", "A"),
}


# --------------------------------------------------------------------------- result
@dataclass(frozen=True, eq=False)
class FRF:
    """A frequency response function on a grid, measured or computed.

    Attributes
    ----------
    frequency_hz : ndarray, shape (n_f,)
        Frequencies (Hz), increasing.
    H : ndarray of complex, shape (n_f, ny, nu)
        ``H[k, i, j]`` response ``i`` per unit input ``j`` at ``frequency_hz[k]`` (units in
        :attr:`units`). ``nan`` where not estimable (e.g. an ill-conditioned ``Φ_uu``).
    coherence : ndarray, shape (n_f, ny, nu), or None
        Ordinary coherence γ² in [0, 1] of each pair (estimates), a quality indicator for
        ratio estimates (see :func:`plant_frf`), ``None`` for models.
    input_names, output_names : tuple of str
        Channel names, length ``nu`` and ``ny`` (e.g. ``"excitation_A_zeta"``,
        ``"displacement_A_zeta"``).
    method : str
        ``"siso"``, ``"mimo"`` (H1 estimates), ``"siso-ratio"``, ``"mimo-ratio"`` (plant from
        closed loops) or ``"model"``.
    units : str
        Units of ``H``, e.g. ``"m/A"``; ``""`` when unknown.
    multiple_coherence : ndarray, shape (n_f, ny), or None
        Multiple coherence per response (``method="mimo"`` only).
    info : dict
        JSON-safe estimation settings: ``sample_rate_hz``, ``nperseg``, ``noverlap``,
        ``n_segments``, ``window`` (estimates); ``dt`` (models).
    """

    frequency_hz: np.ndarray
    H: np.ndarray
    coherence: np.ndarray | None
    input_names: tuple[str, ...]
    output_names: tuple[str, ...]
    method: str
    units: str = ""
    multiple_coherence: np.ndarray | None = None
    info: dict = field(default_factory=dict)

    def __post_init__(self) -> None:
        f = np.asarray(self.frequency_hz, dtype=float)
        H = np.asarray(self.H, dtype=complex)
        if f.ndim != 1 or H.ndim != 3 or H.shape[0] != f.size:
            raise ValueError(f"H: expected shape (n_f, ny, nu) with n_f={f.size}, got {H.shape}")
        ins, outs = tuple(map(str, self.input_names)), tuple(map(str, self.output_names))
        if (len(outs), len(ins)) != H.shape[1:]:
            raise ValueError(f"names: {len(outs)} outputs × {len(ins)} inputs do not match H {H.shape}")
        for arr in (f, H):
            arr.setflags(write=False)
        object.__setattr__(self, "frequency_hz", f)
        object.__setattr__(self, "H", H)
        object.__setattr__(self, "input_names", ins)
        object.__setattr__(self, "output_names", outs)
        for name, shape in (("coherence", H.shape), ("multiple_coherence", H.shape[:2])):
            c = getattr(self, name)
            if c is not None:
                c = np.asarray(c, dtype=float)
                if c.shape != shape:
                    raise ValueError(f"{name}: expected shape {shape}, got {c.shape}")
                c.setflags(write=False)
                object.__setattr__(self, name, c)

    @property
    def magnitude(self) -> np.ndarray:
        """``|H|``, shape (n_f, ny, nu)."""
        return np.abs(self.H)

    @property
    def phase_deg(self) -> np.ndarray:
        """Phase of ``H`` in degrees, unwrapped along frequency, shape (n_f, ny, nu)."""
        ph = np.angle(self.H)
        ok = np.isfinite(ph).all(axis=0)
        out = np.degrees(ph)
        if ok.any():
            out[:, ok] = np.degrees(np.unwrap(ph[:, ok], axis=0))
        return out

    def pair(self, output: str | int, input: str | int) -> np.ndarray:
        """``H[:, i, j]`` of one (output, input) pair by name or index, shape (n_f,)."""
        return self.H[:, self._index(output, self.output_names), self._index(input, self.input_names)]

    @staticmethod
    def _index(key: str | int, names: tuple[str, ...]) -> int:
        if isinstance(key, (int, np.integer)):
            return int(key)
        try:
            return names.index(key)
        except ValueError:
            raise KeyError(f"{key!r} not in {names}") from None

    def band(self, fmin_hz: float = 0.0, fmax_hz: float = math.inf) -> "FRF":
        """The FRF restricted to ``fmin_hz <= f <= fmax_hz``."""
        m = (self.frequency_hz >= fmin_hz) & (self.frequency_hz <= fmax_hz)
        return FRF(
            self.frequency_hz[m], self.H[m], None if self.coherence is None else self.coherence[m],
            self.input_names, self.output_names, self.method, self.units,
            None if self.multiple_coherence is None else self.multiple_coherence[m], dict(self.info),
        )

    def to_dict(self) -> dict:
        """JSON-safe form: grid, ``H`` as ``re``/``im`` nested lists (NaN → None), names."""
        return {
            "method": self.method,
            "units": self.units,
            "input_names": list(self.input_names),
            "output_names": list(self.output_names),
            "frequency_hz": _jlist(self.frequency_hz),
            "H_re": _jlist(self.H.real),
            "H_im": _jlist(self.H.imag),
            "coherence": None if self.coherence is None else _jlist(self.coherence),
            "multiple_coherence": None if self.multiple_coherence is None else _jlist(self.multiple_coherence),
            "info": dict(self.info),
        }


def _jlist(a: np.ndarray) -> list:
    a = np.asarray(a, dtype=float)
    out = a.astype(object)
    out[~np.isfinite(a)] = None
    return out.tolist()


# --------------------------------------------------------------------------- estimation
def _as_2d(x: Any, name: str) -> np.ndarray:
    a = np.asarray(x, dtype=float)
    if a.ndim == 1:
        a = a[:, None]
    if a.ndim != 2 or a.shape[1] == 0:
        raise DataError(f"{name}: expected shape (n,) or (n, channels), got {a.shape}")
    bad = ~np.isfinite(a)
    if bad.any():
        r, c = np.argwhere(bad)[0]
        raise DataError(f"{name}: column {c}, row {r + 1}: {float(a[r, c])!r} is not finite")
    return a


def _spectra(x: np.ndarray, nperseg: int, noverlap: int, window: Any) -> tuple[np.ndarray, int]:
    """Windowed segment spectra, shape (n_seg, n_f, channels), as scipy.signal.csd forms them."""

    w = scipy.signal.get_window(window, nperseg)
    step = nperseg - noverlap
    seg = np.lib.stride_tricks.sliding_window_view(x, nperseg, axis=0)[::step]  # (n_seg, ch, nperseg)
    seg = seg - seg.mean(axis=-1, keepdims=True)
    X = np.fft.rfft(seg * w, axis=-1)  # (n_seg, ch, n_f)
    return np.transpose(X, (0, 2, 1)), seg.shape[0]


def estimate_frf(
    u: Any,
    y: Any,
    sample_rate_hz: float,
    *,
    nperseg: int,
    noverlap: int | None = None,
    method: str = "siso",
    window: Any = "hann",
    input_names: Sequence[str] | None = None,
    output_names: Sequence[str] | None = None,
    units: str = "",
    max_cond: float = 1e8,
) -> FRF:
    """H1 estimate of the FRF from inputs ``u`` to outputs ``y`` with Welch averaging.

    Parameters
    ----------
    u : array_like, shape (n,) or (n, nu)
        Inputs (the excitation), uniformly sampled.
    y : array_like, shape (n,) or (n, ny)
        Outputs on the same samples.
    sample_rate_hz : float
        Sampling rate (Hz).
    nperseg : int
        Samples per segment (frequency resolution ``sample_rate_hz / nperseg``), ``2 <=
        nperseg <= n``.
    noverlap : int, optional
        Overlap of segments in samples, ``0 <= noverlap < nperseg``; default ``nperseg // 2``.
    method : {"siso", "mimo"}
        Pairwise H1 or the multivariable H1 ``Φ_yu Φ_uu⁻¹`` (see the module docstring).
    window : str, tuple or array_like
        Window for :func:`scipy.signal.get_window` (default Hann, periodic).
    input_names, output_names : sequence of str, optional
        Channel names; default ``u[j]`` and ``y[i]``.
    units : str
        Units of ``H`` for labels, e.g. ``"m/A"``.
    max_cond : float
        ``method="mimo"``: bins where the 2-norm condition number of ``Φ_uu`` exceeds this get
        ``H = nan`` (inputs not independent there, e.g. at PRBS spectral nulls).

    Returns
    -------
    FRF
        ``frequency_hz = rfftfreq(nperseg, 1/sample_rate_hz)``, all bins including 0 Hz.

    Raises
    ------
    ValueError
        On invalid ``sample_rate_hz``, ``nperseg``, ``noverlap``, ``method`` or names.
    DataError
        If ``u`` or ``y`` hold non-finite values or their lengths differ.
    IdentificationError
        ``method="mimo"`` with fewer segments than inputs, or ``Φ_uu`` ill-conditioned in
        every bin (the excitations are not independent).

    Notes
    -----
    Matches :func:`scipy.signal.csd` / :func:`scipy.signal.coherence` with the same
    ``window``, ``nperseg``, ``noverlap`` and ``detrend="constant"`` (the segment spectra
    are computed once and shared by all channel pairs).
    """
    fs = float(sample_rate_hz)
    if not math.isfinite(fs) or fs <= 0:
        raise ValueError(f"sample_rate_hz: expected a finite number > 0, got {sample_rate_hz!r}")
    U, Y = _as_2d(u, "u"), _as_2d(y, "y")
    n = U.shape[0]
    if Y.shape[0] != n:
        raise DataError(f"y: {Y.shape[0]} samples, but u has {n}")
    if isinstance(nperseg, bool) or not isinstance(nperseg, (int, np.integer)) or not 2 <= nperseg <= n:
        raise ValueError(f"nperseg: expected an integer in [2, {n}], got {nperseg!r}")
    noverlap = nperseg // 2 if noverlap is None else noverlap
    if isinstance(noverlap, bool) or not isinstance(noverlap, (int, np.integer)) or not 0 <= noverlap < nperseg:
        raise ValueError(f"noverlap: expected an integer in [0, {nperseg}), got {noverlap!r}")
    if method not in ("siso", "mimo"):
        raise ValueError(f"method: expected 'siso' or 'mimo', got {method!r}")
    nu, ny = U.shape[1], Y.shape[1]
    ins = tuple(input_names) if input_names is not None else tuple(f"u[{j}]" for j in range(nu))
    outs = tuple(output_names) if output_names is not None else tuple(f"y[{i}]" for i in range(ny))
    if len(ins) != nu:
        raise ValueError(f"input_names: {len(ins)} names for {nu} inputs")
    if len(outs) != ny:
        raise ValueError(f"output_names: {len(outs)} names for {ny} outputs")

    X, nseg = _spectra(np.hstack([U, Y]), int(nperseg), int(noverlap), window)
    Xu, Xy = X[..., :nu], X[..., nu:]
    Suu = np.einsum("skj,skl->kjl", Xu, Xu.conj()) / nseg  # Φ_uu[j,l] = E[U_j U_l*]
    Syu = np.einsum("ski,skj->kij", Xy, Xu.conj()) / nseg  # Φ_yu[i,j] = E[Y_i U_j*]
    Syy = np.einsum("ski,ski->ki", Xy, Xy.conj()).real / nseg
    Sjj = np.real(np.einsum("kjj->kj", Suu))
    freq = np.fft.rfftfreq(int(nperseg), 1.0 / fs)
    tiny = np.finfo(float).tiny
    with np.errstate(divide="ignore", invalid="ignore"):
        coh = np.abs(Syu) ** 2 / (Syy[:, :, None] * Sjj[:, None, :])
    coh = np.clip(np.nan_to_num(coh, nan=0.0, posinf=0.0), 0.0, 1.0)
    info = {
        "sample_rate_hz": fs, "nperseg": int(nperseg), "noverlap": int(noverlap),
        "n_segments": int(nseg), "window": window if isinstance(window, (str, tuple)) else "array",
    }
    mcoh = None
    if method == "siso":
        with np.errstate(divide="ignore", invalid="ignore"):
            H = Syu / np.where(Sjj > tiny, Sjj, np.nan)[:, None, :]
    else:
        if nseg < nu:
            raise IdentificationError(
                f"mimo H1: {nseg} segments cannot resolve {nu} inputs; use a longer record or smaller nperseg"
            )
        sv = np.linalg.svd(Suu, compute_uv=False)
        with np.errstate(divide="ignore", invalid="ignore"):
            cond = sv[:, 0] / sv[:, -1]
        good = np.isfinite(cond) & (cond <= max_cond)
        if not good[1:].any() and not (freq.size == 1 and good.all()):
            raise IdentificationError(
                f"mimo H1: the {nu} inputs are not independent in any frequency bin "
                f"(cond Φ_uu > {max_cond:g}); use independent excitations or method='siso'"
            )
        H = np.full((freq.size, ny, nu), np.nan + 0j)
        # H Φ_uu = Φ_yu  <=>  Φ_uuᵀ Hᵀ = Φ_yuᵀ
        Ht = np.linalg.solve(np.transpose(Suu[good], (0, 2, 1)), np.transpose(Syu[good], (0, 2, 1)))
        H[good] = np.transpose(Ht, (0, 2, 1))
        with np.errstate(divide="ignore", invalid="ignore"):
            num = np.einsum("kij,kjl,kil->ki", H, Suu, H.conj()).real
            mcoh = np.clip(np.nan_to_num(num / Syy, nan=0.0, posinf=0.0), 0.0, 1.0)
        mcoh[~good] = np.nan
    return FRF(freq, H, coh, ins, outs, method, units, mcoh, info)


def closed_loop_frf(
    meas: Any,
    *,
    nperseg: int,
    noverlap: int | None = None,
    inputs: Sequence[str] | None = None,
    outputs: Sequence[str] | None = None,
    response: str = "displacement",
    method: str = "siso",
    window: Any = "hann",
    samples: slice | None = None,
) -> FRF:
    """Closed-loop FRF of a :class:`~ambseal.identify.records.data.Measurement` from its excitation.

    Parameters
    ----------
    meas : Measurement
        A loaded or simulated run.
    nperseg, noverlap, method, window
        As in :func:`estimate_frf`.
    inputs : sequence of str, optional
        Axes whose excitation columns are the inputs; default every axis with a non-zero
        excitation. For a parallel excitation with the same signal on two axes pass one.
    outputs : sequence of str, optional
        Axes whose ``response`` columns are the outputs; default all axes.
    response : {"displacement", "current", "current_ref"}
        Which recorded channel is the response: ``T_ye`` (m/A) or ``T_ie`` (A/A).
    samples : slice, optional
        Restrict to these samples (e.g. one stepped-sine window, or dropping a start-up).

    Returns
    -------
    FRF
        Inputs named ``excitation_<axis>``, outputs ``<response>_<axis>``.

    Raises
    ------
    ValueError
        On an unknown ``response`` or axis, or no excited axis.
    DataError, IdentificationError
        As in :func:`estimate_frf`.
    """
    if response not in _RESPONSES:
        raise ValueError(f"response: expected one of {tuple(_RESPONSES)}, got {response!r}")
    fld, unit = _RESPONSES[response]
    axes = tuple(meas.axes)
    sl = slice(None) if samples is None else samples
    E = np.asarray(meas.excitation_a, dtype=float)[sl]
    if inputs is None:
        inputs = [a for j, a in enumerate(axes) if np.any(E[:, j] != 0)]
        if not inputs:
            raise ValueError("inputs: the measurement has no excited axis")
    outputs = axes if outputs is None else tuple(outputs)
    for nm, lst in (("inputs", inputs), ("outputs", outputs)):
        unknown = [a for a in lst if a not in axes]
        if unknown:
            raise ValueError(f"{nm}: axes {unknown} not in the measurement's axes {axes}")
    ji = [axes.index(a) for a in inputs]
    jo = [axes.index(a) for a in outputs]
    R = np.asarray(getattr(meas, fld), dtype=float)[sl]
    fs = float(meas.sample_rate_hz)
    return estimate_frf(
        E[:, ji], R[:, jo], fs, nperseg=nperseg, noverlap=noverlap, method=method, window=window,
        input_names=[f"excitation_{a}" for a in inputs],
        output_names=[f"{response}_{a}" for a in outputs],
        units=f"{unit}/A",
    )


def plant_frf(T_ye: FRF, T_ie: FRF, *, method: str = "mimo") -> FRF:
    """Open-loop plant FRF from two closed-loop FRFs with the same excitation.

    Parameters
    ----------
    T_ye : FRF, H shape (n_f, ny, ne)
        Excitation → displacement (m/A).
    T_ie : FRF, H shape (n_f, ni, ne)
        Excitation → coil current (A/A), same grid and inputs as ``T_ye``; current ``j`` must
        belong to the axis of excitation ``j`` for ``method="siso"``.
    method : {"mimo", "siso"}
        ``"mimo"``: ``G = T_ye T_ie⁻¹`` per frequency (``ni == ne``), shape (n_f, ny, ni);
        ``nan`` where ``T_ie`` is singular. ``"siso"``: ``G[:, i, j] = T_ye[:, i, j] /
        T_ie[:, j, j]`` (``ni == ne``), the displacement per current of the excited axis
        — equal to the plant for a decoupled axis (a 1-DOF loop), an effective FRF with the
        other loops closed otherwise.

    Returns
    -------
    FRF
        Inputs = ``T_ie.output_names`` (the currents), outputs = ``T_ye.output_names``,
        ``method`` ``"mimo-ratio"``/``"siso-ratio"``. ``coherence`` is a quality indicator,
        not a coherence of ``G``: SISO ``min(γ²_ye[i, j], γ²_ie[j, j])``; MIMO
        ``min(q_ye[i], min_l q_ie[l])`` with ``q`` the multiple coherence of each response
        (else its smallest ordinary coherence).

    Raises
    ------
    ValueError
        If the grids or inputs differ, ``T_ie`` is not square, or ``method`` is unknown.
    """
    if method not in ("mimo", "siso"):
        raise ValueError(f"method: expected 'mimo' or 'siso', got {method!r}")
    if T_ye.frequency_hz.shape != T_ie.frequency_hz.shape or not np.allclose(
        T_ye.frequency_hz, T_ie.frequency_hz, rtol=1e-12, atol=0
    ):
        raise ValueError("T_ie: frequency grid differs from T_ye's")
    if T_ye.H.shape[2] != T_ie.H.shape[2] or T_ye.input_names != T_ie.input_names:
        raise ValueError(f"T_ie: inputs {T_ie.input_names} differ from T_ye's {T_ye.input_names}")
    ni, ne = T_ie.H.shape[1:]
    if ni != ne:
        raise ValueError(f"T_ie: expected as many currents as excitations, got {ni} × {ne}")
    units = ""
    if "/" in T_ye.units and "/" in T_ie.units:  # (m/A) / (A/A) -> m/A
        units = f"{T_ye.units.split('/')[0]}/{T_ie.units.split('/')[0]}"
    c_ye, c_ie = T_ye.coherence, T_ie.coherence
    with np.errstate(divide="ignore", invalid="ignore"):
        if method == "siso":
            d = np.einsum("kjj->kj", T_ie.H)
            G = T_ye.H / d[:, None, :]
            coh = None
            if c_ye is not None and c_ie is not None:
                coh = np.minimum(c_ye, np.einsum("kjj->kj", c_ie)[:, None, :])
        else:
            G = np.full((T_ye.frequency_hz.size, T_ye.H.shape[1], ni), np.nan + 0j)
            ok = np.isfinite(T_ie.H).all(axis=(1, 2)) & np.isfinite(T_ye.H).all(axis=(1, 2))
            if ok.any():
                sv = np.linalg.svd(T_ie.H[ok], compute_uv=False)
                good = sv[:, -1] > 1e-12 * sv[:, 0]
                idx = np.flatnonzero(ok)[good]
                # G T_ie = T_ye  <=>  T_ieᵀ Gᵀ = T_yeᵀ
                Gt = np.linalg.solve(np.transpose(T_ie.H[idx], (0, 2, 1)), np.transpose(T_ye.H[idx], (0, 2, 1)))
                G[idx] = np.transpose(Gt, (0, 2, 1))
            coh = None
            if c_ye is not None and c_ie is not None:
                q_ye = T_ye.multiple_coherence if T_ye.multiple_coherence is not None else c_ye.min(axis=2)
                q_ie = T_ie.multiple_coherence if T_ie.multiple_coherence is not None else c_ie.min(axis=2)
                qmin = np.nanmin(q_ie, axis=1)
                coh = np.broadcast_to(np.minimum(q_ye, qmin[:, None])[:, :, None], G.shape).copy()
    return FRF(
        T_ye.frequency_hz, G, coh, T_ie.output_names, T_ye.output_names, f"{method}-ratio", units,
        None, dict(T_ye.info),
    )


# --------------------------------------------------------------------------- model
def model_frf(
    sys: Any,
    frequency_hz: Any,
    *,
    input_names: Sequence[str] | None = None,
    output_names: Sequence[str] | None = None,
    units: str = "",
) -> FRF:
    """Evaluate a linear model on a frequency grid, for comparison with a measured FRF.

    ``H(f) = C (sI − A)⁻¹ B + D`` at ``s = j2πf`` (continuous) or ``z = exp(j2πf·dt)``
    (discrete), evaluated by :func:`ambseal.lti.freqresp.freqresp_at` (modal, or
    the Hessenberg method of Laub, IEEE TAC 26(2), 1981).

    Parameters
    ----------
    sys : control.StateSpace or anything ``control.ss`` accepts
        Continuous (``dt = 0``) or discrete (``dt > 0``) model, ``nu`` inputs, ``ny`` outputs.
    frequency_hz : array_like, shape (n_f,)
        Frequencies (Hz), finite and ``>= 0``; for a discrete model at most ``1 / (2 dt)``.
        Typically ``measured.frequency_hz``.
    input_names, output_names : sequence of str, optional
        Default: the system's signal labels.
    units : str
        Units of ``H`` for labels.

    Returns
    -------
    FRF
        ``method="model"``, ``coherence=None``, ``info={"dt": dt}``.

    Raises
    ------
    ValueError
        On an invalid grid, a frequency above Nyquist of a discrete model, a discrete model
        without a sampling time (``dt=True``), or names of the wrong length.

    Examples
    --------
    >>> import control
    >>> frf = model_frf(control.ss(control.tf([1.0], [1.0, 1.0])), [0.0])
    >>> complex(frf.H[0, 0, 0])
    (1+0j)
    """

    f = np.atleast_1d(np.asarray(frequency_hz, dtype=float))
    if f.ndim != 1 or f.size == 0 or not np.all(np.isfinite(f)) or np.any(f < 0):
        raise ValueError("frequency_hz: expected a non-empty 1-D grid of finite frequencies >= 0 Hz")
    if not isinstance(sys, control.StateSpace):
        sys = control.ss(sys)
    dt = sys.dt
    if dt is True:
        raise ValueError("sys: a discrete model needs a numeric sampling time dt, got dt=True")
    if dt in (0, None):
        x = 2j * np.pi * f
        dt_info = 0.0
    else:
        dt_info = float(dt)
        if f.max() > 0.5 / dt_info * (1 + 1e-12):
            raise ValueError(f"frequency_hz: {f.max()} Hz is above the Nyquist frequency {0.5 / dt_info} Hz of sys")
        x = np.exp(2j * np.pi * f * dt_info)
    H = freqresp_at(sys, x)
    ins = tuple(input_names) if input_names is not None else tuple(sys.input_labels)
    outs = tuple(output_names) if output_names is not None else tuple(sys.output_labels)
    if len(ins) != sys.ninputs:
        raise ValueError(f"input_names: {len(ins)} names for {sys.ninputs} inputs")
    if len(outs) != sys.noutputs:
        raise ValueError(f"output_names: {len(outs)} names for {sys.noutputs} outputs")
    return FRF(f, H, None, ins, outs, "model", units, None, {"dt": dt_info})

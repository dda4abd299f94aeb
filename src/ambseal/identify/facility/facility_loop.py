"""The virtual facility's sample loop, compiled with numba.

The facility (:mod:`ambseal.identify.facility.rig_sim`) cannot be vectorised over time: every
sample the digital controller reads the noisy, quantised sensors, the amplifier saturates,
and the nonlinear AMB force law feeds back into the linear rotor over ``substeps``
sub-steps. In pure Python that loop cost about 1 µs per arithmetic statement and was the
largest part of ``ambseal run``; ``benchmarks/bench_facility.py`` times this compiled
loop against the same function run as Python (``facility_loop.py_func``) in one run.

The arithmetic is the same as written in Python (IEEE double; the matrix–vector products
go through BLAS in both), so records agree with the interpreted loop to rounding.
"""

from __future__ import annotations

import numpy as np

from ambseal.lti import cached_njit

__all__ = ["facility_loop"]


@cached_njit(nogil=True)
def facility_loop(Phi, Gam, seg_start, C_all, D_coil, D_ieff, Ac, Bc, Cc, Dc, e, noise, inoise,
                  lsb, limit, i0, s0, kf, ki, ks, substeps, lp_a, z, xc, yf, rec_y, rec_i,
                  rec_ref):
    """Run the sampled closed loop of the virtual facility; fill the three records.

    Parameters
    ----------
    Phi, Gam : ndarray (S, n, n), (S, n, 2k)
        Sub-step ZOH transition of the linear part, inputs ``[i_ref (k), f_rem (k)]``, one
        per segment of a piecewise-constant pressure (S = 1: one condition).
    seg_start : ndarray (S,) of int
        First sample of each segment (``seg_start[0] = 0``).
    C_all : ndarray (4k, n)
        Rows: sensor displacement, bearing displacement, force current, coil current.
    D_coil, D_ieff : ndarray (k, k)
        Feedthrough of the current reference to the coil and to the force current.
    Ac, Bc, Cc, Dc : ndarray
        Discrete controller, ``u = Cc xc + Dc y`` and ``i_ref = −u + e``.
    e, noise, inoise : ndarray (N, k)
        Excitation (A), sensor noise (m) and current-measurement noise (A) per sample.
    lsb : float
        ADC step (m); 0 for no quantisation.
    limit : float
        Current-reference limit (A), ``inf`` for none.
    i0 : float
        Bias current (A).
    s0, kf, ki, ks : ndarray (k,)
        Force-law gap (m) and constant, and the linearised Ki (N/A), Ks (N/m) per axis.
    substeps : int
    lp_a : float
        Pole of the sensors' sampled first-order low-pass ``y_f ← a y_f + (1 − a) y``;
        0 for none (then ``y_f = y`` exactly).
    z, xc, yf : ndarray (n,), (n_c,), (k,)
        State of the linear part, of the controller and of the sensors' low-pass at the
        first sample, updated in place to the state after the last (zeros for a run from
        rest; carried over when the run goes on in blocks, e.g. with a switched controller).
    rec_y, rec_i, rec_ref : ndarray (N, k)
        Output: measured displacement (m), measured coil current (A), current reference (A).

    Returns
    -------
    int
        −1 when the run completed, else the sample at which a bearing displacement left
        90 % of its air gap (the rest of the records is then undefined).
    """
    N, k = e.shape
    seg = 0
    u_in = np.zeros(2 * k)
    y = np.zeros(k)
    out = C_all @ z
    # the products below go into buffers (np.dot with out: the BLAS call of ``@``, no
    # allocation per sample and sub-step)
    u = np.empty(Cc.shape[0])
    tk = np.empty(Dc.shape[0])
    xn = np.empty(xc.shape[0])
    tx = np.empty(xc.shape[0])
    coil = np.empty(k)
    i_ff = np.empty(k)
    iref = np.empty(k)
    zn = np.empty(z.shape[0])
    tz = np.empty(z.shape[0])
    for n in range(N):
        while seg + 1 < seg_start.shape[0] and n >= seg_start[seg + 1]:
            seg += 1
        for a in range(k):
            yf[a] = lp_a * yf[a] + (1.0 - lp_a) * out[a]
            v = yf[a] + noise[n, a]
            if lsb > 0.0:
                v = np.rint(v / lsb) * lsb
            y[a] = v
        np.dot(Cc, xc, u)
        np.dot(Dc, y, tk)
        for a in range(k):
            iref[a] = min(max(-(u[a] + tk[a]) + e[n, a], -limit), limit)
        np.dot(Ac, xc, xn)
        np.dot(Bc, y, tx)
        for j in range(xc.shape[0]):
            xc[j] = xn[j] + tx[j]
        np.dot(D_coil, iref, coil)
        np.dot(D_ieff, iref, i_ff)
        for a in range(k):
            rec_y[n, a] = y[a]
            rec_ref[n, a] = iref[a]
            rec_i[n, a] = out[3 * k + a] + coil[a] + inoise[n, a]
            u_in[a] = iref[a]
        for _ in range(substeps):
            for a in range(k):
                x = out[k + a]
                i = out[2 * k + a] + i_ff[a]
                if abs(x) >= 0.9 * s0[a]:
                    return n
                ip = max(i0 + i, 0.0)
                im = max(i0 - i, 0.0)
                dp = s0[a] - x
                dm = s0[a] + x
                f = kf[a] * (ip * ip / (dp * dp) - im * im / (dm * dm))
                u_in[k + a] = f - (ki[a] * i + ks[a] * x)
            np.dot(Phi[seg], z, zn)
            np.dot(Gam[seg], u_in, tz)
            for j in range(z.shape[0]):
                z[j] = zn[j] + tz[j]
            np.dot(C_all, z, out)
    return -1

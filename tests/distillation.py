"""The robust-performance distillation problem of Skogestad & Postlethwaite (2005) §8.12.4,
Table 8.1, for tests (benchmarks/bench_dk.py builds the same plant)."""

import control
import numpy as np


def distillation_rp_plant(pole: float | None = None, wp_low: float = 1e-5, gains=None):
    """G = 1/(75s+1)·[87.8 −86.4; 108.2 −109.6], W_I = (s+0.2)/(0.5s+1)·I,
    W_P = 0.5(10s+1)/(10s+1e-5)·I; inputs [w_Δ, w, u], outputs [z_Δ, z, v]; blocks
    [(1, 1), (1, 1), (2, 2)]. With ``pole`` (rad/s) the column's time constant is 1/pole
    instead of 75 s, in a realisation whose B and C do not depend on it
    (G = (g0/75)/(s + pole)): the frozen plants of an LPV family. ``wp_low`` is the
    constant of W_P's denominator (1e-5: a near-integrator); ``gains`` the 2 × 2 steady-state
    gains instead of Table 8.1's."""
    g0 = np.array([[87.8, -86.4], [108.2, -109.6]] if gains is None else gains, float)
    if pole is None:
        G = control.ss(control.tf([[[g0[i, j]] for j in range(2)] for i in range(2)],
                                  [[[75.0, 1.0]] * 2] * 2), inputs=["up0", "up1"],
                       outputs=["yp0", "yp1"], name="G")
    else:
        G = control.ss(-pole * np.eye(2), g0 / 75.0, np.eye(2), np.zeros((2, 2)),
                       inputs=["up0", "up1"], outputs=["yp0", "yp1"], name="G")

    def diag(num, den, inp, out, name):
        return control.ss(control.tf([[num, [0.0]], [[0.0], num]], [[den, [1.0]], [[1.0], den]]),
                          inputs=inp, outputs=out, name=name)

    parts = [G, diag([5.0, 0.5], [10.0, wp_low], ["e0", "e1"], ["z0", "z1"], "Wp"),
             diag([1.0, 0.2], [0.5, 1.0], ["u0", "u1"], ["zd0", "zd1"], "Wi")]
    for k in range(2):
        parts += [control.summing_junction(inputs=[f"u{k}", f"wd{k}"], output=f"up{k}"),
                  control.summing_junction(inputs=[f"yp{k}", f"w{k}"], output=f"e{k}"),
                  control.ss([], [], [], [[-1.0]], inputs=[f"e{k}"], outputs=[f"v{k}"])]
    ins, outs = ["wd0", "wd1", "w0", "w1", "u0", "u1"], ["zd0", "zd1", "z0", "z1", "v0", "v1"]
    return control.interconnect(parts, inplist=ins, outlist=outs, inputs=ins, outputs=outs)

"""The mixed-μ spring–mass problem of Barros, Fekri & Athans (2005), as MathWorks' Robust
Control Toolbox example "Control of a Spring-Mass-Damper System Using Mixed-Mu Synthesis"
states it, for the tests and benchmarks/bench_dk.py."""

import control
import numpy as np


def spring_mass_plant(k1_range: float = 0.8, delay_weight: float = 2.6):
    """Two masses (m1 = 1, m2 = 2) joined by the spring k1 = 2 ± ``k1_range`` (real; the
    example's ureal k1 in [1.2, 2.8]) and damper b1 = 0.05, m2 tied to the wall by k2 = 1,
    b2 = 0.05; the control force f1 on m1 reaches it through 0.06 s of delay, bounded as a
    complex multiplicative error by ``delay_weight``·s/(s + 40); the disturbance force f2 on
    m2 is coloured by 0.25/(s + 0.25); the measured position of m2 carries noise 0.001.
    Performance [W_p z2; W_u f1] with W_p = 80·0.1/(s + 0.1), W_u = 10(s + 10)/(s + 1000).
    Inputs [w_k1, w_delay, disturbance, noise, f1], outputs [z_k1, z_delay, W_p z2, W_u f1,
    measured z2]; blocks [(-1, 0), (1, 1), (2, 2)]; u = K y (positive feedback, as the
    example's interconnection)."""
    m1, m2, k2, b1, b2, k10 = 1.0, 2.0, 1.0, 0.05, 0.05, 2.0
    v = np.array([0.0, 0.0, -1 / m1, 1 / m2])
    A = np.column_stack([v * k10, -v * k10 + np.array([0.0, 0.0, 0.0, -k2 / m2]),
                         [1.0, 0.0, -b1 / m1, b1 / m2], [0.0, 1.0, b1 / m1, -(b1 + b2) / m2]])
    # k1 = k10 + k1_range·δ acts as v·k1·(z1 − z2): the channel z_k = k1_range·(z1 − z2)
    B = np.column_stack([v, [0.0, 0.0, 1 / m1, 0.0], [0.0, 0.0, 0.0, 1 / m2]])
    C = np.array([[k1_range, -k1_range, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0]])
    plant = control.ss(A, B, C, np.zeros((2, 3)), inputs=["wk", "f1a", "f2"],
                       outputs=["zk", "z2"])
    parts = [plant,
             control.ss(control.tf([delay_weight, 0.0], [1.0, 40.0]), inputs=["f1"],
                        outputs=["zdel"]),
             control.summing_junction(inputs=["f1", "wdel"], output="f1a"),
             control.ss(control.tf([0.25], [1.0, 0.25]), inputs=["dist"], outputs=["f2"]),
             control.ss(10 * control.tf([1.0, 10.0], [1.0, 1000.0]), inputs=["f1"],
                        outputs=["zu"]),
             control.ss(80 * control.tf([0.1], [1.0, 0.1]), inputs=["z2"], outputs=["zp"]),
             control.ss([], [], [], [[0.001]], inputs=["noise"], outputs=["wn"]),
             control.summing_junction(inputs=["z2", "wn"], output="z2n")]
    return control.interconnect(parts, inplist=["wk", "wdel", "dist", "noise", "f1"],
                                outlist=["zk", "zdel", "zp", "zu", "z2n"])

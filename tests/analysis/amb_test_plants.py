"""Small AMB test plants with known structure, shared by the analysis tests.

* ``mass_1dof``: a mass ``m`` on one AMB axis, ``m x'' = k_s x + k_i i`` (P5 Eq. 1, negative
  stiffness ``k_s > 0`` pulls away from the centre), with a PD controller with filtered
  derivative (P5 Eq. 6 without the integral term) — transfer functions are closed forms.
* ``rigid_rotor``: a rigid rotor (mass, transverse inertia) on two AMBs A and B in two axes
  ζ, η, with a cross-coupled seal stiffness ``k`` at mid-span (P5 Eq. 3), decentralised PD
  control, and a force plant ``Gf`` with mid-span forces ``Fx``, ``Fy``.
"""

from __future__ import annotations

import control
import numpy as np

NAMES = ["A_zeta", "A_eta", "B_zeta", "B_eta"]


def pd_tf(kp: float, td: float, eps: float = 0.1) -> tuple[np.ndarray, np.ndarray]:
    """Numerator/denominator of ``kp (1 + td s / (eps td s + 1))`` (P5 Eq. 6, no integral)."""
    num = kp * np.array([eps * td + td, 1.0])
    den = np.array([eps * td, 1.0])
    return num, den


def mass_1dof(m=10.0, ks=1.0e6, ki=100.0, kp_factor=3.0, td=2e-3):
    """Return (G, K, (numG, denG), (numK, denK)) for the 1-DOF AMB axis with PD control."""
    numG, denG = np.array([ki]), np.array([m, 0.0, -ks])
    G = control.ss(np.array([[0.0, 1.0], [ks / m, 0.0]]), np.array([[0.0], [ki / m]]),
                   np.array([[1.0, 0.0]]), np.array([[0.0]]), inputs=["A_zeta"], outputs=["A_zeta"])
    numK, denK = pd_tf(kp_factor * ks / ki, td)
    K = control.ss(control.tf(numK, denK), inputs=["A_zeta"], outputs=["A_zeta"])
    return G, K, (numG, denG), (numK, denK)


def rigid_rotor(m=69.0, J=3.0, l=0.3, ks=(1.2e6, 1.0e6), ki=(250.0, 220.0), k_seal=2e5, c=50.0,
                kp_factor=3.0, td=3.5e-3):
    """Rigid rotor on two AMBs; returns (G, Gf, K).

    Coordinates q = [A_ζ, A_η, B_ζ, B_η] (bearing displacements, bearings at ∓l from mid-span).
    Seal at mid-span: f = −[[0, k], [−k, 0]] q_c − c q̇_c (Childs convention, DESIGN.md).
    """
    # mid-span displacement and tilt from bearing displacements, per axis
    Tp = np.array([[0.5, 0.5], [-0.5 / l, 0.5 / l]])  # [x_c, θ] = Tp [q_A, q_B]
    T = np.zeros((4, 4))  # [ζ_c, θ_ζ, η_c, θ_η] = T q
    T[np.ix_([0, 1], [0, 2])] = Tp
    T[np.ix_([2, 3], [1, 3])] = Tp
    M = T.T @ np.diag([m, J, m, J]) @ T
    Ks = np.diag([ks[0], ks[0], ks[1], ks[1]])
    Ki = np.diag([ki[0], ki[0], ki[1], ki[1]])
    # seal at centre acting on (ζ_c, η_c): rows/cols 0 and 2 of the T-coordinates
    Sc = np.zeros((4, 4))
    Sc[0, 2], Sc[2, 0] = k_seal, -k_seal
    Ss = T.T @ Sc @ T
    Cs = T.T @ np.diag([c, 0.0, c, 0.0]) @ T
    Kq = -Ks + Ss  # M q'' + Cs q' + Kq q = Ki i + forces
    Minv = np.linalg.inv(M)
    A = np.block([[np.zeros((4, 4)), np.eye(4)], [-Minv @ Kq, -Minv @ Cs]])
    B = np.vstack([np.zeros((4, 4)), Minv @ Ki])
    Pf = T.T @ np.array([[1.0, 0.0], [0.0, 0.0], [0.0, 1.0], [0.0, 0.0]])  # mid-span Fx, Fy
    Bf = np.vstack([np.zeros((4, 2)), Minv @ Pf])
    C = np.hstack([np.eye(4), np.zeros((4, 4))])
    G = control.ss(A, B, C, np.zeros((4, 4)), inputs=NAMES, outputs=NAMES)
    Gf = control.ss(A, Bf, C, np.zeros((4, 2)), inputs=["Fx", "Fy"], outputs=NAMES)
    ks_v = np.array([ks[0], ks[0], ks[1], ks[1]])
    ki_v = np.array([ki[0], ki[0], ki[1], ki[1]])
    blocks = []
    for j in range(4):
        num, den = pd_tf(kp_factor * ks_v[j] / ki_v[j], td)
        blocks.append(control.ss(control.tf(num, den)))
    K = control.append(*blocks)
    K = control.ss(K.A, K.B, K.C, K.D, inputs=NAMES, outputs=NAMES)
    return G, Gf, K

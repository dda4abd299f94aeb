"""The drop's right-hand side: the rotor's modes under gravity, the overload and the
unbalance, the AMB loop, the rings' contacts and friction, the axial stops, and the seals
and springs (the package's docstring, :mod:`ambseal.analysis.drop`); one method per force.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.constants import g as GRAVITY

from ambseal.analysis.drop._event import DropEvent
from ambseal.analysis.drop._model import (
    DropModel,
    _housings,
    _seal_offset_forces,
    support_matrices,
)
from ambseal.analysis.drop._state import StateLayout, tolerances
from ambseal.analysis.drop_loop import AmbLoop
from ambseal.errors import ConfigError
from ambseal.model import friction_force


class DropDynamics:
    """The equations of one drop: ``rhs(t, y)`` with the state's layout, each force on
    its own, and what the integration changes as it goes — each plane's impact speed v₀
    (set at a contact's onset) and a digital controller's updates.

    Parameters
    ----------
    cfg : RigConfig
        The rig dropped.
    dm : DropModel
        Its drop model.
    loop : AmbLoop
        The AMB loop.
    event : DropEvent
        The event and its settings.

    Raises
    ------
    ConfigError
        A ``failed`` channel the rig does not have, axes left running without a
        controller, an overload off the rotor or not finite, a thrust not finite.
    """

    def __init__(self, cfg, dm: DropModel, loop: AmbLoop, event: DropEvent):
        self.dm, self.loop, self.event = dm, loop, event
        m, P = dm.phi.shape[1], len(dm.laws)
        self.m, self.P = m, P
        self.W0 = event.speed_rad_s
        names = loop.names
        failed = names if event.failed is None else tuple(event.failed)
        unknown = [n for n in failed if n not in names]
        if unknown:
            raise ConfigError(f"drop: failed: {', '.join(unknown)}: expected AMB channels "
                              f"of the rig ({', '.join(names)})")
        self.failed = failed
        self.down = np.array([n in failed for n in names])
        thrust = event.axial_thrust
        self.thrust = float(cfg.drop.axial_thrust if thrust is None else thrust)
        if not math.isfinite(self.thrust):
            raise ConfigError(f"drop: axial thrust: expected a finite force in N, got "
                              f"{thrust!r}")
        self.stops = [p for p, law in enumerate(dm.axial_laws) if law is not None]
        # the thrust bearing lets go with the radial axes: the rotor then moves axially
        self.axial = bool(self.stops) and bool(self.down.all())
        if not self.down.all() and not loop.has_controller:
            raise ConfigError("drop: the AMB axes that run on need a controller (the loop "
                              "has none)")
        self.f_over = self._overload(event.overload)
        self.sealed = bool(event.supports and (cfg.seal or cfg.spring))
        nh = 2 * _housings(cfg) if self.sealed else 0
        if self.sealed:
            self.K_s, self.C_s, self.M_s = support_matrices(cfg, dm, event.speed_rpm,
                                                            event.pressure_bar)
            # the modes' unit mass and the housings' own (in M_s)
            self.M_inv = np.linalg.inv(np.diag(np.r_[np.ones(m), np.zeros(nh)]) + self.M_s)
            # the offset seals' static loads at the drop's pressure (the AMBs held them
            # at the operating one): on the rotor as the overload is, their work from
            # outside
            for zs, F in _seal_offset_forces(cfg, cfg.operating.pressure_bar
                                            if event.pressure_bar is None
                                            else event.pressure_bar):
                n_s = int(np.argmin(np.abs(dm.z - zs)))
                self.f_over = self.f_over + dm.phi[[4 * n_s, 4 * n_s + 1], :].T @ F
        self.layout = StateLayout.of(m, dm.race_inertia, dm.support, loop.n_states,
                                     event.coast_down, self.axial, nh)
        # the slowest impact damped: a fall through the clearance under standard gravity,
        # whatever the rotor's orientation — a floor on v₀ against the D = ζ/v₀ of a
        # grazing onset, not the rotor's own fall (a standing rotor has none radially, yet
        # touches its rings through its whirl)
        self.floor = np.sqrt(2 * GRAVITY * dm.clearance)
        self.v0 = self.floor.copy()
        # the rotor's axial force once the thrust bearing lets go: the residual thrust
        # and the weight along the axis (a standing rotor's whole weight)
        self.f_axial = self.thrust + dm.axial_weight
        # axially, a fall through the axial clearance under that force (or standard
        # gravity's acceleration, if larger)
        self.c_ax = dm.axial_clearance if self.stops else np.full(P, np.inf)
        self.floor_ax = np.sqrt(2 * max(abs(self.f_axial) / dm.mass, GRAVITY)
                                * np.where(np.isfinite(self.c_ax), self.c_ax, 0.0))
        self.v0_ax = self.floor_ax.copy()
        self.ring = dm.journal + dm.clearance
        self.C_held = dm.C + self.W0 * dm.G  # the damping and gyroscopics at a held speed
        self.i_s = loop.static / loop.ki
        self.digital = loop.sampled is not None
        self.held = []  # a digital controller's updates: (t, i_ref, clipped)
        self.x_d = np.zeros(loop.n_sampled)  # its state, before its update at t = 0
        self.all_down, self.fading = bool(self.down.all()), bool((loop.tau > 0).any())
        self.no_force, self.no_loop = np.zeros(len(names)), np.zeros(loop.n_states)
        self.no_clip = np.zeros(len(names), bool)
        self.i_fail = np.zeros(len(names))

    def _overload(self, overload) -> np.ndarray:
        """The overload's generalised force on the modes (zero without one)."""
        dm = self.dm
        if overload is None:
            return np.zeros(self.m)
        z_o, F_o = float(overload[0]), np.asarray(overload[1], float)
        if F_o.shape != (2,) or not np.isfinite(F_o).all() or not (
                dm.z[0] <= z_o <= dm.z[-1]):
            raise ConfigError(f"drop: overload: expected a position on the rotor "
                              f"({dm.z[0]:g} to {dm.z[-1]:g} m) and a finite force (x, y) "
                              f"in N, got {overload!r}")
        n_o = int(np.argmin(np.abs(dm.z - z_o)))
        return dm.phi[[4 * n_o, 4 * n_o + 1], :].T @ F_o

    # the state at the drop

    def start(self) -> np.ndarray:
        """The state when the AMBs let go: the levitated equilibrium or ``initial``, the
        loop's ``loop_state``, a digital controller's first update, the spin; and what
        the failed axes' coils carry at that instant."""
        dm, loop, event, L = self.dm, self.loop, self.event, self.layout
        m, n_loop = self.m, loop.n_states
        y = np.zeros(L.size)
        y[:m] = dm.q0
        if event.initial is not None:
            u0, du0 = (np.asarray(a, float) for a in event.initial)
            n_dof = dm.projector.shape[1]
            if u0.shape != (n_dof,) or du0.shape != (n_dof,) or not (
                    np.isfinite(u0).all() and np.isfinite(du0).all()):
                raise ConfigError(f"drop: initial: expected a finite displacement and "
                                  f"velocity of {n_dof} DOFs each, got shapes {u0.shape}, "
                                  f"{du0.shape}")
            y[:m], y[m:2 * m] = dm.projector @ u0, dm.projector @ du0
        n_d = loop.n_sampled
        if event.loop_state is not None:
            x0 = np.asarray(event.loop_state, float)
            if x0.shape != (n_loop + n_d,) or not np.isfinite(x0).all():
                raise ConfigError(f"drop: loop_state: expected {n_loop + n_d} finite "
                                  f"states, got shape {x0.shape}")
            y[L.i_loop:L.i_spin], self.x_d = x0[:n_loop], x0[n_loop:].copy()
        if self.digital:
            self.sample(0.0, y)
        Aa, _, Ca, Da = loop.coil
        na = Aa.shape[0]
        x_k0 = y[L.i_loop + na:L.i_spin]
        i_ref0 = self.held[-1][1] if self.digital else loop.reference(
            loop.sensor @ (y[:m] - dm.q0), x_k0)[0]
        self.i_fail = Ca @ y[L.i_loop:L.i_loop + na] + Da @ i_ref0
        if event.coast_down:
            y[L.i_spin] = self.W0
        return y

    def tolerances(self) -> np.ndarray:
        """The integrator's absolute tolerance per state (:func:`tolerances`)."""
        dm, loop, L = self.dm, self.loop, self.layout
        races = L.races
        # the loop's states by what they add to a current: of the order of the static
        # currents, the limit or 1 mA, whichever is largest
        i_scale = max(float(np.abs(self.i_s).max(initial=0.0)),
                      float(loop.limit[np.isfinite(loop.limit)].min(initial=0.0)), 1e-3)
        gain = np.abs(np.hstack([loop.coil[2], loop.controller[2]])).max(axis=0,
                                                                        initial=0.0)
        c_min = dm.clearance.min()
        return tolerances(
            L, self.event.rtol, c_min,
            abs(self.W0) * dm.journal[races] / self.ring[races], self.W0,
            dm.mass * GRAVITY * c_min,
            float(self.c_ax[self.stops].min()) if self.axial else None,
            i_scale / np.where(gain > 0, gain, 1.0))

    # the spin

    def spin(self, y) -> float:
        """The spin speed Ω (rad/s): held, or the coasting state's."""
        return float(y[self.layout.i_spin]) if self.event.coast_down else self.W0

    def angle(self, t, y) -> float:
        """The spin's angle θ (rad)."""
        return float(y[self.layout.i_spin + 1]) if self.event.coast_down else self.W0 * t

    # the rings

    def contacts(self, t, y, parts=None) -> list:
        """Per plane: relative position, δ, normal force, friction, n, t, slip speed
        (``parts``: ``layout.unpack(y)`` where the caller has it)."""
        dm = self.dm
        eta, deta, wr, s, ds = self.layout.unpack(y) if parts is None else parts
        out = []
        for p in range(self.P):
            r = dm.planes[p] @ eta - s[p]
            v = dm.planes[p] @ deta - ds[p]
            d = math.hypot(r[0], r[1])
            delta = d - dm.clearance[p]
            if delta <= 0.0 or d == 0.0:
                out.append((r, delta, 0.0, 0.0, None, None, 0.0))
                continue
            n = r / d
            tang = np.array([-n[1], n[0]])
            law = dm.laws[p]
            N = float(law.force(delta, float(n @ v), self.v0[p]))
            slip = float(tang @ v) + self.spin(y) * dm.journal[p] - wr[p] * self.ring[p]
            Ft = float(friction_force(law.friction, N, slip, law.friction_velocity))
            out.append((r, delta, N, Ft, n, tang, slip))
        return out

    def axial_contacts(self, y, wr) -> list:
        """Per plane in axial contact: (plane, δ_a, normal force, friction, slip speed) of
        the rotor's shoulder on the ring's face at the ring's bore radius, the slip that
        of the spin against the ring's."""
        if not self.axial:
            return []
        i_ax = self.layout.i_ax
        z, vz = float(y[i_ax]), float(y[i_ax + 1])
        out = []
        for p in self.stops:
            delta = abs(z) - self.c_ax[p]
            if delta <= 0.0:
                continue
            law = self.dm.axial_laws[p]
            # δ̇ = sign(z)·ż
            N = float(law.force(delta, vz if z >= 0 else -vz, self.v0_ax[p]))
            slip = (self.spin(y) - wr[p]) * self.ring[p]
            Ft = float(friction_force(law.friction, N, slip, law.friction_velocity))
            out.append((p, delta, N, Ft, slip))
        return out

    # the AMB loop

    def fade(self, t):
        """Each failed axis's force's share left at t (module docstring of
        :mod:`ambseal.analysis.drop_loop`): e^{−2t R/L}, 0 at once."""
        tau = np.where(self.loop.tau > 0, self.loop.tau, 1.0)
        return np.where(self.loop.tau > 0, np.exp(-2.0 * t / tau), 0.0)

    def amb(self, t, y, hold=None):
        """The axes' forces (N), the loop's state derivative, the currents (A) and where
        the loop's reference was clipped; a digital controller's reference is the one
        held (``hold``: (i_ref, clipped), default the last update's). With every axis
        lost the loop drives nothing: its states are held, and the forces are the fading
        ones alone (none where every coil lets go at once)."""
        loop, dm, L = self.loop, self.dm, self.layout
        m = self.m
        if self.all_down:
            if not self.fading:
                return self.no_force, self.no_loop, self.no_force, self.no_clip
            b2 = self.fade(t)
            pull = loop.ks * (loop.axis @ (y[:m] - dm.q0))
            return (b2 * (loop.static + loop.ki * self.i_fail + pull), self.no_loop,
                    np.sqrt(b2) * (self.i_s + self.i_fail), self.no_clip)
        Aa, Ba, Ca, Da = loop.coil
        Ak, Bk, _, _ = loop.controller
        na = Aa.shape[0]
        dev = y[:m] - dm.q0
        x_a, x_k = y[L.i_loop:L.i_loop + na], y[L.i_loop + na:L.i_spin]
        sensed = loop.sensor @ dev
        if self.digital:
            i_ref, clipped = self.held[-1][1:] if hold is None else hold
        else:
            i_ref, clipped = loop.reference(sensed, x_k)
        i_e = Ca @ x_a + Da @ i_ref
        pull = loop.ks * (loop.axis @ dev)
        fch = loop.static + loop.ki * i_e + pull
        b2 = self.fade(t)
        down = self.down
        fch[down] = (b2 * (loop.static + loop.ki * self.i_fail + pull))[down]
        current = np.where(down, np.sqrt(b2) * (self.i_s + self.i_fail), self.i_s + i_e)
        return (fch, np.concatenate([Aa @ x_a + Ba @ i_ref, Ak @ x_k + Bk @ sensed]),
                current, clipped & ~down)

    def sample(self, t, y) -> None:
        """The digital controller's update at the sample instant t (module docstring of
        :mod:`ambseal.analysis.drop_loop`): its output held from t."""
        loop = self.loop
        A_d, B_d, C_d, D_d, _ = loop.sampled
        y_k = loop.sensor @ (y[:self.m] - self.dm.q0)
        u = C_d @ self.x_d + D_d @ y_k
        self.x_d = A_d @ self.x_d + B_d @ y_k
        self.held.append((t, *loop.clip(-u)))

    # the right-hand side, force by force

    def _loads(self, t, y, deta):
        """Gravity, the overload, the AMBs' forces and the unbalance on the modes, their
        power, and the loop's state derivative."""
        dm, loop = self.dm, self.loop
        f = dm.gravity + self.f_over
        power = float(self.f_over @ deta)
        fch, dloop, _, _ = self.amb(t, y)
        if fch is not self.no_force:
            f += loop.axis.T @ fch
            power += float(fch @ (loop.axis @ deta))
        u = self.event.unbalance_kgm
        if u:
            W, th = self.spin(y), self.angle(t, y)
            fu = u * W * W * np.array([math.cos(th), math.sin(th)])
            f += dm.cg_rows.T @ fu
            power += float(fu @ (dm.cg_rows @ deta))
        return f, power, dloop

    def _rings(self, t, y, parts, f):
        """The rings' normal and friction forces added to ``f``; the friction's torque on
        the rotor, each plane's friction power, the rings' spin-up and the supports'
        accelerations."""
        dm, P = self.dm, self.P
        _, _, wr, s, ds = parts
        dwr = np.zeros(P)
        dsup = {}
        heat = np.zeros(P)  # each plane's friction power (W)
        torque = 0.0
        for p, (r, delta, N, Ft, n, tang, slip) in enumerate(self.contacts(t, y, parts)):
            F = np.zeros(2) if n is None else -N * n - Ft * tang
            if n is not None:
                f += dm.planes[p].T @ F
            torque -= Ft * dm.journal[p]
            heat[p] = Ft * slip
            if dm.race_inertia[p] > 0:
                w_d = dm.laws[p].friction_velocity / self.ring[p]
                dwr[p] = (Ft * self.ring[p] - dm.drag[p] * math.tanh(wr[p] / w_d)) \
                    / dm.race_inertia[p]
            if dm.support[p] is not None:
                ms, ks, cs = dm.support[p]
                dsup[p] = (-F - ks * s[p] - cs * ds[p]) / ms
        return torque, heat, dwr, dsup

    def _axial(self, y, wr, dy, torque, heat, dwr):
        """The rotor as a rigid body along its axis, on the thrust, its axial weight and
        the faces: its derivatives into ``dy``; the faces' friction added to ``torque``,
        ``heat`` and the rings' spin-up; the thrust's power (the weight's is in the
        energy, as its potential)."""
        i_ax, dm = self.layout.i_ax, self.dm
        f_ax = self.f_axial
        for p, _, N, Ft, slip in self.axial_contacts(y, wr):
            f_ax -= math.copysign(N, y[i_ax])
            torque -= Ft * self.ring[p]
            heat[p] += Ft * slip
            if dm.race_inertia[p] > 0:
                dwr[p] += Ft * self.ring[p] / dm.race_inertia[p]
        dy[i_ax], dy[i_ax + 1] = y[i_ax + 1], f_ax / dm.mass
        return torque, self.thrust * float(y[i_ax + 1])

    def _seals(self, y, eta, deta, acc, dy):
        """(I + M_s) η̈ = the rest − K_s Δη − C_s η̇, the housings' derivatives into
        ``dy``: the modes' accelerations and the seals' power (work from outside)."""
        L, m = self.layout, self.m
        nh = L.n_housing
        h, dh = y[L.i_house:L.i_house + nh], y[L.i_house + nh:L.i_house + 2 * nh]
        pushed = -self.K_s @ np.r_[eta - self.dm.q0, h] - self.C_s @ np.r_[deta, dh]
        both = self.M_inv @ (np.r_[acc, np.zeros(nh)] + pushed)
        dy[L.i_house:L.i_house + nh], dy[L.i_house + nh:L.i_house + 2 * nh] = dh, both[m:]
        return both[:m], float((pushed[:m] - self.M_s[:m] @ both) @ deta)

    def rhs(self, t, y):
        """dy/dt of the drop at (t, y)."""
        dm, L, m, P = self.dm, self.layout, self.m, self.P
        parts = L.unpack(y)
        eta, deta, wr, s, ds = parts
        f, power, dloop = self._loads(t, y, deta)
        dy = np.empty_like(y)
        torque, heat, dwr, dsup = self._rings(t, y, parts, f)
        if self.axial:
            torque, p_thrust = self._axial(y, wr, dy, torque, heat, dwr)
            power += p_thrust
        dy[L.i_heat:L.i_heat + P] = heat
        W = self.spin(y)
        dy[:m] = deta
        coast = self.event.coast_down
        acc = f - (self.C_held if not coast else dm.C + W * dm.G) @ deta - dm.K @ eta
        if self.sealed:
            acc, p_seals = self._seals(y, eta, deta, acc, dy)
            power += p_seals
        dy[m:2 * m] = acc
        if coast:
            dy[L.i_spin] = (torque - self.event.drag_torque * math.tanh(W / 0.1)) \
                / dm.polar_inertia
            dy[L.i_spin + 1] = W
        else:  # the drive supplies the friction's torque
            power -= torque * W
        dy[-1] = power
        dy[L.i_loop:L.i_spin] = dloop
        dy[2 * m:2 * m + L.races.size] = dwr[L.races]
        for k, p in enumerate(L.supported):
            i = L.support_at(k)
            dy[i:i + 2] = ds[p]
            dy[i + 2:i + 4] = dsup[p]
        return dy

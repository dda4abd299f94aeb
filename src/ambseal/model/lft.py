"""Physical parameters as LFT channels of a state-space plant.

A change θ (in the parameter's own SI unit) of a stiffness, damping or force factor
changes the plant as

    A(θ) = A + B_θ θ C_θ,    B(θ) = B + B_θ θ D_θ,

with θ entering as θ·I_r when the parameter appears r times (a seal's k and −k share one
parameter, thesis P5 §4.1 item 3 and Appendix A). This is the upper LFT
G_fi = [[A, B_θ, B], [C_θ, 0, D_θ], [C, 0, D]] of thesis P1 Eqs. 46–52, P2 Eqs. 4–8 and
P4 Eqs. 7–13; a stiffness change of a single direction at node j changes one column of
A_f (P1 Eq. 48). A reduced model carries the same channels through its modal
transformation: B_θ,r = T_L B_θ, C_θ,r = C_θ T_R (P4 Eqs. 11–13).
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

import ambseal.lti as lti
from ambseal.errors import ModelError

# ``lti.name`` is looked up where it is used (ambseal.lti loads each name's module on first
# use), and python-control is imported in the one method that calls it: the model's modes
# (``ambseal modes``) use the channels of the rotor's elements only, and python-control
# costs 1 s of start-up.

__all__ = ["Channel", "Parameter", "Plant", "channel_tag"]


def channel_tag(name: str, j: int = 0) -> str:
    """The signal tag of repeat ``j`` of parameter ``name`` in a python-control system:
    ``"seal.k"``, 0 → ``"seal__k_0"`` ('.' is not allowed in signal names)."""
    return f"{name.replace('.', '__')}_{j}"


@dataclass(frozen=True)
class Channel:
    """A parameter of the second-order model as a low-rank change of K, C or B_u.

    ΔK = θ U Vᵀ (``kind="K"``), ΔC = θ U Vᵀ (``kind="C"``), or ΔB_u = θ U e_jᵀ with
    j = ``V[:, 0]`` (``kind="B"``, a force factor on input j): the channel description of
    thesis P1 Eqs. 48–50 before it becomes a state-space :class:`Parameter`
    (:func:`ambseal.model.rig.mechanical_plant`). Element modules (``amb``, ``seal``,
    ``spring``) build their own.

    Attributes
    ----------
    name : str
        ``"{element}.{key}"``, e.g. ``"A.Ks_zeta"``.
    nominal : float
        The value in the model (SI).
    unit : str
        Its SI unit.
    kind : str
        ``"K"``, ``"C"`` or ``"B"``.
    U : ndarray, shape (n_dof, r)
    V : ndarray, shape (n_dof, r) for K/C; (r, 1) integer input indices for B
    """

    name: str
    nominal: float
    unit: str
    kind: str
    U: np.ndarray
    V: np.ndarray


@dataclass(frozen=True)
class Parameter:
    """One named physical parameter and its LFT channels.

    Attributes
    ----------
    name : str
        E.g. ``"A.Ks_zeta"``, ``"A.Ki_eta"``, ``"coupling.kxx"``, ``"seal.k"``.
    nominal : float
        Its value in the model (SI).
    unit : str
        SI unit of the value and of θ.
    B : ndarray, shape (n_states, r)
    C : ndarray, shape (r, n_states)
    D : ndarray, shape (r, n_inputs)
    """

    name: str
    nominal: float
    unit: str
    B: np.ndarray
    C: np.ndarray
    D: np.ndarray

    def __post_init__(self):
        for X in (self.B, self.C, self.D):  # read-only: shared with every copy of the plant
            lti.freeze(X)

    @property
    def repeats(self) -> int:
        """How many times θ appears (r)."""
        return self.B.shape[1]


@dataclass(frozen=True)
class Plant:
    """A state-space plant with named signals and parameter channels.

    Continuous time: ẋ = A x + B u, y = C x + D u. Inputs are the current references
    ``i_<axis>`` (A) per actuator axis, then any extra force inputs ``F<k>_<x|y>`` (N);
    outputs are the sensor displacements ``y_<axis>`` (m), ``<axis>`` such as ``A_zeta``.
    A controller (:mod:`ambseal.machine.controller`) has the reverse names, inputs
    ``y_<axis>`` and outputs ``i_<axis>``, so python-control's ``interconnect`` closes the
    loop by name (with the sign of ``i = −K y``).

    Immutable: its arrays, and the arrays they are views of, are made read-only
    (:func:`ambseal.lti.freeze`); changes give new plants (:meth:`with_changes`).

    Attributes
    ----------
    A : ndarray, shape (n_states, n_states)
        State matrix (1/s); the state is ``[q; q̇]`` of the full model or modal coordinates
        of a reduced one.
    B : ndarray, shape (n_states, n_inputs)
        Input matrix.
    C : ndarray, shape (n_outputs, n_states)
        Output matrix (displacements in m).
    D : ndarray, shape (n_outputs, n_inputs)
        Feedthrough (zero for the rotor models).
    input_names : tuple of str
        ``i_<axis>`` (A), then ``F<k>_<x|y>`` (N).
    output_names : tuple of str
        ``y_<axis>`` (m).
    state_names : tuple of str
        One name per state.
    parameters : dict of str to Parameter
        The physical parameters' LFT channels (thesis P1 Eqs. 46–52), by name.
    """

    A: np.ndarray
    B: np.ndarray
    C: np.ndarray
    D: np.ndarray
    input_names: tuple[str, ...]
    output_names: tuple[str, ...]
    state_names: tuple[str, ...]
    parameters: dict[str, Parameter] = field(default_factory=dict)

    def __post_init__(self):
        # read-only from here: the systems made from the plant share its state matrix
        # (to_statespace), the memos of its decompositions key it by its digest, computed
        # once for a frozen array (ambseal.lti.freeze), and build_plant hands the same
        # plant to every caller
        for X in (self.A, self.B, self.C, self.D):
            lti.freeze(X)

    @property
    def n_states(self) -> int:
        return self.A.shape[0]

    @property
    def nbytes(self) -> int:
        """Bytes of the state-space arrays (what a memo of plants weighs)."""
        return int(sum(X.nbytes for X in (self.A, self.B, self.C, self.D)))

    @property
    def axes(self) -> tuple[str, ...]:
        """The actuator axes ``<axis>`` that have both a current input ``i_<axis>`` and a
        sensor output ``y_<axis>``, in input order."""
        outs = set(self.output_names)
        return tuple(n[2:] for n in self.input_names
                     if n.startswith("i_") and f"y_{n[2:]}" in outs)

    def current_inputs(self) -> list[int]:
        """Indices of the current inputs ``i_<axis>`` of :attr:`axes`."""
        names = {f"i_{a}" for a in self.axes}
        return [j for j, n in enumerate(self.input_names) if n in names]

    def parameter(self, name: str) -> Parameter:
        """The parameter ``name``; raises ModelError listing the known names."""
        try:
            return self.parameters[name]
        except KeyError:
            known = ", ".join(self.parameters)
            raise ModelError(f"unknown parameter {name!r} (expected one of: {known})") from None

    def channels(self, names: list[str] | tuple[str, ...]) -> tuple[np.ndarray, ...]:
        """Stacked (B_θ, C_θ, D_θ) of ``names`` in order, each repeated r times.

        Returns arrays (n_states, Σr), (Σr, n_states), (Σr, n_inputs).
        """
        ps = [self.parameter(n) for n in names]
        if not ps:
            n, m = self.B.shape
            return np.zeros((n, 0)), np.zeros((0, n)), np.zeros((0, m))
        return (
            np.hstack([p.B for p in ps]),
            np.vstack([p.C for p in ps]),
            np.vstack([p.D for p in ps]),
        )

    def with_changes(self, changes: dict[str, float]) -> "Plant":
        """The plant with parameter changes θ (SI) applied through the LFT, no rebuild.

        The nominal values of the returned plant's parameters move by θ.
        """
        A, B = self.A.copy(), self.B.copy()
        params = dict(self.parameters)
        for name, theta in changes.items():
            p = self.parameter(name)
            A += theta * (p.B @ p.C)
            B += theta * (p.B @ p.D)
            params[name] = replace(p, nominal=p.nominal + theta)
        return replace(self, A=A, B=B, parameters=params)

    def with_values(self, values: dict[str, float]) -> "Plant":
        """The plant with parameters set to absolute values (SI) through the LFT."""
        return self.with_changes({n: v - self.parameter(n).nominal for n, v in values.items()})

    def select_inputs(self, names: list[str] | tuple[str, ...]) -> "Plant":
        """The plant restricted to some inputs (parameter D_θ restricted alike)."""
        idx = [self.input_names.index(n) for n in names]
        params = {k: replace(p, D=p.D[:, idx]) for k, p in self.parameters.items()}
        return replace(
            self, B=self.B[:, idx], D=self.D[:, idx], input_names=tuple(names), parameters=params
        )

    def to_statespace(self):
        """The plant as a ``control.StateSpace`` with named inputs, outputs and states; its
        ``A`` shared with the plant's (:func:`ambseal.lti.shared_ss`), not copied."""
        lti.picklable()
        return lti.shared_ss(
            self.A,
            self.B,
            self.C,
            self.D,
            inputs=list(self.input_names),
            outputs=list(self.output_names),
            states=list(self.state_names),
        )

    def lft(self, names: list[str] | tuple[str, ...]):
        """G_fi of thesis P4 Eq. 7 as a ``control.StateSpace``.

        Inputs are [w_θ (Σr), u], outputs [z_θ (Σr), y]; closing w_θ = θ z_θ (upper LFT)
        gives the plant with changes θ. The θ channels are named ``w_<tag>``, ``z_<tag>``
        with :func:`channel_tag` (python-control allows no '.' in a signal name).
        """
        import control  # start-up: see the imports

        lti.picklable()
        Bt, Ct, Dt = self.channels(names)
        r = Bt.shape[1]
        tags = [channel_tag(n, j) for n in names for j in range(self.parameter(n).repeats)]
        B = np.hstack([Bt, self.B])
        C = np.vstack([Ct, self.C])
        D = np.block([[np.zeros((r, r)), Dt], [np.zeros((self.C.shape[0], r)), self.D]])
        return control.ss(
            self.A,
            B,
            C,
            D,
            inputs=[f"w_{t}" for t in tags] + list(self.input_names),
            outputs=[f"z_{t}" for t in tags] + list(self.output_names),
            states=list(self.state_names),
        )

    def transformed(self, T_L: np.ndarray, T_R: np.ndarray, state_names: tuple[str, ...]) -> "Plant":
        """The plant in reduced coordinates x_r = T_L x (P1 Eqs. 43–45, P4 Eq. 11–13)."""
        params = {
            k: replace(p, B=T_L @ p.B, C=p.C @ T_R) for k, p in self.parameters.items()
        }
        return replace(
            self,
            A=T_L @ self.A @ T_R,
            B=T_L @ self.B,
            C=self.C @ T_R,
            state_names=state_names,
            parameters=params,
        )

    def series_actuator(
        self,
        Aa: np.ndarray,
        Ba: np.ndarray,
        Ca: np.ndarray,
        Da: np.ndarray,
        inputs: list[int],
        label: str = "act",
    ) -> "Plant":
        """Put the same SISO actuator in series with each of the ``inputs`` (indices).

        The actuator states are appended; a parameter whose D_θ acted on the actuated input
        (a force factor Ki) then acts through C_θ on the actuator's output, so Ki enters A.
        """
        A, B, C, D, C_out, D_out = lti.series_inputs((self.A, self.B, self.C, self.D),
                                                 (Aa, Ba, Ca, Da), inputs)
        na = Aa.shape[0]
        params = {}
        for key, p in self.parameters.items():
            Dp = p.D.copy()
            Dp[:, inputs] = 0.0
            params[key] = replace(
                p,
                B=np.vstack([p.B, np.zeros((A.shape[0] - p.B.shape[0], p.repeats))]),
                C=np.hstack([p.C, np.zeros((p.C.shape[0], A.shape[0] - p.C.shape[1]))])
                + p.D[:, inputs] @ C_out,
                D=Dp + p.D[:, inputs] @ D_out,
            )
        names = tuple(
            f"{label}_{self.input_names[i]}_{j}" for i in inputs for j in range(na)
        )
        return replace(
            self, A=A, B=B, C=C, D=D, state_names=self.state_names + names, parameters=params
        )

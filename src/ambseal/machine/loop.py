"""The closed loop of a plant and a controller, and the one loop every verdict is taken on.

**Convention** (:mod:`ambseal.machine.controller`): the controller ``K`` maps the plant's
outputs ``y`` to its inputs with **negative feedback**, ``u = −K y + d``.

* :func:`closed_loop` — close ``K`` around ``G`` (continuous, or discrete of one sample
  time), with optional further inputs sharing ``G``'s states; its poles and the verdict of
  :func:`ambseal.robust.stability.is_stable`.
* :func:`judged_loop` — **the** loop a controller is judged on, as it will run: a
  continuous controller acts through the target's hold and computation delay, modelled as
  a lag (:func:`ambseal.robust.delay.loop_delay`) in front of every control input of the
  plant; a discrete controller (its computation delay among its states) is closed on the
  plant sampled exactly by a zero-order hold at its sample time (Franklin, Powell &
  Workman, *Digital Control of Dynamic Systems*, 3rd ed., §6.3). Every command that says
  "stable" — ``run``, ``design``, ``export``, ``sweep``, ``campbell``, ``modes`` — says it
  of this loop, by the one rule.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from functools import cached_property
from typing import Any, NamedTuple

import numpy as np

from ambseal.errors import ModelError
from ambseal.lti import (
    STRUCTURED_STATES,
    feedback_matrices,
    feedback_poles,
    feedback_response,
    freqresp_at,
    json_float,
    json_list,
    labels,
    sampled_modal_form,
    sampled_response_at,
    select_inputs,
    series_inputs,
    shared_ss,
    simulate_modal_loop,
    ss_matrices,
    wired,
    zoh,
)
from ambseal.robust import decay_rate, is_stable

__all__ = ["ClosedLoop", "JudgedLoop", "closed_loop", "judged_loop", "delayed_plant",
           "sampled_plant", "sampled_loop_matrix", "loop_matrices", "sample_time"]


@dataclass(frozen=True, eq=False)
class ClosedLoop:
    """The closed loop of ``(G, K)`` with ``u = −K y + d`` and optional force inputs.

    Attributes
    ----------
    system : control.StateSpace
        Continuous, or discrete with sample time ``dt``. Inputs: ``d_<u>`` current disturbances added to the controller output (A), one per
        plant input, then the force inputs of ``Gf`` under their own names (N), if given.
        Outputs: the plant outputs under their own names (m), then ``i_<u>`` the controller
        output ``−K y`` (A; the "control action" of P5 Fig. 14). States: plant states then
        controller states.
    poles : ndarray of complex, shape (n + n_K,)
        Closed-loop poles (rad/s), sorted by decreasing real part; of a discrete loop the
        ``z`` (sorted by decreasing ``|z|``).
    max_real_pole : float
        Largest real part of the poles (1/s); ``< 0`` means asymptotically stable. Of a
        discrete loop the same rate of its slowest-decaying pole, ``ln max|z| / dt``.
    stable : bool
        The poles are stable by the package's one rule
        (:func:`ambseal.robust.stability.is_stable`).
    n_plant_inputs, n_plant_outputs, n_force_inputs : int
        Channel counts, so ``system`` can be sliced without parsing names.
    dt : float
        Sample time (s) of a discrete loop, 0 for a continuous one.
    inputs, outputs : tuple of str
        The names of ``system``'s inputs and outputs.
    _build : callable
        Makes ``system`` (no arguments); called once, when ``system`` is first read.
    _modal_from : tuple or None
        ``(G, K, lag)`` for a loop on a large plant: matrices of the continuous plant's
        control inputs, of the controller, and of the lag in front of the plant (None:
        none, or a discrete loop on the plant sampled by a zero-order hold); the loop's
        time response then comes from the plant's modal form (:meth:`modal_response`).

    ``system`` is built when first asked for: a loop on a large plant sampled by
    :func:`judged_loop` has its poles and its time response (:meth:`modal_response`)
    from the continuous plant's modal form, and its dense state space costs an ``expm``
    of the plant.
    """

    _build: Callable[[], Any] = field(repr=False)
    poles: np.ndarray
    max_real_pole: float
    stable: bool
    n_plant_inputs: int
    n_plant_outputs: int
    n_force_inputs: int
    dt: float = 0.0
    inputs: tuple = ()
    outputs: tuple = ()
    _modal_from: tuple | None = field(default=None, repr=False)

    @cached_property
    def system(self) -> Any:
        """The closed loop as a ``control.StateSpace`` (inputs, outputs and states above)."""
        return self._build()

    def modal_response(self, d: np.ndarray, h: float) -> np.ndarray | None:
        """The outputs (``y`` then ``i``) of a loop on a large plant for the disturbances
        ``d`` added to the controller's outputs, held over steps of ``h``, from rest,
        without forming ``system``: a discrete loop stepped in the continuous plant's
        certified sampled modal form (:func:`ambseal.lti.freqresp.sampled_modal_form`,
        :func:`ambseal.lti.discrete.simulate_modal_loop`), a continuous one from its split
        along the plant's modal form (:func:`ambseal.lti.interconnect.feedback_response`).
        The samples of :func:`ambseal.lti.discrete.simulate_lti` on ``system`` (sampled
        by :func:`ambseal.lti.discrete.zoh` if continuous).

        Parameters
        ----------
        d : numpy.ndarray, shape (N, n_plant_inputs)
            Disturbances (A), one row per step.
        h : float
            The step (s); a discrete loop's own sample time.

        Returns
        -------
        numpy.ndarray, shape (N, n_plant_outputs + n_plant_inputs), or None
            ``None`` for any other loop, or where the modal path is not certified: take
            ``system`` then.
        """
        if self._modal_from is None:
            return None
        G, K, lag = self._modal_from
        if not self.dt:
            return feedback_response(G, K, d, h, lag=lag)
        form = sampled_modal_form(*G, self.dt)
        return None if form is None else simulate_modal_loop(*form, K, d)

    @property
    def s_poles(self) -> np.ndarray:
        """The poles as continuous rates (rad/s): ``poles``, or ``ln z / dt`` (the
        equivalent s-plane pole of each z, below Nyquist)."""
        if not self.dt:
            return self.poles
        with np.errstate(divide="ignore"):
            return np.log(self.poles.astype(complex)) / self.dt

    @property
    def max_abs_pole(self) -> float:
        """Largest ``|z|`` of a discrete loop (``< 1``: stable); NaN for a continuous one."""
        if not self.dt:
            return float("nan")
        return float(np.abs(self.poles).max()) if self.poles.size else 0.0

    def to_dict(self) -> dict:
        """JSON-safe summary (no state-space matrices): stability, poles (real/imag, rad/s)."""
        return {
            "n_states": int(self.poles.size),
            "stable": bool(self.stable),
            "max_real_pole": json_float(self.max_real_pole),
            "poles_real": json_list(self.poles.real),
            "poles_imag": json_list(self.poles.imag),
            "inputs": list(self.inputs),
            "outputs": list(self.outputs),
        }


def sample_time(sys: Any) -> float:
    """Sample time of a python-control system (0 if continuous or a matrix tuple).

    Parameters
    ----------
    sys : control.StateSpace or (A, B, C, D)
        The system.

    Returns
    -------
    float
        Sample time (s); 0 for a continuous system, a tuple, or python-control's
        unspecified ``dt=True``.
    """
    dt = getattr(sys, "dt", 0)
    return float(dt) if dt not in (None, True) else 0.0


def loop_matrices(G: Any, K: Any) -> tuple[tuple, tuple]:
    """``(A, B, C, D)`` of the plant and of the controller wired to it by signal names
    (:func:`ambseal.lti.interconnect.wired`), their time bases and shapes checked.

    Parameters
    ----------
    G : control.StateSpace or (A, B, C, D)
        The plant, ``nu`` inputs → ``ny`` outputs, continuous or discrete.
    K : control.StateSpace or (A, B, C, D)
        The controller, measurements → commands (``u = −K y``), on the plant's time base.

    Returns
    -------
    G, K : (A, B, C, D)
        The plant's matrices, and the controller's with its inputs and outputs in the
        plant's order (``ny`` inputs, ``nu`` outputs).

    Raises
    ------
    ModelError
        Different sample times, or a controller whose channels do not fit the plant's.
    """
    mg = ss_matrices(G, name="G", allow_discrete=True)
    mk = ss_matrices(wired(G, K), name="K", allow_discrete=True)
    if abs(sample_time(G) - sample_time(K)) > 1e-12 * max(sample_time(G), sample_time(K)):
        raise ModelError(f"G (dt={sample_time(G)}) and K (dt={sample_time(K)}) must share one time base")
    ny, nu = mg[3].shape
    if mk[3].shape != (nu, ny):
        raise ModelError(
            f"K has {mk[3].shape[1]} inputs and {mk[3].shape[0]} outputs; expected {ny} inputs"
            f" (G outputs, m) and {nu} outputs (G inputs, A)"
        )
    return mg, mk


def closed_loop(G: Any, K: Any, Gf: Any | None = None, *, atol: float = 0.0) -> ClosedLoop:
    """Close the loop ``u = −K y + d`` around ``G`` (and ``Gf`` sharing its states).

    Plant ``ẋ = A x + B u + B_f f``, ``y = C x + D u + D_f f``; controller
    ``ẋ_K = A_K x_K + B_K y``, ``i = −(C_K x_K + D_K y)``, ``u = i + d``, closed by
    :func:`ambseal.lti.interconnect.feedback_matrices`. Same result as
    ``control.feedback(G, K, sign=-1)`` for the ``d → y`` channel (tested side by side).

    Parameters
    ----------
    G : control.StateSpace
        Plant, ``nu`` current inputs (A) → ``ny`` displacement outputs (m).
    K : control.StateSpace
        Controller, ``ny`` inputs (m) → ``nu`` outputs (A).
    Gf : control.StateSpace, optional
        Plant with the same states and outputs and force inputs (N), e.g. at mid-span.
    atol : float
        Tolerance when checking that ``Gf`` has the same ``A`` and ``C`` as ``G``
        (compared relative to their norms: ``≤ atol + 1e-9 ‖·‖``).

    Returns
    -------
    ClosedLoop

    Raises
    ------
    ModelError
        If the dimensions of ``G``, ``K`` (and ``Gf``) do not fit, ``Gf`` has a different
        ``A`` or ``C``, or ``I + D D_K`` is singular (ill-posed loop).
    """
    return _closed(G, K, Gf, atol, None)


def _closed(G, K, Gf, atol, source, remake=None) -> ClosedLoop:
    """:func:`closed_loop`; ``source``: ``(G₀, lag)`` when ``G`` was made from the
    continuous ``G₀`` with the SISO ``lag`` (matrices) in front of every input, whose modal
    form then gives the poles (:func:`ambseal.lti.interconnect.feedback_poles`);
    ``remake``: makes ``(G, Gf)`` again (default: returns them).

    The state space of a loop on a large plant without feedthrough (``STRUCTURED_STATES``
    states or more) is built from ``remake`` only when its dense eigenvalues or
    ``system`` are asked for, and not kept: the judgement holds a design's loops at every
    condition at once, each would keep n² numbers (28 MB at 1 888 states) that the modal
    paths never read, and the eigendecomposition of the plant that they do read peaks
    while they are closed."""
    parts = _loop_parts(G, K, Gf, atol)
    (A, B, C, D), mk, dt = parts.g, parts.k, parts.dt
    names = (parts.inputs, parts.outputs)
    G0, lag = (A, B, C, D), None
    if source is not None:
        G0, lag = ss_matrices(source[0]), source[1]
    modal_from = None if source is None else (G0, mk, lag)
    if A.shape[0] < STRUCTURED_STATES or np.any(D):  # (an ill-posed loop raises here)
        sys = _loop_system(parts)
        poles = feedback_poles(G0, mk, dt=dt, state_matrix=sys.A, lag=lag)
        return _loop(lambda: sys, poles, dt, B.shape[1], C.shape[0], names, modal_from)
    remake = remake or (lambda G=G, Gf=Gf: (G, Gf))

    def build():  # neither the loop nor (with remake) G is kept
        G1, Gf1 = remake()
        return _loop_system(_loop_parts(G1, K, Gf1, atol))

    poles = feedback_poles(G0, mk, dt=dt, state_matrix=lambda: build().A, lag=lag)
    return _loop(build, poles, dt, B.shape[1], C.shape[0], names, modal_from)


def _loop(build, poles, dt, nu, ny, names, modal_from=None) -> ClosedLoop:
    poles = poles[np.argsort(-np.abs(poles) if dt else -poles.real, kind="stable")]
    G = modal_from[0] if modal_from else None
    if G is not None and (G[0].shape[0] < STRUCTURED_STATES or np.any(G[3])):
        modal_from = None  # the modal paths take large plants without feedthrough
    return ClosedLoop(build, poles, decay_rate(poles, dt), is_stable(poles, dt), nu, ny,
                      len(names[0]) - nu, dt, *names, modal_from)


def _names(G, f_names, nu, ny) -> tuple[list, list]:
    """The closed loop's input and output names (:class:`ClosedLoop`): ``G``'s, and
    ``f_names`` of the external inputs."""
    u_names = labels(G, "input", nu, "u")
    return ([f"d_{u}" for u in u_names] + list(f_names),
            list(labels(G, "output", ny, "y")) + [f"i_{u}" for u in u_names])


def _loop_parts(G, K, Gf, atol):
    """(G's matrices, K's wired matrices, ``(B_f, D_f)``, the closed loop's input and
    output names) of :func:`closed_loop`, checked."""
    (A, B, C, D), mk = loop_matrices(G, K)
    n, nu = B.shape
    ny = C.shape[0]
    if Gf is not None:
        Af, Bf, Cf, Df = ss_matrices(Gf, name="Gf", allow_discrete=True)
        if Af.shape != A.shape or Cf.shape != C.shape:
            raise ModelError(f"Gf must share G's states and outputs: A{Af.shape} vs {A.shape}, C{Cf.shape} vs {C.shape}")
        for nm, X, Y in (("A", Af, A), ("C", Cf, C)):
            if _same(X, Y):  # two selections of one plant (an n² difference saved)
                continue
            if np.max(np.abs(X - Y), initial=0.0) > atol + 1e-9 * max(np.max(np.abs(Y), initial=0.0), 1.0):
                raise ModelError(f"Gf.{nm} differs from G.{nm}: Gf must have the same states as G")
        nf = Bf.shape[1]
    else:
        Bf, Df, nf = np.zeros((n, 0)), np.zeros((ny, 0)), 0
    inputs, outputs = _names(G, labels(Gf, "input", nf, "f") if Gf is not None else (),
                             nu, ny)
    return _Parts((A, B, C, D), mk, (Bf, Df), tuple(inputs), tuple(outputs), sample_time(G))


class _Parts(NamedTuple):
    """A loop before it is closed (:func:`_loop_parts`)."""

    g: tuple  # the plant's (A, B, C, D)
    k: tuple  # the controller's, wired to it
    f: tuple  # (B_f, D_f) of the external inputs
    inputs: tuple  # the closed loop's input names
    outputs: tuple  # and output names
    dt: float


def _same(X, Y) -> bool:
    """Whether the arrays are views of the same numbers (same memory, shape and strides)."""
    return (X.shape == Y.shape and X.strides == Y.strides and X.dtype == Y.dtype
            and X.__array_interface__["data"][0] == Y.__array_interface__["data"][0])


def _loop_system(parts):
    """The closed loop's ``control.StateSpace`` (:class:`ClosedLoop`) from
    :func:`_loop_parts`."""
    try:
        Acl, Bcl, Ccl, Dcl = feedback_matrices(parts.g, parts.k, parts.f)
    except ModelError:
        raise ModelError("closed_loop: I + D·D_K is singular; the loop is ill-posed") from None
    n = parts.g[0].shape[0]
    states = [f"x[{i}]" for i in range(n)] + [f"xK[{i}]" for i in range(Acl.shape[0] - n)]
    return shared_ss(Acl, Bcl, Ccl, Dcl, parts.dt, inputs=list(parts.inputs),
                     outputs=list(parts.outputs), states=states, name="closed_loop")


def _sampled_loop(P, K, cur, rest, dt) -> ClosedLoop:
    """The discrete ``K`` closed on the continuous ``P`` sampled at ``dt`` (its inputs
    ``cur`` driven): poles from the continuous plant with the hold
    (:func:`ambseal.lti.interconnect.feedback_poles`), and, for a large plant without
    feedthrough, the time response from its modal form (:meth:`ClosedLoop.modal_response`);
    the sampled plant's dense state space only when ``system`` is asked for."""
    G0 = select_inputs(P, cur)
    mg = ss_matrices(G0)
    mk = ss_matrices(wired(G0, K), name="K", allow_discrete=True)
    ny, nu = mg[3].shape
    if mk[3].shape != (nu, ny):
        raise ModelError(
            f"K has {mk[3].shape[1]} inputs and {mk[3].shape[0]} outputs; expected {ny} inputs"
            f" (G outputs, m) and {nu} outputs (G inputs, A)")
    poles = feedback_poles(mg, mk, dt=dt, hold=dt)

    def build():
        Pj = sampled_plant(P, dt, cur)
        Gf = select_inputs(Pj, rest) if rest else None
        return _loop_system(_loop_parts(select_inputs(Pj, cur), K, Gf, 0.0))

    names = _names(G0, [P.input_labels[j] for j in rest], nu, ny)
    return _loop(build, poles, dt, nu, ny, tuple(map(tuple, names)), (mg, mk, None))


@dataclass(frozen=True, eq=False)
class JudgedLoop:
    """A controller closed on a plant as it will run (:func:`judged_loop`).

    Attributes
    ----------
    plant : control.StateSpace
        The plant as the controller sees it: with the delay lag in front of its control
        inputs (continuous), or sampled by a zero-order hold at the controller's sample
        time (discrete); every input and output name kept.
    loop : ClosedLoop
        The closed loop (control inputs closed, the other inputs external); its
        ``stable`` is the verdict.
    source : control.StateSpace
        The continuous plant ``plant`` was made from.
    delay : control.StateSpace or None
        The lag in front of the control inputs of a continuous ``plant``.
    control_inputs : tuple of int
        The inputs of ``plant`` the controller drives.
    _plant : callable
        Makes ``plant`` (no arguments); called once, when ``plant`` is first read.
    """

    _plant: Callable[[], Any] = field(repr=False)
    loop: ClosedLoop
    source: Any
    delay: Any
    control_inputs: tuple

    @cached_property
    def plant(self) -> Any:
        """The plant as the controller sees it (above); a sampled one is formed when first
        asked for (an ``expm`` of the plant)."""
        return self._plant()

    @property
    def stable(self) -> bool:
        """The verdict (:func:`ambseal.robust.stability.is_stable` on the loop's poles)."""
        return self.loop.stable

    def plant_response(self, w: np.ndarray) -> np.ndarray:
        """``plant``'s frequency response at ``w`` (rad/s; at ``e^{jω dt}`` for a sampled
        plant), from the modal form of the continuous plant it was made from: the delayed
        plant's is the plant's times the lag's on the control inputs, the sampled plant's
        :func:`ambseal.lti.freqresp.sampled_response_at` — no eigendecomposition of the
        delayed or sampled plant.

        Parameters
        ----------
        w : ndarray, shape (n_w,)
            Angular frequencies (rad/s), at most Nyquist for a sampled plant.

        Returns
        -------
        ndarray of complex, shape (n_w, ny, nu)
            Outputs per input of ``plant`` (all its inputs, in its order).
        """
        dt = self.loop.dt
        if dt:  # per input group, as sampled_plant samples them
            P, cur = self.source, list(self.control_inputs)
            return sampled_response_at(P, dt, w, groups=(
                cur, [j for j in range(P.ninputs) if j not in cur]))
        H = freqresp_at(self.source, 1j * w)
        if self.delay is not None:
            cur = list(self.control_inputs)
            H[:, :, cur] *= freqresp_at(self.delay, 1j * w)[:, :1, :1]
        return H


def delayed_plant(P, inputs, delay):
    """The continuous plant ``P`` with the SISO ``delay`` system in front of each input in
    ``inputs`` (:func:`ambseal.lti.interconnect.series_inputs`), signal names kept."""

    def mats(S):
        return tuple(np.asarray(getattr(S, m), float) for m in ("A", "B", "C", "D"))

    A, B, C, D = series_inputs(mats(P), mats(delay), list(inputs))[:4]
    return shared_ss(A, B, C, D, inputs=list(P.input_labels), outputs=list(P.output_labels))


def sampled_plant(P, dt: float, inputs=None):
    """The plant ``P`` sampled exactly with a zero-order hold at ``dt`` (s): inputs held
    over each sample, outputs read at the samples (:func:`ambseal.lti.discrete.zoh`),
    signal names kept. ``inputs`` (indices; default all) are sampled together and give
    ``A_d``, the others apart: the controller's loop then has the state matrix of the
    plant sampled with its control inputs alone, as the discretisation chosen for it
    (:func:`ambseal.robust.digital.sampled_plants`), and their poles are computed once.

    Parameters
    ----------
    P : control.StateSpace
        The continuous plant.
    dt : float
        Sample time (s), > 0.
    inputs : sequence of int, optional
        The inputs sampled together (default all).

    Returns
    -------
    control.StateSpace
        Discrete, ``dt`` its sample time, the same states and signal names.
    """

    A, B = np.asarray(P.A, float), np.asarray(P.B, float)
    cur = list(range(B.shape[1])) if inputs is None else list(inputs)
    rest = [j for j in range(B.shape[1]) if j not in cur]
    Bd = np.empty_like(B)
    Ad, Bd[:, cur] = zoh(A, B[:, cur], dt)
    if rest:
        Bd[:, rest] = zoh(A, B[:, rest], dt)[1]
    return shared_ss(Ad, Bd, np.asarray(P.C, float), np.asarray(P.D, float), dt,
                     inputs=list(P.input_labels), outputs=list(P.output_labels))


def sampled_loop_matrix(P, K) -> np.ndarray:
    """The state matrix of the discrete ``K`` closed on the continuous ``P`` sampled by a
    zero-order hold at its sample time, ``u = −K y`` wired by signal names: states
    ``[x; x_K]``, ``x`` the plant's own. Only the matrix (no poles, no system): what a
    modal analysis of the loop as it runs needs.

    Parameters
    ----------
    P : control.StateSpace
        Continuous plant, every input driven by ``K``.
    K : control.StateSpace
        Discrete controller (``dt`` its sample time, its delay among its states).

    Returns
    -------
    ndarray, shape (n + n_K, n + n_K)

    Raises
    ------
    ModelError
        A continuous ``K`` or channels that do not fit.
    """
    dt = sample_time(K)
    if not dt:
        raise ModelError("sampled_loop_matrix: the controller must be discrete")
    Pd = sampled_plant(P, dt)
    return feedback_matrices(ss_matrices(Pd, allow_discrete=True),
                             ss_matrices(wired(Pd, K), name="K", allow_discrete=True))[0]


def judged_loop(P, K, control_inputs=None, *, delay=None) -> JudgedLoop:
    """Close ``K`` on the continuous plant ``P`` as it will run (module docstring).

    Parameters
    ----------
    P : control.StateSpace
        Continuous plant (e.g. the full-order model), ``n`` states. Its inputs
        ``control_inputs`` are driven by the controller; any others (forces, N) stay
        external inputs of the loop.
    K : control.StateSpace
        Continuous controller, or a discrete one whose ``dt`` is its sample time (its
        computation delay among its states); ``u = −K y``, wired by signal names.
    control_inputs : sequence of int, optional
        Indices of the inputs of ``P`` the controller drives (default: all).
    delay : control.StateSpace, optional
        SISO lag of a continuous controller's hold and computation delay
        (:func:`ambseal.robust.delay.loop_delay` ``.system``); ignored for a discrete one,
        whose delay is in its states.

    Returns
    -------
    JudgedLoop
        The plant as closed (delayed or sampled) and the closed loop: inputs ``d_<u>``
        (disturbances added to the controller's output) then the external inputs, outputs
        the plant's then ``i_<u>``.

    Raises
    ------
    ModelError
        ``P`` not continuous, or channels that do not fit (:func:`loop_matrices`).
    """
    if sample_time(P):
        raise ModelError("judged_loop: the plant must be continuous; a discrete controller "
                         "samples it itself")
    cur = list(range(P.ninputs)) if control_inputs is None else list(control_inputs)
    rest = [j for j in range(P.ninputs) if j not in cur]
    dt = sample_time(K)
    if dt:
        return JudgedLoop(lambda: sampled_plant(P, dt, cur), _sampled_loop(P, K, cur, rest, dt),
                          P, None, tuple(cur))
    if delay is None:
        G, Gf = select_inputs(P, cur), (select_inputs(P, rest) if rest else None)
        return JudgedLoop(lambda: P, _closed(G, K, Gf, 0.0, None), P, None, tuple(cur))

    def parts():  # the delayed plant's: made again, not kept, when asked for
        Pj = delayed_plant(P, cur, delay)
        return select_inputs(Pj, cur), (select_inputs(Pj, rest) if rest else None)

    source = (select_inputs(P, cur), tuple(np.asarray(getattr(delay, m), float) for m in "ABCD"))
    G, Gf = parts()
    loop = _closed(G, K, Gf, 0.0, source, parts)
    return JudgedLoop(lambda: delayed_plant(P, cur, delay), loop, P, delay, tuple(cur))

"""Session-wide fixtures: the expensive designs, computed once per test session.

Each design below is made by the public function with the arguments ``ambseal run`` uses,
so that the tests of the designs, of the analyses built on them and of the main job see the
same controllers:

* ``testrig_designs`` — PID, H∞ and μ of :func:`ambseal.design.recipes.design` on the
  embedded test facility (thesis P5 §4), a few seconds;
* ``testrig_plants`` — the full-order test-facility plants over 0 … 4.08 bar (P5 Fig. 13);
* ``turbo_lpv`` — the constant-Lyapunov LPV design of the turboexpander over its
  ``[operating] speed_range_hz`` with the frozen γ's (P3 §4), about half a minute;
* ``turbo_frozen`` — the H∞ controller at the operating speed (140 Hz, P3 Fig. 11);
* ``testrig_digital``, ``turbo_digital`` (``turbo_hinf_digital`` its H∞ alone) — the
  digital controllers of those designs as ``ambseal run`` chooses them
  (:func:`ambseal.app.commands.digital_for`);
* ``turbo_rejection`` — the turboexpander's H∞ with its unbalance force rejection.

``design_cache_for`` lets a test run the main job (``ambseal run``) on these designs instead
of recomputing them: it replaces the design functions for the duration of the test by
wrappers that return the session's result when called with the same rig and arguments and
call the real function otherwise. Only the main-job tests use it; the design tests call
the real functions.
"""

from __future__ import annotations

import contextlib
import json
import os
import socket
import sys
import threading
from pathlib import Path

# One BLAS thread per test process, as CI runs the suite (.ci/run) and the README's run
# times are measured: set here, before the workers pytest-xdist starts load numpy, so that
# they inherit it. Otherwise each worker starts OpenBLAS with a thread per core, and the
# README's `pytest -n auto` took 15.7 min of wall time (30 min of CPU) on 2 cores instead
# of 4.3, and a sweep case run in a Dask worker thread rounded one number 1 ulp apart from
# the serial run (OpenBLAS started with two threads, then held to one by the thread policy).
for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import pytest  # noqa: E402  (after the thread variables)

ROOT = Path(__file__).resolve().parents[1]
TURBO = ROOT / "examples" / "turboexpander.toml"


def pytest_collection_modifyitems(config, items):
    """Under pytest-xdist, the tests marked ``heavy`` first. ``--dist loadgroup`` hands
    out the groups largest first, then the single tests in collection order, so a test
    of a minute collected late could run alone at the end while the other worker idled:
    `pytest -n 2 -m "not slow"` took 87 s of wall time beyond half its CPU before, 51 s
    after (benchmarks/README.md, "The suite's long tests first"). The sort is stable:
    every other order stays. Without workers nothing moves."""
    if os.environ.get("PYTEST_XDIST_WORKER"):  # set in the workers, which collect
        items.sort(key=lambda item: item.get_closest_marker("heavy") is None)


#: Pressure grid 0 … 2× nominal (2.04 bar) of thesis P5 Fig. 13, in 8 steps.
PRESSURES_BAR = (0.0, 0.51, 1.02, 1.53, 2.04, 2.55, 3.06, 3.57, 4.08)


@pytest.fixture(scope="session")
def testrig_cfg():
    from ambseal.config import load_rig

    return load_rig()


@pytest.fixture(scope="session")
def turbo_cfg():
    from ambseal.config import load_rig

    return load_rig(TURBO)


@pytest.fixture(scope="session")
def testrig_designs(testrig_cfg):
    """{"pid", "hinf", "mu"} → DesignResult, as ``ambseal run`` makes them."""
    from ambseal.design.recipes import design

    return {m: design(testrig_cfg, m) for m in ("pid", "hinf", "mu")}


@pytest.fixture(scope="session")
def testrig_plants(testrig_cfg):
    """pressure (bar) → (G, Gf): full-order plant from the 4 currents and from the forces at
    the bearings A and B (0.17 and 0.69 m, where P5 §4.4.1 takes the compliance) to the 4
    displacements."""
    from ambseal.model.rig import build_plant

    x_amb = tuple(a.position for a in testrig_cfg.amb)
    out = {}
    for p in PRESSURES_BAR:
        pl = build_plant(testrig_cfg, pressure_bar=p, force_positions=x_amb)
        out[p] = (pl.select_inputs(pl.input_names[:4]).to_statespace(),
                  pl.select_inputs(pl.input_names[4:]).to_statespace())
    return out


@pytest.fixture(scope="session")
def turbo_lpv(turbo_cfg):
    """Constant-Lyapunov LPV design over the rig's speed range, frozen γ's included."""
    from ambseal.design.lpv_design import design_lpv

    return design_lpv(turbo_cfg, speeds_hz=turbo_cfg.operating.speed_range_hz)


@pytest.fixture(scope="session")
def turbo_frozen(turbo_cfg):
    """H∞ at the operating speed (8400 rpm = 140 Hz), the LTI comparison of P3 Fig. 11."""
    from ambseal.design.lpv_design import design_frozen

    return design_frozen(turbo_cfg, turbo_cfg.operating.speed_rpm / 60.0)


def _digital(cfg, designs: dict) -> dict:
    from ambseal.analysis.judge import operating_points
    from ambseal.app.commands import digital_for
    from ambseal.design.specs import design_spec

    pts, cache = operating_points(design_spec(cfg)), {}
    return {m: digital_for(cfg, m, getattr(d, "K", d) if m != "lpv" else d, d, pts, cache)
            for m, d in designs.items()}


@pytest.fixture(scope="session")
def testrig_digital(testrig_cfg, testrig_designs):
    """{"pid", "hinf", "mu"} → DigitalController of the test facility's designs."""
    return _digital(testrig_cfg, testrig_designs)


@pytest.fixture(scope="session")
def turbo_hinf_digital(turbo_cfg, turbo_frozen):
    """The DigitalController of the turboexpander's H∞ (without its LPV's design)."""
    return _digital(turbo_cfg, {"hinf": turbo_frozen})["hinf"]


@pytest.fixture(scope="session")
def turbo_digital(turbo_cfg, turbo_hinf_digital, turbo_lpv):
    """{"hinf", "lpv"} → DigitalController / ScheduledDigital of the turboexpander."""
    return {"hinf": turbo_hinf_digital, **_digital(turbo_cfg, {"lpv": turbo_lpv})}


@pytest.fixture(scope="session")
def turbo_rejection(turbo_cfg, turbo_frozen, turbo_hinf_digital):
    """The turboexpander's H∞ with its unbalance force rejection over its speed range
    (:func:`ambseal.design.design_rejection`, every default)."""
    from ambseal.design import design_rejection

    return design_rejection(turbo_cfg, turbo_frozen.K, turbo_hinf_digital)


class DesignCache:
    """Routes the main job's design calls to the session's designs (see module doc).

    ``patched(rig)`` computes (or fetches) the session designs of that rig first, then
    replaces the design functions until the ``with`` block ends; calls with other rigs or
    arguments go to the real functions. ``hits`` lists the calls answered from the session,
    so a test can check that the cache was used.
    """

    FIXTURES = {"testrig": ("testrig_cfg", "testrig_designs", "testrig_digital"),
                "turbo": ("turbo_cfg", "turbo_lpv", "turbo_frozen", "turbo_digital")}

    def __init__(self, request):
        self._request = request  # the requesting fixture's or test's
        self.hits: list[str] = []

    @contextlib.contextmanager
    def patched(self, rig: str):
        """Replace the design functions for the duration of the ``with`` block."""
        # every module that imports the design functions, loaded before they are replaced
        # (a module first imported inside the block would keep the replacement)
        import ambseal.app.commands as cmod
        import ambseal.app.handlers  # noqa: F401
        import ambseal.design.recipes as dmod
        import ambseal.design.lpv_design as lmod

        got = {n: self._request.getfixturevalue(n) for n in self.FIXTURES[rig]}
        real_design, real_lpv, real_frozen = dmod.design, lmod.design_lpv, lmod.design_frozen
        real_digital = cmod.digital_for
        digital = got.get("testrig_digital") or got.get("turbo_digital")
        cfg0 = got.get("testrig_cfg") or got.get("turbo_cfg")

        def digital_for(cfg, method, controller, result, points, cache=None):
            dc = digital.get(method)
            if dc is not None and _same(cfg, cfg0) and (
                    getattr(dc, "continuous", None) is controller
                    or (method == "lpv" and result is got.get("turbo_lpv"))):
                self.hits.append(f"digital:{method}")
                return dc
            return real_digital(cfg, method, controller, result, points, cache)

        def design(cfg, method="mu", **kw):
            # the main job passes the rig's own specification, a progress callback,
            # allow_unstable=True (the judgement decides; the cached designs are stable, so
            # it changes nothing) and the trials its designs share (the same designs),
            # `ambseal design` the operating pressure (None: the rig's)
            plain = set(kw) <= {"spec", "progress", "allow_unstable", "pressure_bar",
                                "trials"} \
                and kw.get("pressure_bar") is None
            if rig == "testrig" and plain and _same(cfg, got["testrig_cfg"]):
                self.hits.append(f"design:{method}")
                return got["testrig_designs"][method]
            return real_design(cfg, method, **kw)

        def design_lpv(cfg, **kw):
            tc = got.get("turbo_cfg")
            # the session's design is the default one: over the speed range, 8 states
            if (tc is not None and _same(cfg, tc)
                    and set(kw) - {"allow_unstable", "spec", "states"} == {"speeds_hz"}
                    and kw.get("states", 8) == 8
                    and tuple(kw["speeds_hz"]) == tuple(tc.operating.speed_range_hz)):
                self.hits.append("design_lpv")
                return got["turbo_lpv"]
            return real_lpv(cfg, **kw)

        def design_frozen(cfg, speed_hz=None, **kw):
            tc = got.get("turbo_cfg")
            if (tc is not None and not set(kw) - {"allow_unstable", "spec"} and _same(cfg, tc)
                    and speed_hz in (None, tc.operating.speed_rpm / 60.0)):
                self.hits.append("design_frozen")
                return got["turbo_frozen"]
            return real_frozen(cfg, speed_hz, **kw)

        with pytest.MonkeyPatch.context() as mp:
            for real, fake in ((real_design, design), (real_lpv, design_lpv),
                               (real_frozen, design_frozen), (real_digital, digital_for)):
                _replace_everywhere(mp, real, fake)
            yield self


def _replace_everywhere(mp, real, fake) -> None:
    """Replace ``real`` by ``fake`` in every ambseal module that holds it (modules import
    the functions by name at their top)."""
    for mod in list(sys.modules.values()):
        name = getattr(mod, "__name__", "") or ""
        if (name == "ambseal" or name.startswith("ambseal.")) and \
                getattr(mod, real.__name__, None) is real:
            mp.setattr(mod, real.__name__, fake)


#: AMB keys no design reads (the amplifier's limits are judged, not designed for): a rig
#: that differs in them alone is served the session's designs.
_JUDGED_ONLY = {"supply_voltage", "inductance", "resistance", "saturation_flux_density"}


def _same(a, b) -> bool:
    def designed(cfg):
        return cfg.model_copy(update={"amb": [amb.model_copy(update=dict.fromkeys(
            _JUDGED_ONLY)) for amb in cfg.amb]}).model_dump_json()
    return designed(a) == designed(b)


@pytest.fixture(scope="session")
def design_cache_for():
    """:class:`DesignCache` itself: ``with design_cache_for(request).patched(rig): ...`` with the
    ``request`` of the fixture or test that runs the main job (the session designs are
    looked up through it while it is active)."""
    return DesignCache


@pytest.fixture(scope="session")
def testrig_tracked(testrig_cfg, tmp_path_factory):
    """The controller scheduled on the seal's k over 0–3× nominal, as
    :func:`ambseal.design.seal_schedule.design_seal_scheduled` makes it by default
    (minutes of LMI synthesis: only the slow tests use it; ``$AMBSEAL_CACHE_DIR`` keeps
    it between sessions)."""
    from ambseal.design.seal_schedule import design_seal_scheduled

    return design_seal_scheduled(testrig_cfg)


def _on_a_terminal(argv: list[str], columns: int = 150) -> tuple[int, str]:
    """``main(argv)`` with stdout and stderr on a pseudo-terminal (POSIX ``pty``) of
    ``columns`` × 50; its exit status and everything the terminal received."""
    import fcntl
    import os
    import pty
    import struct
    import sys
    import termios
    import threading

    from ambseal.cli import main

    master, slave = pty.openpty()
    fcntl.ioctl(slave, termios.TIOCSWINSZ, struct.pack("HHHH", 50, columns, 0, 0))
    tty = os.fdopen(slave, "w", buffering=1, encoding="utf-8")
    chunks: list[bytes] = []

    def pump():
        while True:
            try:
                data = os.read(master, 65536)
            except OSError:
                return
            if not data:
                return
            chunks.append(data)

    reader = threading.Thread(target=pump, daemon=True)
    reader.start()
    old = sys.stdout, sys.stderr
    sys.stdout = sys.stderr = tty
    try:
        code = main(argv)
    finally:
        sys.stdout, sys.stderr = old
        tty.close()
        reader.join(timeout=10)
        os.close(master)
    return code, b"".join(chunks).decode("utf-8", "replace")


@pytest.fixture(scope="session")
def terminal_run(tmp_path_factory, request, design_cache_for):
    """``ambseal run`` on the embedded rig on a pseudo-terminal, with the session's PID
    (the same call ``run`` makes, computed once). H∞ and μ are designed on the rig
    identified from the virtual facility, so not from the cache. Once per session: the
    main-job tests (tests/test_pipeline.py) and the manual's ``ambseal run`` block
    (tests/test_docs.py) read the same folder."""
    out = tmp_path_factory.mktemp("run")
    cache = design_cache_for(request)
    with cache.patched("testrig"):
        code, screen = _on_a_terminal(["run", "--out", str(out)])
    assert code == 0, screen
    assert {"design:pid", "digital:pid"} <= set(cache.hits)
    assert not {"design:hinf", "design:mu"} & set(cache.hits)
    return out, json.loads((out / "metrics.json").read_text()), screen


@pytest.fixture(scope="session")
def flywheel_10k_lpv(tmp_path_factory):
    """``(rig, {kernels: out folder})``: ``ambseal design --method lpv`` on the example
    flywheel with its sample rate set to 10 kHz (a copy; the example stays as it is), in
    two processes at once under the two BLAS kernel sets of :mod:`tests.kernel_runs`
    where ``OPENBLAS_CORETYPE`` selects them, else once in this process (key
    ``"native"``). Its readers (the LPV's pole bound, and its sameness under two kernel
    sets) carry the group ``flywheel_10k_lpv``: the design is made once."""
    import re

    from ambseal.cli import main
    from tests.kernel_runs import run_both, selectable_pair

    tmp = tmp_path_factory.mktemp("flywheel10k")
    text, n = re.subn(r"(?m)^sample_rate_hz\s*=.*$", "sample_rate_hz = 10000.0",
                      (ROOT / "examples" / "flywheel.toml").read_text(encoding="utf-8"))
    assert n == 1
    rig = tmp / "flywheel_10k.toml"
    rig.write_text(text, encoding="utf-8")
    argv = ["design", str(rig), "--method", "lpv"]
    pair, _ = selectable_pair()
    if pair is None:
        assert main(["--quiet", *argv, "--out", str(tmp / "native")]) == 0
        return rig, {"native": tmp / "native"}
    run_both(pair, argv, tmp, 600)
    return rig, {c: tmp / c for c in pair}


@pytest.fixture
def silent_peer():
    """The address of a TCP socket on this machine that accepts connections and never
    answers (a wrong port, a stalled host): a Dask scheduler that would hang a client."""
    srv = socket.socket()
    srv.bind(("127.0.0.1", 0))
    srv.listen(8)
    srv.settimeout(0.2)
    held, stop = [], threading.Event()

    def accept():
        while not stop.is_set():
            try:
                held.append(srv.accept()[0])
            except OSError:
                continue

    t = threading.Thread(target=accept, daemon=True)
    t.start()
    yield f"tcp://127.0.0.1:{srv.getsockname()[1]}"
    stop.set()
    t.join()
    for c in held:
        c.close()
    srv.close()

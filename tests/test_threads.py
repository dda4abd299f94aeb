"""The thread policy (ambseal.threads): one BLAS thread unless the user says otherwise, the
same numbers whatever the environment's BLAS variables and the machine's load.

References: threadpoolctl's own report of the loaded BLAS libraries (an independent reader
of their thread counts) and python-control's frequency response of the controllers."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from ambseal.errors import ConfigError
from ambseal.threads import ENV_VAR, blas_threads, numerics_threads

ROOT = Path(__file__).resolve().parents[1]
BLAS_VARS = ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS",
             "BLIS_NUM_THREADS", "VECLIB_MAXIMUM_THREADS", "NUMEXPR_NUM_THREADS", ENV_VAR)


def _env(**blas) -> dict:
    """This process's environment without any BLAS variable, then ``blas``."""
    env = {k: v for k, v in os.environ.items() if k not in BLAS_VARS}
    env.update({k: str(v) for k, v in blas.items()})
    env["PYTHONPATH"] = os.pathsep.join([str(ROOT), env.get("PYTHONPATH", "")])
    return env


def _child(code: str, **blas) -> dict:
    out = subprocess.run([sys.executable, "-c", code], env=_env(**blas), capture_output=True,
                         text=True, timeout=300, cwd=ROOT)
    assert out.returncode == 0, out.stderr
    return json.loads(out.stdout.strip().splitlines()[-1])


_COUNTS = """
import json, numpy, scipy.linalg, control
from threadpoolctl import threadpool_info
from ambseal.threads import numerics_threads
def blas(): return {i["filepath"]: i["num_threads"] for i in threadpool_info()
                    if i["user_api"] == "blas"}
before = blas()
with numerics_threads() as n:
    inside = blas()
    with numerics_threads():  # nested: shares the outer setting
        nested = blas()
    import os
    child = os.environ.get("OPENBLAS_NUM_THREADS")
print(json.dumps({"before": before, "inside": inside, "nested": nested, "after": blas(),
                  "n": n, "child": child}))
"""


@pytest.mark.skipif((os.cpu_count() or 1) < 2, reason="BLAS runs one thread on one core")
def test_one_blas_thread_by_default_and_restored_after():
    """A user's environment with two BLAS threads: threadpoolctl reads the libraries' own
    counts before (2 where the library is built for threads), 1 inside the policy (nested
    too) and those of before after it; children started inside inherit 1."""
    r = _child(_COUNTS, OPENBLAS_NUM_THREADS=2)
    assert max(r["before"].values()) == 2
    assert set(r["inside"].values()) == {1} and set(r["nested"].values()) == {1}
    assert r["after"] == r["before"] and r["n"] == 1 and r["child"] == "1"


@pytest.mark.skipif((os.cpu_count() or 1) < 2, reason="BLAS runs one thread on one core")
def test_policy_overrides_and_inherit():
    """``AMBSEAL_BLAS_THREADS=2`` sets two threads (where the library is built for
    threads) in an environment that asks for one; ``inherit`` leaves the environment's."""
    r = _child(_COUNTS, OPENBLAS_NUM_THREADS=1, AMBSEAL_BLAS_THREADS=2)
    assert set(r["before"].values()) == {1} and max(r["inside"].values()) == 2
    assert r["child"] == "2" and r["after"] == r["before"]
    r = _child(_COUNTS, OPENBLAS_NUM_THREADS=2, AMBSEAL_BLAS_THREADS="inherit")
    assert r["inside"] == r["before"] and max(r["before"].values()) == 2 and r["n"] is None


def test_bad_policy_values_are_refused(monkeypatch):
    """A thread count must be a whole number ≥ 1 or ``inherit``; the error names the
    variable or option it came from."""
    for bad in ("0", "-1", "1.5", "two", "1e3"):
        with pytest.raises(ConfigError, match="--blas-threads"):
            blas_threads(bad)
    monkeypatch.setenv(ENV_VAR, "zero")
    with pytest.raises(ConfigError, match=ENV_VAR):
        with numerics_threads():
            pass
    monkeypatch.setenv(ENV_VAR, " ")
    assert blas_threads() == 1 and blas_threads("+4") == 4 and blas_threads("Inherit") is None


def test_cli_refuses_a_bad_policy_in_one_line():
    """``--blas-threads x`` and ``AMBSEAL_BLAS_THREADS=x``: exit 2, one line naming it."""
    for args, extra in ((["--blas-threads", "x", "validate"], {}),
                        (["validate"], {ENV_VAR: "x"})):
        out = subprocess.run([sys.executable, "-m", "ambseal.cli", *args],
                             env=_env(**extra), capture_output=True, text=True, timeout=120)
        lines = out.stderr.strip().splitlines()
        assert out.returncode == 2 and len(lines) == 1, out.stderr
        assert ("--blas-threads" if not extra else ENV_VAR) in lines[0]


_SYNTHESIS = """
import json, sys, numpy as np
sys.path.insert(0, ".")
from tests.distillation import distillation_rp_plant
from ambseal.robust import musyn
P = distillation_rp_plant()
w = np.logspace(-3, 3, 61)
r = musyn(P, [(1, 1), (1, 1), (2, 2)], 2, 2, w, max_iter=3, search=40)
h = np.concatenate([np.ravel(r.K(1j * w)) for w in np.logspace(-3, 3, 41)])
print(json.dumps({"mu": r.mu, "gamma": r.gamma, "re": h.real.tolist(), "im": h.imag.tolist(),
                  "stopping": r.stopping}))
"""


@pytest.mark.heavy
def test_synthesis_is_the_same_whatever_the_threads_and_load():
    """μ-synthesis with its D search in three child processes — one BLAS thread set by
    the environment, four set by it, and none set with a CPU hog running beside it: μ and γ
    equal to 1e-9 relative, the controllers' frequency responses to 1e-7, and the same
    stopping record (counts, never a clock)."""
    runs = [_child(_SYNTHESIS, OPENBLAS_NUM_THREADS=1),
            _child(_SYNTHESIS, OPENBLAS_NUM_THREADS=4)]
    hog = subprocess.Popen([sys.executable, "-c", "while True: pass"])
    try:
        runs.append(_child(_SYNTHESIS))
    finally:
        hog.kill()
        hog.wait()
    ref = runs[0]
    h_ref = np.array(ref["re"]) + 1j * np.array(ref["im"])
    assert ref["stopping"]["search"]["evaluations"] == 40
    for r in runs[1:]:
        assert r["mu"] == pytest.approx(ref["mu"], rel=1e-9)
        assert r["gamma"] == pytest.approx(ref["gamma"], rel=1e-9)
        h = np.array(r["re"]) + 1j * np.array(r["im"])
        assert np.max(np.abs(h - h_ref)) <= 1e-7 * np.max(np.abs(h_ref))
        assert r["stopping"] == ref["stopping"]


#: Keys of metrics.json that are measurements of time, not results.
_TIMES = {"elapsed_s", "synthesis_s", "wall_time_s", "time_s", "cpu_s"}


def _same_numbers(a, b, path="metrics") -> list[str]:
    """Where two JSON documents differ: numbers beyond 1e-9 relative, anything else
    unequal; the time measurements left out."""
    if isinstance(a, dict) and isinstance(b, dict):
        if set(a) != set(b):
            return [f"{path}: keys {sorted(set(a) ^ set(b))}"]
        return [d for k in a if k not in _TIMES for d in _same_numbers(a[k], b[k], f"{path}.{k}")]
    if isinstance(a, list) and isinstance(b, list):
        if len(a) != len(b):
            return [f"{path}: lengths {len(a)} and {len(b)}"]
        return [d for i, (x, y) in enumerate(zip(a, b)) for d in _same_numbers(x, y, f"{path}[{i}]")]
    if isinstance(a, float) and isinstance(b, float):
        return [] if a == pytest.approx(b, rel=1e-9, abs=1e-300) else [f"{path}: {a} and {b}"]
    return [] if a == b else [f"{path}: {a!r} and {b!r}"]


@pytest.mark.slow
def test_main_job_metrics_are_the_same_with_one_or_two_blas_threads(tmp_path):
    """``ambseal run --no-identify`` with ``OPENBLAS_NUM_THREADS`` 1 and 2 in the
    environment: metrics.json equal to 1e-9 (the policy runs both on one thread)."""
    docs = []
    for n in (1, 2):
        out = tmp_path / f"out{n}"
        proc = subprocess.run([sys.executable, "-m", "ambseal.cli", "-q", "run", "--no-identify",
                               "--out", str(out)], env=_env(OPENBLAS_NUM_THREADS=n),
                              capture_output=True, text=True, timeout=900, cwd=tmp_path)
        assert proc.returncode in (0, 1), proc.stderr
        docs.append(json.loads((out / "metrics.json").read_text()))
    assert _same_numbers(*docs) == []

"""Runs of ``ambseal`` under two sets of BLAS kernels (tests/test_kernels.py, and the
session fixture ``flywheel_10k_lpv`` of tests/conftest.py that other tests read too).

OpenBLAS picks its kernels by the processor (Haswell's AVX2, SkylakeX's AVX-512, …);
``OPENBLAS_CORETYPE`` makes one machine run either set, each process with one BLAS thread.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
BLAS_VARS = ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS",
             "BLIS_NUM_THREADS", "VECLIB_MAXIMUM_THREADS", "NUMEXPR_NUM_THREADS",
             "OPENBLAS_CORETYPE", "OPENBLAS_VERBOSE", "AMBSEAL_BLAS_THREADS")
_MAIN = "import sys; from ambseal.cli import main; sys.exit(main())"
_ARCH = ("import json, numpy, scipy.linalg, threadpoolctl; print(json.dumps(sorted("
         "{i.get('architecture') or '' for i in threadpoolctl.threadpool_info() "
         "if i.get('internal_api') == 'openblas'})))")


def kernel_env(coretype: str) -> dict:
    """This environment without BLAS variables, then one kernel set and one thread."""
    env = {k: v for k, v in os.environ.items() if k not in BLAS_VARS}
    env.update(OPENBLAS_CORETYPE=coretype, OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1",
               MPLBACKEND="Agg")
    env["PYTHONPATH"] = os.pathsep.join([str(ROOT / "src"), env.get("PYTHONPATH", "")])
    return env


def _cpu_flags() -> set[str]:
    try:
        text = Path("/proc/cpuinfo").read_text()
    except OSError:
        return set()
    for line in text.splitlines():
        if line.startswith("flags"):
            return set(line.split(":", 1)[1].split())
    return set()


def _kernel_pair() -> tuple[str, str] | None:
    """Two OpenBLAS kernel sets this processor runs: the AVX-512 one against AVX2's where
    it has AVX-512, else AVX2's against AVX's; None where it has neither."""
    flags = _cpu_flags()
    if "avx512f" in flags:
        return "Haswell", "SkylakeX"
    if "avx2" in flags:
        return "Sandybridge", "Haswell"
    return None


def _architecture(coretype: str) -> list[str]:
    """The kernel sets NumPy's and SciPy's OpenBLAS report under ``coretype``."""
    out = subprocess.run([sys.executable, "-c", _ARCH], env=kernel_env(coretype), cwd=ROOT,
                         capture_output=True, text=True, timeout=120)
    return json.loads(out.stdout) if out.returncode == 0 else []


def selectable_pair() -> tuple[tuple[str, str] | None, str]:
    """``(pair, "")``: the kernel pair of :func:`_kernel_pair` where ``OPENBLAS_CORETYPE``
    selects it; else ``(None, why not)``."""
    pair = _kernel_pair()
    if pair is None:
        return None, "no two OpenBLAS kernel sets on this processor (neither AVX2 nor AVX-512)"
    arch = [_architecture(c) for c in pair]
    if [[c.lower()] for c in pair] != [[a.lower() for a in x] for x in arch]:
        return None, f"OPENBLAS_CORETYPE does not select the kernels here: {pair} gave {arch}"
    return pair, ""


def kernels_selectable() -> tuple[str, str]:
    """:func:`selectable_pair`'s pair, else the test is skipped saying why."""
    pair, why = selectable_pair()
    if pair is None:
        pytest.skip(why)
    return pair


def run_both(pair, argv: list[str], tmp_path: Path, timeout: float) -> None:
    """``ambseal argv…`` in two processes at once, one per kernel set of ``pair``, each
    writing to ``tmp_path/<kernels>``; a run that does not exit 0 fails the test."""
    procs = [(c, subprocess.Popen([sys.executable, "-c", _MAIN, "-q", *argv, "--out",
                                   str(tmp_path / c)], env=kernel_env(c), cwd=tmp_path,
                                  stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True))
             for c in pair]
    try:
        for c, proc in procs:
            _, stderr = proc.communicate(timeout=timeout)
            if proc.returncode != 0:
                pytest.fail(f"{c}: exit {proc.returncode}\n{stderr[-3000:]}")
    finally:
        for _, proc in procs:
            if proc.poll() is None:
                proc.kill()
                proc.wait()

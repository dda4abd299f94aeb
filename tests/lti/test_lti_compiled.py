"""numba kernels on a read-only installation (lti/compiled.py): no writable cache folder
must not end a command in numba's "no locator available" traceback."""

import os
import subprocess
import sys
import textwrap

_CHILD = textwrap.dedent("""
    import numba
    import numpy as np

    try:  # the set-up below leaves numba no folder to cache in, as a read-only install
        numba.njit(cache=True)(lambda x: x)
        print("numba found a cache folder")
    except RuntimeError:
        pass
    from ambseal.identify.facility import facility_loop  # noqa: F401  (its kernels compile on import)
    from ambseal.lti.discrete import simulate_lti
    from ambseal.robust import _hinf_small, _mu_newton  # noqa: F401  (likewise)

    A = np.array([[0.9, 0.1], [-0.2, 0.8]])
    B = np.array([[1.0], [0.5]])
    C = np.array([[1.0, -1.0]])
    u = np.sin(0.3 * np.arange(200.0))[:, None]
    (y,) = simulate_lti(A, B, [C], u, block=16)
    z, ref = np.zeros(2), []
    for k in range(200):  # the recursion itself, sample by sample
        ref.append(C @ z)
        z = A @ z + B @ u[k]
    print("error", float(np.max(np.abs(y - np.array(ref)))))
""")


def test_kernels_compile_without_a_writable_cache(tmp_path):
    """Reference: the recursion z[k+1] = A z[k] + B u[k], y = C z, sample by sample. With
    numba's only cache locator pointed below a regular file (not writable, even for root)
    the modules with cached kernels import and :func:`simulate_lti`'s compiled kernels give
    the recursion's outputs to 1e-12, with no traceback."""
    blocker = tmp_path / "file"
    blocker.write_text("")
    env = {**os.environ, "NUMBA_CACHE_DIR": str(blocker / "cache"),
           "NUMBA_CACHE_LOCATOR_CLASSES": "UserProvidedCacheLocator",
           "OPENBLAS_NUM_THREADS": "1"}
    proc = subprocess.run([sys.executable, "-c", _CHILD], capture_output=True, text=True,
                          env=env, cwd=tmp_path, timeout=300)
    assert proc.returncode == 0 and "Traceback" not in proc.stderr, proc.stderr[-2000:]
    lines = proc.stdout.split("\n")
    assert "numba found a cache folder" not in lines, proc.stdout
    err = float(next(ln for ln in lines if ln.startswith("error")).split()[1])
    assert err < 1e-12

"""``benchmarks/bench_rigs.py``'s command line: the meshes it runs are the ones asked for,
and a mesh it does not know is refused, not run as the rig's own mesh under its name."""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

import pytest

BENCH = Path(__file__).resolve().parents[1] / "benchmarks"


def _bench_rigs():
    sys.path.insert(0, str(BENCH))  # its sibling bench_suite
    spec = importlib.util.spec_from_file_location("bench_rigs", BENCH / "bench_rigs.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


@pytest.mark.parametrize("given, meshes", [(None, ["own", "finer"]),
                                           ("both", ["own", "finer"]),
                                           ("finer", ["finer"]),
                                           ("finer,own", ["finer", "own"])])
def test_the_meshes_asked_for_are_run(given, meshes):
    argv = [] if given is None else ["--mesh", given]
    assert _bench_rigs()._args(argv).mesh == meshes


@pytest.mark.parametrize("given", ["all", "own,fine", ""])
def test_an_unknown_mesh_is_refused(given, capsys):
    with pytest.raises(SystemExit) as exit_:
        _bench_rigs()._args(["--mesh", given])
    assert exit_.value.code == 2
    assert "--mesh" in capsys.readouterr().err

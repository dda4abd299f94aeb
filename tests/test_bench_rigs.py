"""``benchmarks/bench_rigs.py``'s command line: the meshes it runs are the ones asked for,
and a mesh it does not know is refused, not run as the rig's own mesh under its name."""

from __future__ import annotations

import pytest

from .benchmark_module import bench_module


def _bench_rigs():
    return bench_module("bench_rigs")


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

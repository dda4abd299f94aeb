"""The suite's own distribution: tests that share an expensive module fixture (an example
rig's whole run) carry ``pytest.mark.xdist_group`` so that ``--dist loadgroup`` (the
suite's ``addopts``) sends them to one worker, and the run is made once. Under pytest 9.2
pytest-xdist 3.8 stopped grouping without a word (pytest-dev/pytest-xdist#1386): the
flywheel example then ran on both workers, 400 s of CPU each."""

from __future__ import annotations

import subprocess
import sys
import textwrap


def test_grouped_tests_run_on_one_worker(tmp_path):
    """Reference: pytest-xdist's documented contract for ``--dist loadgroup`` — every test
    with the same ``xdist_group`` name runs in the same worker. Four grouped tests (a
    module-level mark, one of them parametrised, as the suite's example-run modules are)
    beside four ungrouped ones, two workers: each test writes its worker's name; the
    grouped ones must name one worker."""
    seen = tmp_path / "seen"
    seen.mkdir()
    record = textwrap.dedent(f"""
        import os
        from pathlib import Path

        def record(name):
            Path({str(seen)!r}, name).write_text(os.environ["PYTEST_XDIST_WORKER"])
        """)
    (tmp_path / "test_grouped.py").write_text(record + textwrap.dedent("""
        import pytest

        pytestmark = pytest.mark.xdist_group("shared_run")

        @pytest.mark.parametrize("k", [0, 1])
        def test_p(k):
            record(f"grouped_p{k}")

        def test_a():
            record("grouped_a")

        def test_b():
            record("grouped_b")
        """))
    (tmp_path / "test_free.py").write_text(record + "".join(
        f"\ndef test_{k}():\n    record('free_{k}')\n" for k in range(4)))
    (tmp_path / "pytest.ini").write_text("[pytest]\n")
    done = subprocess.run(
        [sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", "-n", "2",
         "--dist", "loadgroup", "-c", str(tmp_path / "pytest.ini"), "--rootdir",
         str(tmp_path), str(tmp_path)], capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stdout + done.stderr
    workers = {p.name: p.read_text() for p in seen.iterdir()}
    assert len(workers) == 8
    grouped = {w for name, w in workers.items() if name.startswith("grouped")}
    assert len(grouped) == 1, workers

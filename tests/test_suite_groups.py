"""The suite's own distribution: tests that share an expensive module fixture (an example
rig's whole run) carry ``pytest.mark.xdist_group`` so that ``--dist loadgroup`` (the
suite's ``addopts``) sends them to one worker, and the run is made once. Under pytest 9.2
pytest-xdist 3.8 stopped grouping without a word (pytest-dev/pytest-xdist#1386): the
flywheel example then ran on both workers, 400 s of CPU each."""

from __future__ import annotations

import ast
import subprocess
import sys
import textwrap
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


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


#: Session fixtures whose readers share one worker, by the group they carry: made once
#: per worker that asks, each a whole `ambseal run` or design of tens of seconds.
GROUPED_FIXTURES = {"terminal_run": "terminal_run", "flywheel_10k_lpv": "flywheel_10k_lpv"}


def _groups(decorators) -> set[str]:
    """The ``xdist_group`` names among decorators or ``pytestmark`` values (AST nodes)."""
    out = set()
    for node in decorators:
        for call in ast.walk(node):
            if (isinstance(call, ast.Call) and isinstance(call.func, ast.Attribute)
                    and call.func.attr == "xdist_group" and call.args
                    and isinstance(call.args[0], ast.Constant)):
                out.add(call.args[0].value)
    return out


def _ungrouped_readers(source: str) -> list[str]:
    """Functions of a test module that take a fixture of :data:`GROUPED_FIXTURES` as an
    argument and carry neither its group nor a module-level ``pytestmark`` of it."""
    tree = ast.parse(source)
    module = _groups([n.value for n in tree.body if isinstance(n, ast.Assign)
                      and any(isinstance(t, ast.Name) and t.id == "pytestmark"
                              for t in n.targets)])
    out = []
    for fn in ast.walk(tree):
        if not isinstance(fn, (ast.FunctionDef, ast.AsyncFunctionDef)):
            continue
        args = {a.arg for a in fn.args.args + fn.args.kwonlyargs}
        for fixture, group in GROUPED_FIXTURES.items():
            if fixture in args and group not in module | _groups(fn.decorator_list):
                out.append(f"{fn.name} ({fixture})")
    return out


def test_every_reader_of_the_session_run_shares_its_worker():
    """Reference: pytest-xdist's ``--dist loadgroup`` sends an unmarked test wherever a
    worker is free, and a session fixture is made once per worker that asks for it. A
    test that takes the session's embedded run without its group made that run (30 s)
    a second time whenever it landed on the other worker. Every test and fixture of the
    suite that takes it carries the group; the check itself finds an unmarked reader and
    passes a marked one, by function or by module."""
    found = {str(p.relative_to(ROOT)): _ungrouped_readers(p.read_text(encoding="utf-8"))
             for p in sorted((ROOT / "tests").rglob("test_*.py"))}
    assert not {k: v for k, v in found.items() if v}
    reader = "def test_a(terminal_run):\n    pass\n"
    assert _ungrouped_readers("import pytest\n" + reader) == ["test_a (terminal_run)"]
    assert _ungrouped_readers('import pytest\n@pytest.mark.xdist_group("terminal_run")\n'
                              + reader) == []
    assert _ungrouped_readers('import pytest\npytestmark = [pytest.mark.xdist_group('
                              '"terminal_run"), pytest.mark.heavy]\n' + reader) == []
    assert _ungrouped_readers('import pytest\n@pytest.mark.xdist_group("other")\n'
                              + reader) == ["test_a (terminal_run)"]

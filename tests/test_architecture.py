"""The architecture as a contract (docs/architecture.md), checked on the source.

``lint-imports`` (CI, ``[tool.importlinter]`` in ``pyproject.toml``) checks that the layers
import downwards only and that the generic core knows no rotor. The tests here check what a
contract cannot say: that the contract covers every package, that no two modules import
each other in a circle (at module level or inside functions), that the core's boundary
holds on the contract itself, and that one package takes another's names only through its
face (its ``__init__.py``).
"""

from __future__ import annotations

import ast
import importlib
import inspect
import re
import tomllib
from pathlib import Path

import grimp
import pytest

ROOT = Path(__file__).resolve().parents[1]
SRC = ROOT / "src" / "ambseal"


def _contracts() -> list[dict]:
    data = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))
    return data["tool"]["importlinter"]["contracts"]


def _layers() -> list[set[str]]:
    (layers,) = [c["layers"] for c in _contracts() if c["type"] == "layers"]
    return [{m.strip() for m in layer.replace(":", "|").split("|")} for layer in layers]


@pytest.fixture(scope="module")
def graph():
    return grimp.build_graph("ambseal")


def test_the_layers_cover_every_package():
    """A new package or top-level module must be placed in a layer on purpose."""
    tops = {p.name.removesuffix(".py") for p in SRC.iterdir()
            if (p.suffix == ".py" or (p / "__init__.py").exists())}
    placed = {m.removeprefix("ambseal.") for layer in _layers() for m in layer}
    assert tops - {"__init__", "__main__"} == placed


def test_the_core_is_forbidden_every_rotor_layer():
    """``robust`` and ``lti`` may import nothing above ``robust`` (the contract is complete)."""
    (forbid,) = [c for c in _contracts() if c["type"] == "forbidden"]
    assert set(forbid["source_modules"]) == {"ambseal.robust", "ambseal.lti"}
    layers = _layers()
    above = {m for layer in layers[:[i for i, l in enumerate(layers)
                                     if "ambseal.robust" in l][0]] for m in layer}
    assert above == set(forbid["forbidden_modules"])


def _cycles(graph) -> list[list[str]]:
    """Strongly connected components of more than one module (Tarjan, iterative)."""
    index, low, on, stack, out = {}, {}, set(), [], []
    for root in sorted(graph.modules):
        if root in index:
            continue
        work = [(root, iter(sorted(graph.find_modules_directly_imported_by(root))))]
        index[root] = low[root] = len(index)
        stack.append(root), on.add(root)
        while work:
            v, it = work[-1]
            w = next(it, None)
            if w is not None:
                if w not in index:
                    index[w] = low[w] = len(index)
                    stack.append(w), on.add(w)
                    work.append((w, iter(sorted(graph.find_modules_directly_imported_by(w)))))
                elif w in on:
                    low[v] = min(low[v], index[w])
                continue
            work.pop()
            if work:
                low[work[-1][0]] = min(low[work[-1][0]], low[v])
            if low[v] == index[v]:
                comp = []
                while True:
                    w = stack.pop()
                    on.discard(w)
                    comp.append(w)
                    if w == v:
                        break
                if len(comp) > 1:
                    out.append(sorted(comp))
    return out


def test_no_import_cycles_between_modules(graph):
    assert _cycles(graph) == []


def test_the_cycle_finder_sees_a_cycle():
    """The finder reports a circle of three modules and ignores a chain (so the test above
    can fail)."""
    g = grimp.ImportGraph()
    for m in ("p", "p.a", "p.b", "p.c", "p.d"):
        g.add_module(m)
    for a, b in (("p.a", "p.b"), ("p.b", "p.c"), ("p.c", "p.a"), ("p.d", "p.a")):
        g.add_import(importer=a, imported=b)
    assert _cycles(g) == [["p.a", "p.b", "p.c"]]


#: Functions that share their module's name are not re-exported by their package's face
#: (re-exporting one would hide the module, tests/test_docstrings.py), so the packages above
#: import each from its module: ``(module, name)``.
FACE_EXCEPTIONS = {
    ("ambseal.lti.freqresp", "freqresp"),
    ("ambseal.model.modes", "modes"),
    ("ambseal.design.lpv_plant", "lpv_plant"),
    ("ambseal.analysis.campbell", "campbell"),
    ("ambseal.analysis.sweep", "sweep"),
}


def _face_names(face: str) -> set[str]:
    """``__all__`` of a package's face, or of a top-level module (its own face)."""
    return set(importlib.import_module(face).__all__)


def _face_bypasses(root: Path = SRC) -> list[str]:
    """``file:line: import`` of every import in ``root`` (the ``ambseal`` package's folder),
    module or function level, that takes a name from another top-level package or module
    of ambseal other than from its face: a module path below the face (outside
    :data:`FACE_EXCEPTIONS`), a name the face does not list in ``__all__`` (a submodule, a
    helper), or a ``_private`` name. Imports within one package are its own business."""
    found = []
    for path in sorted(root.rglob("*.py")):
        rel = path.relative_to(root)
        mine = "ambseal" if rel == Path("__init__.py") else rel.parts[0].removesuffix(".py")
        text = path.read_text(encoding="utf-8")
        lines = text.splitlines()
        for node in ast.walk(ast.parse(text)):
            if isinstance(node, ast.Import):
                modules = [(a.name, []) for a in node.names]
            elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
                modules = [(node.module, [a.name for a in node.names])]
            else:
                continue
            for module, names in modules:
                parts = module.split(".")
                if parts[0] != "ambseal" or (parts[1:2] or ["ambseal"])[0] == mine:
                    continue
                face = ".".join(parts[:2])
                if len(parts) > 2:
                    bad = [n for n in names if (module, n) not in FACE_EXCEPTIONS] or not names
                else:
                    bad = [n for n in names if n.startswith("_") and not n.startswith("__")
                           or n not in _face_names(face)]
                if bad:
                    found.append(f"{rel}:{node.lineno}: {lines[node.lineno - 1].strip()}")
    return found


def test_packages_import_each_other_through_their_faces():
    """One package takes another's names from its face only (``from ambseal.lti import
    zoh``, not ``from ambseal.lti.discrete import zoh``), and only the names the face lists:
    the face is a package's whole public surface, and its modules can move behind it."""
    found = _face_bypasses()
    assert not found, "imports past a package's face:\n" + "\n".join(found)


def test_the_face_check_sees_a_bypass(tmp_path):
    """A planted module with each kind of bypass is caught, line by line, and the allowed
    imports are not (so the test above can fail)."""
    (tmp_path / "machine").mkdir()
    (tmp_path / "machine" / "planted.py").write_text("\n".join([
        "from ambseal.lti.discrete import zoh",            # 1: below the face
        "from ambseal.lti import zoh",                     # 2: the face
        "from ambseal.lti.freqresp import freqresp",       # 3: a listed exception
        "from ambseal.robust.hinf import _SMALL_STATES",   # 4: private, below the face
        "from ambseal.identify import stages",             # 5: a submodule, not listed
        "import ambseal.model.rig",                        # 6: below the face
        "from ambseal.machine.loop import closed_loop",    # 7: its own package
        "from ambseal.errors import ModelError",           # 8: a module that is a face
        "from ambseal import __version__",                 # 9: the package's own face
        "def f():",
        "    from ambseal.model.rig import build_plant",   # 11: inside a function
    ]) + "\n")
    lines = [int(hit.split(":")[1]) for hit in _face_bypasses(tmp_path)]
    assert lines == [1, 4, 5, 6, 11]


def test_the_face_exceptions_hide_a_module():
    """Each exception is a function named as its module, which its face leaves out (else it
    would be no exception)."""
    for module, name in sorted(FACE_EXCEPTIONS):
        assert module.rsplit(".", 1)[1] == name
        assert inspect.isfunction(getattr(importlib.import_module(module), name))
        assert name not in _face_names(".".join(module.split(".")[:2]))


def _function_level_imports() -> list[tuple[str, int, str]]:
    """(file, line, text) of every import statement inside a function or class."""
    out = []
    for path in sorted(SRC.rglob("*.py")):
        text = path.read_text(encoding="utf-8")
        tree = ast.parse(text)
        top = set()
        stack = list(tree.body)
        while stack:  # module level includes the branches of if/try at module level
            node = stack.pop()
            top.add(id(node))
            if isinstance(node, (ast.If, ast.Try)):
                stack += node.body + node.orelse + getattr(node, "finalbody", [])
                stack += [s for h in getattr(node, "handlers", []) for s in h.body]
        lines = text.splitlines()
        out += [(str(path.relative_to(SRC)), n.lineno, lines[n.lineno - 1])
                for n in ast.walk(tree)
                if isinstance(n, (ast.Import, ast.ImportFrom)) and id(n) not in top]
    return out


def test_imports_sit_at_the_top_of_modules():
    """A function-level import only for an optional dependency or a measured start-up
    cost, with a comment saying which (on its line or just above it); at most 20."""
    found = _function_level_imports()
    assert len(found) <= 20, found
    for file, line, text in found:
        above = (SRC / file).read_text(encoding="utf-8").splitlines()[line - 2].strip()
        assert "#" in text or above.startswith("#"), f"{file}:{line}: {text.strip()}"


def test_no_history_in_code_or_tests():
    """Comments say why; history lives in git and CHANGELOG.md."""
    pattern = re.compile(r"issues?\s*#?\s*[0-9]", re.IGNORECASE)
    hits = [f"{p.relative_to(ROOT)}:{i}" for base in (SRC, ROOT / "tests")
            for p in sorted(base.rglob("*.py"))
            for i, line in enumerate(p.read_text(encoding="utf-8").splitlines(), 1)
            if pattern.search(line)]
    assert hits == []



def _design_spec_calls() -> list[tuple[str, int, bool]]:
    """Every call of ``design_spec`` in the package: (module, line, whether it is the
    fallback ``spec or design_spec(...)`` of a function that takes ``spec``)."""
    out = []
    for path in sorted(SRC.rglob("*.py")):
        tree = ast.parse(path.read_text(encoding="utf-8"))
        fallbacks = set()
        for fn in ast.walk(tree):
            if not isinstance(fn, (ast.FunctionDef, ast.AsyncFunctionDef)):
                continue
            params = {a.arg for a in fn.args.args + fn.args.kwonlyargs}
            for node in ast.walk(fn):
                if (isinstance(node, ast.BoolOp) and isinstance(node.op, ast.Or)
                        and "spec" in params and isinstance(node.values[0], ast.Name)
                        and node.values[0].id == "spec"):
                    fallbacks |= {id(v) for v in node.values[1:]}
        for node in ast.walk(tree):
            if (isinstance(node, ast.Call) and isinstance(node.func, ast.Name)
                    and node.func.id == "design_spec"):
                out.append((str(path.relative_to(SRC)), node.lineno, id(node) in fallbacks))
    return out


def test_the_design_specification_is_built_by_the_commands_and_passed_down():
    """The design specification is derived from the rig once, by the command that runs
    (``app``), and passed to every stage; a design entry point a script calls alone
    (``design(cfg, "hinf")``) derives it only when it was given none (``spec or ...``).
    Nothing below ``design`` derives it (the judgement takes its settings)."""
    calls = _design_spec_calls()
    assert calls, "the finder sees no call at all"
    stray = [(m, line) for m, line, fallback in calls
             if not (m.startswith("app/") or (m.startswith("design/") and fallback))]
    assert stray == []
    assert not any(m.startswith("analysis/") for m, _, _ in calls)


#: Words of a lab notebook or a ticket, not of a contract: code and tests say what holds and
#: why, history goes to benchmarks/README.md and CHANGELOG.md (the words are split so that
#: this file does not match itself)
_HISTORY = re.compile("|".join([r"\bused " + "to\b", r"\bas " + r"before\b",
                                r"\bearlier " + r"tuning\b", r"\bthe " + r"issue\b",
                                r"\bissue" + r"'s\b", r"\bissue " + r"\d+"]), re.IGNORECASE)


def test_no_history_or_ticket_words_in_code_and_tests():
    """Docstrings state the contract (house rule): none of :data:`_HISTORY`'s words of a
    past state or of a ticket in src/ or tests/."""
    found = []
    for path in sorted([*SRC.rglob("*.py"), *(ROOT / "tests").rglob("*.py")]):
        for k, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
            if _HISTORY.search(line):
                found.append(f"{path.relative_to(ROOT)}:{k}: {line.strip()}")
    assert not found, "\n".join(found)


def test_no_measurement_records_in_src():
    """A measurement behind a default ("Measured: …") is a record for benchmarks/README.md
    ("Where the design defaults come from"), not a contract of the code that holds it."""
    found = [f"{p.relative_to(ROOT)}:{k}" for p in sorted(SRC.rglob("*.py"))
             for k, line in enumerate(p.read_text(encoding="utf-8").splitlines(), 1)
             if re.search(r"\bMeasured:", line)]
    assert found == []


#: Words of the machine ambseal is for, and the layers above the generic core: the core
#: (robust, lti) states its contracts for any plant (the rotor layers say what a rotor is).
#: Its grid is a parameter θ, not a speed Ω. Acronyms, paper labels and symbols are matched
#: with their case (``p1`` may be a variable, ``AMB`` is the acronym); an axis is a machine's
#: unless it is numpy's ``axis=`` or the imaginary or real axis of the complex plane.
_MACHINE = re.compile(
    r"(?i:\b(rotors?|seals?|bearings?|rigs?|thesis|gyroscopic\w*|impellers?|turbo\w+|"
    r"levitat\w*|Campbell|displacements?|currents|shafts?|spin[- ]?ups?|speeds?|rpm)\b)"
    r"|\b(AMBs?|P[1-5]|Paper [1-5]|A_zeta|SPEED)\b|Ω"
    r"|(?<!imaginary )(?<!imaginary-)(?<!real )(?<!jω-)\bax[ie]s\b(?!=)"
    r"|ambseal\.(machine|design|analysis|identify|app|model|config|report|export|io|cli)\b")


def _machine_words(pkgs=("robust", "lti")) -> list[str]:
    """``file:line: text`` of every line of the packages' .py files that :data:`_MACHINE`
    matches."""
    found = []
    for pkg in pkgs:
        for path in sorted((SRC / pkg).rglob("*.py")):
            for k, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
                if _MACHINE.search(line):
                    found.append(f"{path.relative_to(ROOT)}:{k}: {line.strip()}")
    return found


def test_the_generic_core_mentions_no_machine():
    """The generic core — ``ambseal.robust`` and ``ambseal.lti`` — neither imports a rotor
    layer (import-linter's contract) nor speaks of one: no rotor word, no speed where it
    means θ, and no module above it in its code, comments or docstrings (:data:`_MACHINE`)."""
    found = _machine_words()
    assert not found, "\n".join(found)


@pytest.mark.parametrize("line, hit", [
    ("the rotor on its magnetic bearings", True),
    ("Rig measurements (P3 §4)", True),
    ("Speeds Ω (rad/s)", True),
    ("the inputs are the p displacements y_k", True),
    ("per AMB axis", True),
    ("controllers of :mod:`ambseal.machine`", True),
    ("np.linalg.norm(v, axis=1)", False),
    ("eigenvalues on the imaginary axis, imaginary-axis zeros, the jω-axis", False),
    ("the current controller, p1 = x, P12 has a jω zero", False),
    ("from ambseal.robust.hinf import hinfsyn", False),
])
def test_the_machine_words_are_seen_and_the_generic_ones_kept(line, hit):
    """:data:`_MACHINE` matches a rotor word in any case, and leaves numpy's ``axis=``,
    the complex plane's axes, "current" as an adjective and the package's own name alone
    (so the test above can fail, and does not fail on mathematics)."""
    assert bool(_MACHINE.search(line)) is hit

"""Every code block of the manual runs (house rule: code in the README and the manual are
tests, so the manual cannot rot).

The blocks of one page run in order, in one temporary folder (holding a copy of
``docs/rigs/`` and links to the repository's ``examples/`` and ``src/``, as a reader
working from the repository's root sees them) and one Python namespace, as a reader
would type them:

* ``python`` — executed;
* ``console`` — each ``$ command`` line runs: ``ambseal ...`` in this process
  (:func:`ambseal.cli.main`), anything else (a C compiler, the program it built, Octave)
  as a subprocess, its rest of the block skipped when the program is not installed. The
  lines after a command are its output as shown: an output that starts with
  ``ambseal: error:`` is checked — exit status 2 and that message on stderr, ``...``
  matching anything — and any other command must exit with 0;
* ``toml`` — parsed; with a first line ``# file: NAME`` also written to NAME;
* ``c`` — with a first line ``/* file: NAME */`` written to NAME (a ``console`` block
  compiles it); ``matlab`` — run by ``octave-cli`` when installed;
* ``json`` — parsed; ``text`` — output shown, not run.

After its blocks ran, every output file name a page quotes (``report.html``,
``campbell_<controller>.png/.json``) is one its commands, or the session's ``ambseal
run``, wrote, and every file its commands wrote (their manifests) is named on the page
(:func:`check_file_names`); the README and the pages that run nothing are held to the
session's run.

A block after a line ``% test: slow`` runs only with ``pytest -m slow`` (minutes of
synthesis); nothing later on its page may depend on it. ``ambseal run`` on the embedded
rig is not run again: the folder of the session's run (``terminal_run`` in
tests/conftest.py, the same command) is copied to where the page's command writes.
"""

from __future__ import annotations

import contextlib
import io
import json
import os
import re
import shlex
import shutil
import subprocess
import tomllib
from dataclasses import dataclass
from pathlib import Path

import pytest

from .octave import octave_cli

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"
KINDS = {"python", "console", "toml", "c", "matlab", "json", "text"}


@dataclass
class Block:
    page: str
    line: int
    kind: str
    body: str
    slow: bool


_FENCE = re.compile(r"^(?P<indent>[ \t]*)(?P<fence>```+)(?P<info>[^\n]*)\n(?P<body>.*?)"
                    r"^(?P=indent)(?P=fence)[ \t]*$", re.M | re.S)
_RST = re.compile(r"^\.\. code-block:: *(?P<kind>\S+)\n(?:[ \t]+:[^\n]*\n)*\n"
                  r"(?P<body>(?:(?:[ \t]+[^\n]*)?\n)+)", re.M)


def blocks_of(path: Path) -> list[Block]:
    """The page's code blocks in order (MyST fences in .md; ``code-block`` in .rst;
    directives such as ``{literalinclude}`` are not code blocks)."""
    text = path.read_text(encoding="utf-8")
    rel = str(path.relative_to(DOCS))
    out = []
    if path.suffix == ".md":
        for m in _FENCE.finditer(text):
            info = m["info"].strip()
            if info.startswith("{"):
                continue
            before = text[:m.start()].rstrip("\n").rsplit("\n", 1)[-1].strip()
            n = len(m["indent"])
            body = "".join(ln[n:] if ln[:n].strip() == "" else ln
                           for ln in m["body"].splitlines(keepends=True))
            out.append(Block(rel, text.count("\n", 0, m.start()) + 1, info.split()[0]
                             if info else "", body, before == "% test: slow"))
    else:
        for m in _RST.finditer(text):
            body = "\n".join(ln[3:] for ln in m["body"].splitlines())
            out.append(Block(rel, text.count("\n", 0, m.start()) + 1, m["kind"], body, False))
    return out


PAGES = sorted(p for p in [*DOCS.rglob("*.md"), *DOCS.rglob("*.rst")]
               if "_build" not in p.parts and "generated" not in p.parts)
WITH_CODE = [p for p in PAGES if blocks_of(p)]
WITH_SLOW = [p for p in WITH_CODE if any(b.slow for b in blocks_of(p))]


def _ids(pages):
    return [str(p.relative_to(DOCS)) for p in pages]


def _commands(body: str) -> list[tuple[str, list[str]]]:
    """(command, expected output lines) of a console block; a line ending in ``\\``
    continues on the next one, as in a POSIX shell (the backslash and the line break
    removed, nothing else)."""
    cmds: list[tuple[str, list[str]]] = []
    pending = None
    for line in body.splitlines():
        if pending is not None:
            pending += line
        elif line.startswith("$ "):
            pending = line[2:]
        elif cmds:
            cmds[-1][1].append(line)
            continue
        if pending is not None and pending.endswith("\\"):
            pending = pending[:-1]
        elif pending is not None:
            cmds.append((pending.strip(), []))
            pending = None
    return cmds


def _matches(expected: list[str], got: str) -> bool:
    """``expected`` (``...`` matching anything, white space folded) is in ``got``."""
    want = " ".join(" ".join(expected).split())
    pattern = ".*?".join(re.escape(part) for part in want.split("..."))
    return re.search(pattern, " ".join(got.split()), re.S) is not None


class Page:
    """The state one page's blocks share: folder, namespace, the commands that ran."""

    def __init__(self, folder: Path, request):
        self.folder, self.request = folder, request
        self.namespace: dict = {"__name__": "__manual__"}
        self.ran: list[str] = []
        self.inputs: set[str] = set()  # files the page's own toml and C blocks wrote

    def run(self, block: Block) -> None:
        where = f"{block.page}:{block.line}"
        if block.kind not in KINDS:
            pytest.fail(f"{where}: a ```{block.kind} block: the manual's blocks are "
                        f"{sorted(KINDS)} (tests/test_docs.py runs them)")
        getattr(self, f"_{block.kind}")(block.body, where)

    def _python(self, body, where):
        exec(compile(body, where, "exec"), self.namespace)

    def _toml(self, body, where):
        tomllib.loads(body)
        first = body.splitlines()[0] if body.strip() else ""
        if first.startswith("# file: "):
            (self.folder / first[len("# file: "):].strip()).write_text(body, encoding="utf-8")
            self.inputs.add(first[len("# file: "):].strip())

    def _c(self, body, where):
        first = body.splitlines()[0]
        m = re.match(r"/\* file: (\S+) \*/", first)
        assert m, f"{where}: a C block starts with /* file: NAME */"
        (self.folder / m[1]).write_text(body, encoding="utf-8")
        self.inputs.add(m[1])

    def _json(self, body, where):
        json.loads(body)

    def _text(self, body, where):
        pass

    def _matlab(self, body, where):
        octave = octave_cli()
        if octave is None:
            return  # tests/robust/test_robust_digital.py checks the .mat in Octave too
        script = "pkg load control\n" + body
        r = subprocess.run([octave, "--no-gui", "-q", "--eval", script],
                           cwd=self.folder, capture_output=True, text=True, timeout=120)
        assert r.returncode == 0, f"{where}: octave: {r.stderr}"

    def _console(self, body, where):
        for cmd, expected in _commands(body):
            argv = shlex.split(cmd)
            if argv[0] == "ambseal":
                self._ambseal(argv[1:], expected, f"{where}: {cmd}")
            else:
                program = argv[0] if argv[0].startswith("./") else shutil.which(argv[0])
                if program is None:
                    return  # not installed here: the rest of the block needs it
                r = subprocess.run([str(self.folder / argv[0]) if argv[0].startswith("./")
                                    else program, *argv[1:]], cwd=self.folder,
                                   capture_output=True, text=True, timeout=300)
                assert r.returncode == 0, f"{where}: {cmd}: {r.stdout}{r.stderr}"
                self.ran.append(cmd)

    def _ambseal(self, argv, expected, where):
        from ambseal.cli import main

        error = bool(expected) and expected[0].startswith("ambseal: error:")
        if argv and argv[0] == "run" and self._embedded_run(argv):
            return
        out, err = io.StringIO(), io.StringIO()
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            code = main(argv)
        got = out.getvalue() + err.getvalue()
        status = re.fullmatch(r"\(exit status (\d+)\)", expected[-1].strip()) \
            if expected else None
        if error:
            assert code == 2, f"{where}: expected the error, got exit {code}: {got}"
            assert _matches(expected, err.getvalue()), (
                f"{where}: the page shows\n{chr(10).join(expected)}\nambseal said\n{got}")
        elif status:  # a verdict the page shows with its exit status
            assert code == int(status[1]), f"{where}: exit {code}: {got}"
            assert _matches(expected[:-1], got), (
                f"{where}: the page shows\n{chr(10).join(expected)}\nambseal said\n{got}")
        else:
            assert code == 0, f"{where}: exit {code}: {got}"
        self.ran.append(" ".join(["ambseal", *argv]))

    def _embedded_run(self, argv) -> bool:
        """``ambseal run [--out DIR]`` on the embedded rig: the session's folder copied."""
        rest = argv[1:]
        if rest and rest[0] == "--out" and len(rest) == 2:
            out = rest[1]
        elif not rest:
            out = "ambseal-out"
        else:
            return False
        src = self.request.getfixturevalue("terminal_run")[0]
        shutil.copytree(src, self.folder / out, dirs_exist_ok=True)
        self.ran.append(" ".join(["ambseal", *argv]))
        return True


def _run_page(path: Path, tmp_path, monkeypatch, request, slow: bool) -> Page:
    for rig in (DOCS / "rigs").glob("*"):
        shutil.copy(rig, tmp_path / rig.name)
    for folder in ("examples", "src"):  # the pages' commands run from the repository root
        (tmp_path / folder).symlink_to(ROOT / folder, target_is_directory=True)
    monkeypatch.chdir(tmp_path)
    page = Page(tmp_path, request)
    for block in blocks_of(path):
        if block.slow and not slow:
            continue
        page.run(block)
    return page


def test_the_manual_has_code_blocks_of_known_kinds():
    found = [b for p in PAGES for b in blocks_of(p)]
    assert len(found) > 20
    assert {b.kind for b in found} <= KINDS, {b.kind for b in found} - KINDS


#: C modules the manual names that no page exports: the LPV controller on speed and the
#: one tracked on the seal's k take minutes of synthesis (``ambseal_<method>``, as the
#: PID's module the deployment page writes and checks)
NOT_EXPORTED = ("ambseal_lpv", "ambseal_tracked")
_C_NAME = re.compile(r"\b(?:ambseal_\w+(?:\.[ch]\b)?|AMBSEAL_\w+)")


def _check_c_names(page: Page, path: Path) -> None:
    """Every C file, function, type and macro name the page quotes (prose, tables and its
    blocks) is one its own commands wrote: a ``.h``/``.c`` name is a file written in the
    page's folder, an identifier is declared in the header of the longest module name it
    starts with. Names of :data:`NOT_EXPORTED` modules are left out; placeholders
    (``ambseal_<m>``) are no names."""
    written = {f.name: f for f in page.folder.rglob("ambseal_*.[ch]")
               if "examples" not in f.relative_to(page.folder).parts[:1]}
    modules = sorted({f.stem for f in written.values()}, key=len, reverse=True)
    text = path.read_text(encoding="utf-8")
    for name in sorted(set(_C_NAME.findall(text))):
        prefixes = [*modules, *NOT_EXPORTED]
        if name.isupper():  # a macro; other upper-case names are not C (environment variables)
            module = next((m for m in prefixes if name.startswith(m.upper() + "_")), None)
        elif name.endswith((".h", ".c")):
            module = name[:-2] if name in written else next(
                (m for m in NOT_EXPORTED if name[:-2] == m), "")
        else:
            module = next((m for m in prefixes if name == m or name.startswith(m + "_")), "")
        if module is None or module in NOT_EXPORTED:
            continue
        assert module, (f"{path.name} quotes {name}: no C module the page's commands wrote "
                        f"({', '.join(modules) or 'none'}) has it")
        if not name.endswith((".h", ".c")) and name != module:
            header = written[f"{module}.h"].read_text(encoding="utf-8")
            assert re.search(rf"\b{name}\b", header), (
                f"{path.name} quotes {name}, which {module}.h does not declare")


#: Extensions of the files ambseal's commands write.
_OUTPUT_EXT = ("json", "html", "png", "csv", "parquet", "mat", "npz", "toml", "h", "c")
_SPAN = re.compile(r"(?<!`)`([^`]+)`(?!`)|``([^`]+)``")  # may break a line; RST's too
_FILE = re.compile(r"(?:[\w.<>*{},-]+/)*[\w<>*{},-][\w.<>*{},-]*\.(?:" + "|".join(_OUTPUT_EXT)
                   + r")(?:/\.\w+)*")
_TREE = re.compile(r"^[│├└─ ]*[├└]── (\S+)", re.M)

#: Output names a page quotes that its commands (and the session's ``ambseal run``) do
#: not write here, each with the reason.
NOT_WRITTEN = {
    "getting-started.md": {
        "controllers/rejection_<m>.json": "a synchronous rejection's; the embedded rig runs "
                                          "none (tests/exported_files.py reads them)",
        "ambseal_<m>_rejection.h": "as controllers/rejection_<m>.json",
        "ambseal_<m>_rejection.c": "as controllers/rejection_<m>.json"},
    "identification.md": {"run.csv": "a user's record, read", "run.csv.json": "its sidecar",
                          "STEPS.csv": "a user's static load steps, read"},
    "own-machine.md": {"campbell_pid.png": "its `ambseal campbell` runs with -m slow"},
}
#: Files every output folder holds, named once in the manual (getting-started.md).
EVERY_FOLDER = ("manifest.json",)


def _expand(name: str) -> list[str]:
    """``a_<m>.json/.npz`` → both names; ``a.{h,c}`` → both names."""
    base, *more = name.split("/.")
    names = [base] + [base.rsplit(".", 1)[0] + "." + ext for ext in more]
    out = []
    for n in names:
        m = re.search(r"\{([^}]*)\}", n)
        out += ([n[:m.start()] + alt + n[m.end():] for alt in m[1].split(",")] if m else [n])
    return out


def quoted_outputs(text: str) -> set[str]:
    """The file names a page quotes as code in its prose and tables, or lists in a folder
    tree (``├── report.html``), with their ``<placeholder>`` and ``*`` parts; names in
    its code blocks are inputs or commands, not quotes (a figure's caption is prose)."""
    prose = _FENCE.sub(lambda m: m["body"] if m["info"].strip().startswith("{figure}")
                       else "", text)  # a figure's caption is prose
    trees = "".join(m["body"] for m in _FENCE.finditer(text)
                    if m["info"].strip().split()[:1] == ["text"])
    found = set()
    for chunk in [*("".join(m) for m in _SPAN.findall(prose)), *_TREE.findall(trees)]:
        for token in chunk.split():
            found.update(n for n in _expand(token.strip(",;:()")) if _FILE.fullmatch(n))
    return found


def _pattern(name: str) -> re.Pattern:
    """A quoted name as a pattern over written paths: ``<m>`` one path part, ``*`` any."""
    parts = re.split(r"(<[^>]+>|\*)", name)
    rx = "".join("[^/]+" if p.startswith("<") else "[^/]*" if p == "*" else re.escape(p)
                 for p in parts)
    return re.compile(r"(?:.*/)?" + rx)


def _written(folder: Path) -> list[str]:
    """Every file under ``folder`` (links to the repository's folders not followed), as a
    POSIX path relative to it."""
    out = []
    for here, dirs, files in os.walk(folder):
        dirs[:] = [d for d in dirs if not (Path(here) / d).is_symlink()]
        out += [(Path(here) / f).relative_to(folder).as_posix() for f in files]
    return out


def _inputs(page: Page | None) -> set[str]:
    """Names of files the commands read: the repository's rigs and data, the page's own
    files."""
    repo = {f.name for d in (ROOT / "examples", ROOT / "src" / "ambseal" / "data",
                             DOCS / "rigs") for f in d.iterdir()}
    return repo | {"pyproject.toml"} | (page.inputs if page else set())


def check_file_names(text: str, where: str, written: list[str], request,
                     not_written: dict[str, str], manifests: list[Path]) -> None:
    """Each output file name the page quotes (:func:`quoted_outputs`) is a file its
    commands wrote (``written``), or one ``ambseal run`` writes (the session's run,
    ``terminal_run``, looked at only when needed); and each file a command of the page
    wrote (each ``manifest.json`` of ``manifests``) is one the page names (``*.png``
    alone names none)."""
    quoted = {n for n in quoted_outputs(text) if n not in not_written
              and Path(n).name not in _inputs(None) | set(not_written)}
    run: list[str] | None = None
    for name in sorted(quoted):
        pat = _pattern(name)
        if any(pat.fullmatch(w) for w in written):
            continue
        if run is None:
            run = _written(request.getfixturevalue("terminal_run")[0])
        assert any(pat.fullmatch(w) for w in run), (
            f"{where} names {name}: no command of the page, nor `ambseal run`, writes it")
    # a bare `*.png` names no file: each must be named by a name of its own
    patterns = [_pattern(n) for n in quoted_outputs(text)
                if re.sub(r"<[^>]+>|\*", "", Path(n).stem)]
    for manifest in manifests:
        for f in json.loads(manifest.read_text(encoding="utf-8"))["files"]:
            if Path(f).name in EVERY_FOLDER:
                continue
            assert any(p.fullmatch(f) for p in patterns), (
                f"{where}: {manifest.parent.name}/{f} is written by a command of the page, "
                "which does not name it")


#: pages whose blocks design for a minute or more (a μ-synthesis with every default, the
#: rotor's controllers discretised for the target): CI's second Python leaves them out
HEAVY_PAGES = {"robust-control.md", "deploying.md"}


@pytest.mark.xdist_group("terminal_run")  # the manual's `ambseal run` reads it
@pytest.mark.parametrize("path", [pytest.param(p, marks=pytest.mark.heavy)
                                  if p.name in HEAVY_PAGES else p for p in WITH_CODE],
                         ids=_ids(WITH_CODE))
def test_page_runs(path, tmp_path, monkeypatch, request):
    """The page's blocks run (module docstring), the C names it quotes are those its
    commands wrote (:func:`_check_c_names`), and so are the file names it quotes, each
    file written named (:func:`check_file_names`)."""
    page = _run_page(path, tmp_path, monkeypatch, request, slow=False)
    if path.name == "own-machine.md":
        # the page's rig, written from the page alone, validates and runs modes and design
        for command in ("ambseal validate compressor.toml", "ambseal modes compressor.toml",
                        "ambseal design compressor.toml --method pid"):
            assert any(c.startswith(command) for c in page.ran), command
    if path.name == "deploying.md":
        # export names its C module after the method or after the controller file: both
        # ways are shown, so that the names the page quotes for each are checked
        for way in ("--method", "--controller"):
            assert any(c.startswith("ambseal export") and way in c.split()
                       for c in page.ran), way
    _check_c_names(page, path)
    rel = str(path.relative_to(DOCS))
    written = [w for w in _written(page.folder) if w not in page.inputs
               and not w.startswith(tuple(f.name for f in (DOCS / "rigs").iterdir()))]
    check_file_names(path.read_text(encoding="utf-8"), rel, written, request,
                     NOT_WRITTEN.get(rel, {}),
                     [page.folder / w for w in written if Path(w).name == "manifest.json"])


def test_the_file_name_check_catches_a_wrong_name_and_an_unnamed_file(tmp_path):
    """:func:`check_file_names` on a made-up page: the name ``export --controller``
    writes (``ambseal_controller_pid.h``) passes and the one the manual once showed
    (``ambseal_pid.h``) fails, as does a written file the page leaves unnamed; placeholders,
    ``/.ext`` and ``{h,c}`` alternatives expand; the session's run folder is asked only
    for a name the page's commands did not write."""
    out = tmp_path / "again"
    written = ["again/c/ambseal_controller_pid.h", "again/c/ambseal_controller_pid.c",
               "again/manifest.json"]
    for w in written:
        (tmp_path / w).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / w).write_text("{}")
    (out / "manifest.json").write_text(json.dumps({"files": {
        "c/ambseal_controller_pid.h": "", "c/ambseal_controller_pid.c": "",
        "manifest.json": ""}}))
    run = tmp_path / "run"
    (run / "controllers").mkdir(parents=True)
    (run / "controllers" / "controller_mu.npz").write_text("")

    class Request:
        asked = 0

        def getfixturevalue(self, name):
            assert name == "terminal_run"
            self.asked += 1
            return run, {}, ""

    def check(text):
        request = Request()
        check_file_names(text, "page.md", written, request, {}, [out / "manifest.json"])
        return request.asked

    assert check("It writes `ambseal_controller_<m>.{h,c}`.") == 0
    assert check("`ambseal_controller_pid.h/.c`; a run's `controller_<m>.npz`.") == 1
    with pytest.raises(AssertionError, match="names ambseal_pid.h"):
        check("Its header is `ambseal_pid.h` (`ambseal_controller_pid.c`).")
    for text in ("Its header is `ambseal_controller_pid.h`.",
                 "`ambseal_controller_pid.h` and `*.c`"):  # a bare glob names no file
        with pytest.raises(AssertionError, match="c/ambseal_controller_pid.c is written"):
            check(text)


WITHOUT_CODE = [ROOT / "README.md", *(p for p in PAGES if p not in WITH_CODE)]


@pytest.mark.xdist_group("terminal_run")  # the names are those `ambseal run` writes
@pytest.mark.parametrize("path", WITHOUT_CODE,
                         ids=["README.md", *_ids(WITHOUT_CODE[1:])])
def test_page_without_commands_names_files_a_run_writes(path, request):
    """The README and the pages that run nothing quote output files of ``ambseal run``
    (the session's run, ``terminal_run``): each is one it writes
    (:func:`check_file_names`)."""
    check_file_names(path.read_text(encoding="utf-8"), path.name, [], request, {}, [])


@pytest.mark.slow
@pytest.mark.parametrize("path", WITH_SLOW, ids=_ids(WITH_SLOW))
def test_page_runs_with_its_slow_blocks(path, tmp_path, monkeypatch, request):
    _run_page(path, tmp_path, monkeypatch, request, slow=True)

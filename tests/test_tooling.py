"""The habits of a maintained package, as tests: lint and format (ruff),
types (mypy), the import architecture (import-linter and two rules it can't
express), the version written once, a light ``import qc_control``, and the
files a release needs.

The tools are in the ``lint`` extra, which the ``test`` extra includes; their
configuration is in pyproject.toml, shared with .pre-commit-config.yaml.
"""

from __future__ import annotations

import ast
import functools
import importlib
import importlib.metadata
import io
import pydoc
import re
import shutil
import subprocess
import sys
import tokenize
from collections.abc import Iterator
from pathlib import Path

import pytest

import qc_control

try:  # Python >= 3.11
    import tomllib
except ModuleNotFoundError:  # pragma: no cover - Python 3.10
    import tomli as tomllib

ROOT = Path(__file__).resolve().parent.parent
PACKAGE = ROOT / "qc_control"
PYPROJECT = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))
LINTED = ["qc_control", "tests", "examples", "benchmarks"]

#: Third-party packages that may be imported inside a function (with a comment
#: saying why): heavy, and needed only for figures or for distributed sweeps.
#: tqdm is not here: a required dependency that imports in ~0.2 s.
DEFERRABLE = {"matplotlib", "dask", "distributed", "panel", "bokeh"}
#: The deferred imports of the package's own code: the entry point loads the
#: command inside its Ctrl-C handler (qc_control/cli/console.py says why), and the
#: nonlinear car and the sweeps' streams load their compiled loops, which
#: import numba (~0.5 s), only when a batch is stepped or a stream is built.
DEFERRED_OWN = {
    ("qc_control/cli/console.py", "qc_control.cli.parser"),
    # and its light top level (--version, --help) first, inside the same handler
    ("qc_control/cli/console.py", "qc_control.cli.commands"),
    ("qc_control/models/nonlinear.py", "qc_control.models.nlkernel"),
    ("qc_control/numerics/lti.py", "qc_control.numerics.recurrence"),
    # substeps_for's old home answers from the step policy, which imports
    # python-control (stability limits), only when the old name is asked for
    ("qc_control/numerics/stepper.py", "qc_control.numerics.steps"),
    # the explorer's page imports Panel (an optional extra) when it runs
    ("qc_control/cli/parser.py", "qc_control.cli.explore"),
    # scipy.optimize (~0.3 s) for the contact events' root finder only, so
    # that ``import qc_control`` and runs without events do not load it
    ("qc_control/numerics/integrate.py", "scipy.optimize"),
}
#: The presentation layer, where matplotlib may be imported at module level.
PRESENTATION = ("qc_control.report", "qc_control.report.plotting")


def _run(args: list[str], timeout: float = 300) -> subprocess.CompletedProcess:
    return subprocess.run(
        args, cwd=ROOT, capture_output=True, text=True, timeout=timeout, check=False
    )


# --- ruff, mypy, import-linter ---------------------------------------------


def test_ruff_check_is_clean():
    run = _run([sys.executable, "-m", "ruff", "check", "--no-fix", *LINTED])
    assert run.returncode == 0, run.stdout + run.stderr


def test_ruff_format_is_clean():
    run = _run([sys.executable, "-m", "ruff", "format", "--check", *LINTED])
    assert run.returncode == 0, run.stdout + run.stderr


@pytest.mark.slow  # measured 0.9-3 s with a warm .mypy_cache, 8-21 s cold
@pytest.mark.xdist_group("mypy")  # one .mypy_cache in the work tree: one writer at a time
def test_mypy_is_clean():
    run = _run([sys.executable, "-m", "mypy", "qc_control"])
    assert run.returncode == 0, run.stdout + run.stderr


#: Packages that [tool.mypy] types Any on purpose although qc_control imports them (the
#: explorer's Bokeh and Panel: pyproject.toml says why); every other module it skips
#: is one that qc_control never uses (`mypy_skipped_uses`).
TYPED_ANY = {"bokeh", "panel", "param"}


def _mypy_skips() -> dict[str, bool]:
    """The modules [tool.mypy] skips, each with whether its sub-modules are skipped too
    (``a.*``: ``a`` and below), but for `TYPED_ANY`'s."""
    skips: dict[str, bool] = {}
    for override in PYPROJECT["tool"]["mypy"]["overrides"]:
        if override.get("follow_imports") == "skip":
            for pattern in override["module"]:
                base = pattern.removesuffix(".*")
                if base.split(".")[0] not in TYPED_ANY:
                    skips[base] = skips.get(base, False) or pattern.endswith(".*")
    return skips


def _dotted_names(tree: ast.AST) -> Iterator[tuple[ast.AST, str]]:
    """Every module name an absolute import reads, and every dotted name ``a.b.c`` used."""
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            yield from ((node, alias.name) for alias in node.names)
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            yield node, node.module
            yield from ((node, f"{node.module}.{alias.name}") for alias in node.names)
        elif isinstance(node, ast.Attribute):
            parts, base = [node.attr], node.value
            while isinstance(base, ast.Attribute):
                parts.append(base.attr)
                base = base.value
            if isinstance(base, ast.Name):
                yield node, ".".join([base.id, *reversed(parts)])


def mypy_skipped_uses() -> list[str]:
    """The package's imports and dotted names of modules that mypy skips."""
    skips, offenders = _mypy_skips(), []
    for path, _, _ in _modules():
        for node, name in _dotted_names(_tree(path.read_text(encoding="utf-8"))):
            parts = name.split(".")
            below = (skips.get(".".join(parts[:i])) for i in range(1, len(parts)))
            if name in skips or any(below):
                offenders.append(f"{_where(path, node)} ({name})")
    return offenders


def test_mypy_skips_no_module_the_package_uses():
    """[tool.mypy] skips third-party modules that qc_control never imports, to check
    the package sooner; were one of them used, its names would be typed Any in
    qc_control's own code, unchecked and silently."""
    _assert_none(mypy_skipped_uses(), "uses of modules that [tool.mypy] skips")


def test_the_mypy_skip_rule_sees_what_it_looks_for(tmp_path, monkeypatch):
    """An import of a skipped module, an import from one, and a skipped sub-package
    reached as an attribute are found; the explorer's Panel and the scipy
    sub-packages that mypy follows are not."""
    pkg = tmp_path / "qc_control"
    pkg.mkdir()
    (pkg / "a.py").write_text(
        "import jinja2\n"  # an offender
        "import scipy\n"
        "import panel as pn\n"  # typed Any on purpose
        "from scipy.interpolate import CubicSpline\n"  # an offender
        "from scipy import linalg, io\n"  # io: an offender
        "x = scipy.spatial.distance\n"  # an offender
        "y = scipy.linalg.expm\n"
    )
    monkeypatch.setattr(sys.modules[__name__], "ROOT", tmp_path)
    monkeypatch.setattr(sys.modules[__name__], "PACKAGE", pkg)
    assert mypy_skipped_uses() == [
        "qc_control/a.py:1: import jinja2 (jinja2)",
        "qc_control/a.py:4: from scipy.interpolate import CubicSpline (scipy.interpolate)",
        "qc_control/a.py:4: from scipy.interpolate import CubicSpline "
        "(scipy.interpolate.CubicSpline)",
        "qc_control/a.py:5: from scipy import linalg, io (scipy.io)",
        "qc_control/a.py:6: scipy.spatial.distance (scipy.spatial.distance)",
        "qc_control/a.py:6: scipy.spatial (scipy.spatial)",
    ]


def _lint_imports() -> subprocess.CompletedProcess:
    code = "import sys; from importlinter.cli import lint_imports_command as c; sys.exit(c())"
    return _run([sys.executable, "-c", code, "--no-cache"])


def test_import_contracts_hold():
    """The contracts in pyproject.toml's [tool.importlinter]: the layers, the
    numerics that import nothing vehicle-specific, no cycles, and no module
    importing the package root."""
    run = _lint_imports()
    assert run.returncode == 0, run.stdout + run.stderr


@pytest.mark.xdist_group("mypy")
def test_the_tools_accept_their_configuration(tmp_path):
    """The strict xfails above would also hide a broken configuration; this
    does not: mypy reads [tool.mypy] without a warning, and import-linter
    checks every contract (exit status 1 is a broken contract, not an error)."""
    typed = tmp_path / "typed.py"
    typed.write_text("x: int = 1\n")
    run = _run([sys.executable, "-m", "mypy", str(typed)])
    assert run.returncode == 0 and not run.stderr, run.stdout + run.stderr
    run = _lint_imports()
    assert run.returncode in (0, 1), run.stdout + run.stderr
    for contract in PYPROJECT["tool"]["importlinter"]["contracts"]:
        assert re.search(rf"{re.escape(contract['name'])} (KEPT|BROKEN)", run.stdout), contract


def _contract(name: str) -> dict:
    contracts = PYPROJECT["tool"]["importlinter"]["contracts"]
    (found,) = [c for c in contracts if c["name"] == name]
    return found


def test_every_numerics_module_is_kept_from_the_vehicle():
    """The general numerics are one sub-package, the bottom layer of the
    layers contract but for `qc_control.compat` (python-control's private
    names, which imports nothing of qc_control), so they import no
    vehicle-specific module, and every vehicle-specific module lives above it."""
    layers = _contract("Sub-packages, from the command line down to general numerics")["layers"]
    assert layers[-2:] == ["numerics", "compat"]
    assert "from ." not in (PACKAGE / "compat.py").read_text(encoding="utf-8")
    numerics = {p.stem for p in (PACKAGE / "numerics").glob("*.py")} - {"__init__"}
    assert numerics == {
        "checks", "integrate", "interconnect", "limits", "lti", "messages", "methods",
        "order_conditions", "recurrence", "stability", "stepper", "steps", "compiled_stepper",
        "adaptive", "sampled", "clocked", "exact", "trajectory_stability", "threads",
        "reference",
    }  # fmt: skip
    vehicle = {p.stem for p in (PACKAGE / "models").glob("*.py")}
    assert {"vehicle", "quarter", "halfcar", "nonlinear", "nlkernel"} <= vehicle


# --- two import rules import-linter can't express -----------------------------


def _modules() -> Iterator[tuple[Path, str, bool]]:
    """(path, dotted name, is a package) for every module of qc_control."""
    for path in sorted(PACKAGE.rglob("*.py")):
        parts = path.relative_to(ROOT).with_suffix("").parts
        is_package = parts[-1] == "__init__"
        yield path, ".".join(parts[:-1] if is_package else parts), is_package


def _is_module(dotted: str) -> bool:
    base = ROOT.joinpath(*dotted.split("."))
    return base.with_suffix(".py").exists() or (base / "__init__.py").exists()


def _target(node: ast.ImportFrom, module: str, is_package: bool) -> str | None:
    """The qc_control module a ``from ... import`` reads from, else None."""
    if node.level == 0:
        name = node.module or ""
        return name if name.split(".")[0] == "qc_control" else None
    parts = module.split(".") if is_package else module.split(".")[:-1]
    parts = parts[: len(parts) - (node.level - 1)]
    return ".".join(parts + ([node.module] if node.module else []))


def _is_type_checking(test: ast.expr) -> bool:
    return (isinstance(test, ast.Name) and test.id == "TYPE_CHECKING") or (
        isinstance(test, ast.Attribute) and test.attr == "TYPE_CHECKING"
    )


def _imports(tree: ast.AST) -> Iterator[tuple[ast.Import | ast.ImportFrom, bool, bool]]:
    """Every import: (node, inside a function, inside ``if TYPE_CHECKING:``)."""

    def walk(node: ast.AST, in_function: bool, typing_only: bool):
        if isinstance(node, ast.Import | ast.ImportFrom):
            yield node, in_function, typing_only
        in_function = in_function or isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef)
        if isinstance(node, ast.If) and _is_type_checking(node.test):
            for child in node.body:
                yield from walk(child, in_function, True)
            for child in node.orelse:
                yield from walk(child, in_function, typing_only)
            return
        for child in ast.iter_child_nodes(node):
            # an import is a statement, and statements nest only in statements,
            # except clauses and match cases: the expressions (most of a module's
            # nodes) hold none, and walking them took most of this file's AST time
            if isinstance(child, ast.stmt | ast.excepthandler | ast.match_case):
                yield from walk(child, in_function, typing_only)

    yield from walk(tree, False, False)


@functools.cache
def _tree(source: str) -> ast.Module:
    """A module's syntax tree, parsed once per source text: the checks below each
    read every module of the package (the walkers never change a tree)."""
    return ast.parse(source)


def _top_level(node: ast.Import | ast.ImportFrom) -> set[str]:
    """The top-level packages an absolute import names ('' for relative)."""
    if isinstance(node, ast.ImportFrom):
        return {"" if node.level else (node.module or "").split(".")[0]}
    return {alias.name.split(".")[0] for alias in node.names}


def _comment_lines(source: str) -> tuple[set[int], set[int]]:
    """Lines that hold a comment, and lines that hold nothing else."""
    with_comment, comment_only = set(), set()
    for tok in tokenize.generate_tokens(io.StringIO(source).readline):
        if tok.type == tokenize.COMMENT:
            with_comment.add(tok.start[0])
            if not tok.line[: tok.start[1]].strip():
                comment_only.add(tok.start[0])
    return with_comment, comment_only


def _where(path: Path, node: ast.stmt | ast.expr) -> str:
    return f"{path.relative_to(ROOT)}:{node.lineno}: {ast.unparse(node)}"


def private_name_imports() -> list[str]:
    """``from .x import _y`` across the package's modules (a private
    submodule, ``from . import _x``, is the package's own and is allowed)."""
    offenders = []
    for path, module, is_package in _modules():
        for node, _, _ in _imports(_tree(path.read_text(encoding="utf-8"))):
            if not isinstance(node, ast.ImportFrom):
                continue
            target = _target(node, module, is_package)
            if target is None or target == module:
                continue
            private = [
                alias.name
                for alias in node.names
                if alias.name.startswith("_")
                and not (alias.name.startswith("__") and alias.name.endswith("__"))
                and not _is_module(f"{target}.{alias.name}")
            ]
            if private:
                offenders.append(_where(path, node))
    return offenders


def function_level_imports() -> list[str]:
    """Imports inside functions that are not a deferrable heavy package with
    a comment (on the line, or the line above) that says why."""
    offenders = []
    for path, _, _ in _modules():
        source = path.read_text(encoding="utf-8")
        with_comment, comment_only = _comment_lines(source)
        for node, in_function, _ in _imports(_tree(source)):
            if not in_function:
                continue
            lines = range(node.lineno, (node.end_lineno or node.lineno) + 1)
            explained = node.lineno - 1 in comment_only or any(i in with_comment for i in lines)
            entry = (path.relative_to(ROOT).as_posix(), _resolved(path, node)) in DEFERRED_OWN
            if not ((_top_level(node) <= DEFERRABLE or entry) and explained):
                offenders.append(_where(path, node))
    return offenders


def _resolved(path: Path, node: ast.stmt) -> str:
    """``qc_control.cli.parser`` for ``from .parser import run`` in qc_control/cli/console.py."""
    if isinstance(node, ast.ImportFrom) and node.level == 1:
        package = path.parent.relative_to(ROOT).parts
        return ".".join((*package, node.module or ""))
    if isinstance(node, ast.ImportFrom) and node.level == 0:
        return node.module or ""
    return ""


def module_level_matplotlib() -> list[str]:
    """matplotlib imported at module level outside the presentation layer."""
    offenders = []
    for path, module, _ in _modules():
        if module.startswith(PRESENTATION):
            continue
        for node, in_function, typing_only in _imports(_tree(path.read_text("utf-8"))):
            if not in_function and not typing_only and "matplotlib" in _top_level(node):
                offenders.append(_where(path, node))
    return offenders


def _assert_none(offenders: list[str], rule: str) -> None:
    assert not offenders, f"{len(offenders)} {rule}:\n" + "\n".join(offenders)


def test_no_private_names_imported_across_modules():
    _assert_none(private_name_imports(), "private names imported from another module")


def test_imports_inside_functions_only_for_heavy_optional_packages():
    _assert_none(
        function_level_imports(),
        f"imports inside functions that are not one of {sorted(DEFERRABLE)} with a comment",
    )


def test_matplotlib_is_imported_at_module_level_only_by_the_presentation_layer():
    _assert_none(module_level_matplotlib(), "module-level matplotlib imports")


def test_the_import_rules_see_what_they_look_for(tmp_path, monkeypatch):
    """The three checks above find each kind of offender in a small package,
    and accept what they should."""
    pkg = tmp_path / "qc_control"
    pkg.mkdir()
    (pkg / "__init__.py").write_text("")
    (pkg / "_private.py").write_text("")
    (pkg / "a.py").write_text("_hidden = 1\n__dunder__ = 2\n")
    (pkg / "b.py").write_text(
        "from __future__ import annotations\n"
        "from typing import TYPE_CHECKING\n"
        "from .a import _hidden, __dunder__\n"  # private: an offender
        "from . import _private\n"  # a private submodule: allowed
        "import matplotlib.pyplot as plt\n"  # module-level matplotlib: an offender
        "if TYPE_CHECKING:\n"
        "    from matplotlib.figure import Figure\n"  # typing only: allowed
        "def f():\n"
        "    # matplotlib: heavy, only for this figure\n"
        "    from matplotlib.figure import Figure\n"  # allowed
        "    import dask  # optional, for distributed sweeps\n"  # allowed
        "    import tqdm  # light\n"  # not deferrable: an offender
        "    import matplotlib\n"  # no comment: an offender
        "    from .a import __dunder__\n"  # internal: an offender
    )
    monkeypatch.setattr(sys.modules[__name__], "ROOT", tmp_path)
    monkeypatch.setattr(sys.modules[__name__], "PACKAGE", pkg)
    assert private_name_imports() == ["qc_control/b.py:3: from .a import _hidden, __dunder__"]
    assert module_level_matplotlib() == ["qc_control/b.py:5: import matplotlib.pyplot as plt"]
    assert function_level_imports() == [
        "qc_control/b.py:12: import tqdm",
        "qc_control/b.py:13: import matplotlib",
        "qc_control/b.py:14: from .a import __dunder__",
    ]


# --- functions that each do one thing; no repeated blocks -----------------------

#: The longest a function of the package may be, in lines of code: its body
#: without the docstring, blank lines or comment lines. Complexity is ruff's
#: C901 (mccabe, max-complexity in pyproject.toml), run by test_ruff_check_is_clean.
MAX_FUNCTION_LINES = 80


def _code_lines(lines: list[str], node: ast.FunctionDef | ast.AsyncFunctionDef) -> int:
    body = node.body
    first = body[0]
    if isinstance(first, ast.Expr) and isinstance(first.value, ast.Constant):
        if len(body) == 1:
            return 0
        first = body[1]
    code = lines[first.lineno - 1 : node.end_lineno]
    return sum(1 for line in code if line.strip() and not line.strip().startswith("#"))


def long_functions(limit: int = MAX_FUNCTION_LINES) -> list[str]:
    """Functions of the package with more than ``limit`` lines of code."""
    offenders = []
    for path, _, _ in _modules():
        source = path.read_text(encoding="utf-8")
        lines = source.splitlines()
        for node in ast.walk(_tree(source)):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                count = _code_lines(lines, node)
                if count > limit:
                    where = f"{path.relative_to(ROOT).as_posix()}:{node.lineno}"
                    offenders.append(f"{where} {node.name}: {count} lines")
    return offenders


def test_no_function_is_longer_than_80_lines_of_code():
    _assert_none(long_functions(), f"functions over {MAX_FUNCTION_LINES} lines of code")


def test_the_length_rule_counts_code_only(tmp_path, monkeypatch):
    """A docstring, blank lines and comments do not count; statements do."""
    pkg = tmp_path / "qc_control"
    pkg.mkdir()
    body = "\n".join(f"    x{i} = {i}" for i in range(3))
    (pkg / "a.py").write_text(
        f'def short():\n    """A docstring\n\n    of lines."""\n\n    # why\n{body}\n'
    )
    monkeypatch.setattr(sys.modules[__name__], "ROOT", tmp_path)
    monkeypatch.setattr(sys.modules[__name__], "PACKAGE", pkg)
    assert long_functions(limit=3) == []
    assert long_functions(limit=2) == ["qc_control/a.py:1 short: 3 lines"]


def test_complexity_is_checked_by_ruff():
    lint = PYPROJECT["tool"]["ruff"]["lint"]
    assert "C901" in lint["select"]
    assert lint["mccabe"]["max-complexity"] == 15
    assert not any("C901" in codes for codes in lint.get("per-file-ignores", {}).values())


@pytest.mark.skipif(shutil.which("duplicates") is None, reason="the duplicates command is absent")
def test_the_package_repeats_no_block():
    """No run of six or more lines, the same or of the same shape, stands
    twice in the package (the developers' ``duplicates`` command)."""
    run = _run(["duplicates", "--repo", "qc_control", "--seconds", "60"], timeout=120)
    first = run.stdout.splitlines()[0] if run.stdout else run.stderr
    assert first.startswith("no duplicates"), run.stdout


# --- the package root --------------------------------------------------------


def test_import_qc_control_loads_none_of_the_heavy_libraries():
    """python-control imports matplotlib.pyplot when it is imported, and scipy
    and pandas take a third of a second each, so the package root loads its
    names lazily (numpy, the one it needs, ~0.1 s); a fresh interpreter shows it."""
    heavy = ("scipy", "control", "matplotlib", "pandas", "numba")
    code = f"import sys, qc_control; print(sorted(m for m in {heavy!r} if m in sys.modules))"
    run = _run([sys.executable, "-c", code], timeout=120)
    assert run.returncode == 0, run.stderr
    assert run.stdout.strip() == "[]"


def test_the_lazy_names_are_the_public_api():
    """The name -> module map, the TYPE_CHECKING imports that type checkers
    read, and ``__all__`` agree, and each name is its module's object."""
    tree = ast.parse((PACKAGE / "__init__.py").read_text(encoding="utf-8"))
    typed: dict[str, str] = {}
    lazy = qc_control._LAZY
    for node, _, typing_only in _imports(tree):
        if typing_only and isinstance(node, ast.ImportFrom):
            for alias in node.names:
                submodule = f"{node.module}.{alias.name}"  # qc_control.ride.road, a module
                name = alias.asname or alias.name
                typed[name] = submodule if lazy.get(name) == submodule else str(node.module)
    assert typed == lazy
    assert set(qc_control.__all__) == set(lazy)
    for name, module_name in lazy.items():
        module = importlib.import_module(f"qc_control.{module_name}")
        expected = getattr(module, name) if hasattr(module, name) else module
        assert getattr(qc_control, name) is expected, name
    # the function, even once its module qc_control.numerics.integrate is imported
    from qc_control.numerics.integrate import integrate

    assert qc_control.integrate is integrate
    with pytest.raises(AttributeError, match="'qc_control' has no attribute 'not_a_name'"):
        qc_control.not_a_name  # noqa: B018


def test_help_starts_with_the_quickstart():
    """``help(qc_control)`` opens with the quickstart (its doctest runs in
    the suite), not with the 1,400 lines of the API."""
    text = pydoc.render_doc(qc_control, renderer=pydoc.plaintext)
    lines = text.splitlines()
    assert "Quickstart" in "\n".join(lines[:8])
    assert "qc.quarter_car(" in "\n".join(lines[:20])


# --- the version, once; the release files -------------------------------------


def test_the_version_is_written_once():
    """pyproject.toml holds the version; the package reads it back from the
    installed distribution, and nothing else in the package spells it."""
    project = PYPROJECT["project"]
    assert "version" not in project.get("dynamic", [])
    version = project["version"]
    assert qc_control.__version__ == importlib.metadata.version("qc-control") == version
    spelled = [
        str(path.relative_to(ROOT))
        for path in PACKAGE.rglob("*.py")
        if re.search(rf"""["']{re.escape(version)}["']""", path.read_text(encoding="utf-8"))
    ]
    assert not spelled


def test_the_changelog_names_this_version_as_the_latest_release():
    text = (ROOT / "CHANGELOG.md").read_text(encoding="utf-8")
    headings = re.findall(r"^## \[([^\]]+)\]", text, re.M)
    assert headings[0] == "Unreleased"
    assert headings[1] == qc_control.__version__


def test_the_license_is_the_one_pyproject_states():
    assert PYPROJECT["project"]["license"] == "MIT"
    text = (ROOT / "LICENSE").read_text(encoding="utf-8")
    assert text.startswith("MIT License")
    assert "Copyright (c) 2026 qc_control developers" in text


def test_pre_commit_runs_the_versions_the_suite_runs():
    """The hooks' pinned revisions are the ruff and mypy installed here."""
    text = (ROOT / ".pre-commit-config.yaml").read_text(encoding="utf-8")
    for repo, tool in (
        ("astral-sh/ruff-pre-commit", "ruff"),
        ("pre-commit/mirrors-mypy", "mypy"),
    ):
        match = re.search(rf"repo: https://github.com/{repo}\s+rev: v?(\S+)", text)
        assert match, f"no {repo} hook"
        assert match.group(1) == importlib.metadata.version(tool), tool

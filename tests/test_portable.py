"""The package on a platform without POSIX-only modules (Windows).

No module of qc_control may import a POSIX-only module at import time: such
an import fails on Windows and takes every ``qc-control`` command with it.
Windows itself is not at hand here, so a subprocess is made to lack those
modules (an import of any of them raises ImportError, as on Windows) and runs
what a user runs: every import of the package, ``qc-control modes`` and a
complete ``qc-control report``.
"""

from __future__ import annotations

import ast
import os
import pkgutil
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

import qc_control
from qc_control.numerics import limits

#: Modules of the standard library that exist on POSIX systems only.
POSIX_ONLY = ("fcntl", "resource", "termios", "pwd", "grp", "tty", "pty", "posix")

#: Those the subprocess goes without: all but ``posix``, which the standard
#: library itself imports on a POSIX system (``os``, ``shutil``), as it imports
#: ``nt`` on Windows.
BLOCKED = tuple(name for name in POSIX_ONLY if name != "posix")

#: Set first in the subprocess: ``sys.modules[name] = None`` makes ``import
#: name`` raise ImportError, as a module Windows lacks does.
_WITHOUT_POSIX = f"""
import sys
for _name in {BLOCKED!r}:
    sys.modules.pop(_name, None)
    sys.modules[_name] = None
"""


def _package_dir() -> Path:
    return Path(qc_control.__file__).parent


def _top_level_imports(tree: ast.Module) -> set[str]:
    """The modules a module imports when it is imported (not inside functions)."""
    found: set[str] = set()
    pending: list[ast.AST] = list(tree.body)
    while pending:
        node = pending.pop()
        if isinstance(node, ast.Import):
            found.update(alias.name.split(".")[0] for alias in node.names)
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            found.add(node.module.split(".")[0])
        elif isinstance(node, (ast.If, ast.Try, ast.With)):
            # the branches of a module-level if/try run at import
            for field in ("body", "orelse", "finalbody", "handlers"):
                pending.extend(getattr(node, field, []))
        elif isinstance(node, ast.ExceptHandler):
            pending.extend(node.body)
        elif isinstance(node, ast.ClassDef):
            pending.extend(node.body)
    return found


def test_no_module_imports_a_posix_only_module_at_import_time():
    """A quick check of the source (the subprocess test below runs it)."""
    offenders = {}
    for path in sorted(_package_dir().rglob("*.py")):
        tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
        bad = sorted(_top_level_imports(tree) & set(POSIX_ONLY))
        if bad:
            offenders[str(path.relative_to(_package_dir()))] = bad
    assert offenders == {}


def test_the_default_memory_limit_is_half_of_what_the_system_reports():
    """psutil's total against POSIX's own count of pages (where there is one).

    Both read the kernel's count of physical pages, so they agree exactly."""
    if not hasattr(os, "sysconf"):
        pytest.skip("os.sysconf is POSIX only")
    total = os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")
    assert limits._physical_memory() == total
    limits._default_limit.cache_clear()
    assert limits._default_limit()[0] == total // 2


def _run_without_posix(script: str, tmp_path: Path) -> subprocess.CompletedProcess:
    env = {**os.environ, "MPLBACKEND": "Agg", "PYTHONIOENCODING": "utf-8"}
    env.pop(limits.ENV_VAR, None)
    return subprocess.run(
        [sys.executable, "-c", _WITHOUT_POSIX + textwrap.dedent(script)],
        cwd=tmp_path,
        env=env,
        capture_output=True,
        text=True,
        timeout=600,
    )


# a fresh interpreter imports everything and writes a whole report (~10 s); 2 s of
# the seed's scenario run every writer, as the default 10 s do, and its figures are
# drawn at 40 dpi (`reports_shared.quick_figures`): the same artists and files
@pytest.mark.slow
def test_every_import_modes_and_a_report_without_posix_only_modules(tmp_path):
    modules = sorted(m.name for m in pkgutil.walk_packages(qc_control.__path__, "qc_control."))
    script = f"""
    import importlib
    for name in {BLOCKED!r}:
        try:
            importlib.import_module(name)
        except ImportError:
            pass
        else:
            raise SystemExit(f"{{name}} could still be imported")
    for name in {modules!r}:
        importlib.import_module(name)
    print("imported", {len(modules)})
    from qc_control.report import writer
    writer.DPI = 40
    from qc_control.cli.console import main
    code = main(["modes"])
    print("modes exit", code)
    code = main(["report", "--quiet", "--t-end", "2", "--out", "rep"])
    print("report exit", code)
    """
    run = _run_without_posix(script, tmp_path)
    assert run.returncode == 0, run.stderr[-3000:]
    assert f"imported {len(modules)}" in run.stdout
    assert "modes exit 0" in run.stdout and "report exit 0" in run.stdout
    # the modal table: one row per mode of the quarter car (body and wheel hop)
    assert "body" in run.stdout.lower() and "wheel" in run.stdout.lower()
    report = tmp_path / "rep"
    for name in ("report.md", "report.html", "report.pdf", "methods.csv", "scenario.toml"):
        assert (report / name).stat().st_size > 0, name
    # the PNGs the Markdown links to are all there
    text = (report / "report.md").read_text(encoding="utf-8")
    linked = {line.split("](")[1].split(")")[0] for line in text.splitlines() if "![" in line}
    assert linked and all((report / name).exists() for name in linked)
    # nothing left beside the report: no working copy, no lock file
    assert [p.name for p in tmp_path.iterdir()] == ["rep"]


def test_install_hints_work_in_cmd_exe():
    """Issue 39 item 11: cmd.exe passes single quotes on, so ``pip install
    'qc-control[robust]'`` fails there; every hint the package, README and
    guide give uses double quotes, which cmd.exe, PowerShell and POSIX shells
    all take."""
    root = Path(qc_control.__file__).parents[1]
    texts = [*Path(qc_control.__file__).parent.rglob("*.py"), root / "README.md"]
    texts += [*(root / "docs").rglob("*.md"), *(root / "docs").rglob("*.rst")]
    single = [
        f"{p.relative_to(root)}:{i}"
        for p in texts
        for i, line in enumerate(p.read_text(encoding="utf-8").splitlines(), 1)
        if "pip install '" in line or "pip install -e '" in line
    ]
    assert not single, single

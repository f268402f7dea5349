"""The wheel installs alone: built with ``python -m build``, installed into a
fresh virtual environment outside the repository, it gives a working
package and command line.

``python -m build`` makes the sdist and then the wheel from the unpacked
sdist, so a file missing from the sdist fails here too. The sources are
copied first, so that setuptools' ``build/`` and ``*.egg-info`` land in the
test's own folder, not in the work tree other tests read. The fresh
environment gets the wheel and its declared dependencies from the package
index, by uv or pip (nothing of the repository's environment), and
every command runs from a folder outside the repository with no
``PYTHONPATH``: a module or a dependency the wheel does not carry or declare
fails the import. The numbers are checked against references computed here:
python-control's exact response and the eigenvalues of ``A`` assembled from
M, C, K.

The fresh environment's dependencies are the very files of this one (uv links
them from its cache), so the bytecode this environment has already compiled for
them is linked beside them (`seed_bytecode`): Python accepts a cached file only
where its source sits beside it with the size and time recorded in it, so
nothing becomes importable that the wheel and its dependencies do not install,
and qc_control itself is compiled from the wheel's own files.
"""

from __future__ import annotations

import importlib.util
import json
import os
import shutil
import subprocess
import sys
import sysconfig
import zipfile
from pathlib import Path

import control
import numpy as np
import pytest

ROOT = Path(__file__).parent.parent
#: what the sdist is made from (setuptools finds the rest by pyproject.toml)
SOURCES = ("pyproject.toml", "README.md", "LICENSE", "qc_control", "tests")

pytestmark = [pytest.mark.slow, pytest.mark.xdist_group("wheel")]


def run(*cmd, cwd: Path, timeout: float = 600) -> str:
    """Run ``cmd`` without the repository on the path; its stdout (exit 0 asserted).

    The fresh environment writes its bytecode (conftest.py clears
    PYTHONDONTWRITEBYTECODE for every process the suite starts): neither uv nor
    pip byte-compiles its dependencies, and the first command that imports a
    module compiles it for the next ones (this file alone: 42 s of CPU when each
    command compiled numpy, scipy, control and matplotlib afresh, 29 s without).
    What this environment has compiled already is not compiled again
    (`seed_bytecode`).
    """
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "VIRTUAL_ENV")}
    env["MPLBACKEND"] = "Agg"
    out = subprocess.run(
        [str(c) for c in cmd], cwd=cwd, env=env, capture_output=True, text=True, timeout=timeout
    )
    assert out.returncode == 0, f"{cmd}\n{out.stdout[-3000:]}\n{out.stderr[-3000:]}"
    return out.stdout


def venv_python(venv: Path) -> Path:
    """The interpreter of a virtual environment, on POSIX and on Windows."""
    posix, windows = venv / "bin" / "python", venv / "Scripts" / "python.exe"
    return windows if windows.exists() else posix


def venv_script(venv: Path, name: str) -> Path:
    """A console script of a virtual environment, on POSIX and on Windows."""
    windows = venv / "Scripts" / f"{name}.exe"
    return windows if windows.exists() else venv / "bin" / name


def seed_bytecode(env: Path) -> None:
    """Link this environment's bytecode of the dependencies into the fresh one.

    A cached ``__pycache__/m.cpython-3XY.pyc`` is used by Python only for the
    source ``m.py`` beside it, and only while that source has the size and
    modification time recorded in the cache (else Python compiles it anew). A
    file is linked (copied where it cannot be) only where the fresh
    environment's source has this environment's size and time: the same file,
    linked by uv from its cache (on platforms where uv copies instead, nothing
    matches and the commands compile as before). Compiling numpy, scipy,
    control and matplotlib on first import was 4 of the 6.5 s of CPU that
    ``qc-control modes`` took in the fresh environment. qc_control's own files
    are never linked: the wheel's copies are compiled from the wheel.
    """
    here = Path(sysconfig.get_paths()["purelib"])
    there = Path(sysconfig.get_path("purelib", vars={"base": str(env), "platbase": str(env)}))
    # this interpreter's own caches (not pytest's rewritten test modules, nor -O's)
    for cached in here.glob(f"**/__pycache__/*.{sys.implementation.cache_tag}.pyc"):
        source = Path(importlib.util.source_from_cache(str(cached)))
        twin = there / source.relative_to(here)
        if twin.parts[len(there.parts)].startswith("qc_control"):
            continue
        try:
            ours, theirs = source.stat(), twin.stat()
        except OSError:  # not a dependency of the wheel, or a cache without its source
            continue
        if (ours.st_size, ours.st_mtime_ns) != (theirs.st_size, theirs.st_mtime_ns):
            continue
        target = twin.parent / "__pycache__" / cached.name
        target.parent.mkdir(exist_ok=True)
        try:
            os.link(cached, target)
        except OSError:  # another file system, or no hard links
            shutil.copy2(cached, target)


@pytest.fixture(scope="module")
def dist(tmp_path_factory) -> Path:
    """The sdist and the wheel, built from a copy of the sources."""
    src = tmp_path_factory.mktemp("src")
    ignore = shutil.ignore_patterns("__pycache__", "*.egg-info", "*_output")
    for name in SOURCES:
        path = ROOT / name
        if path.is_dir():
            shutil.copytree(path, src / name, ignore=ignore)
        else:
            shutil.copy2(path, src / name)
    out = tmp_path_factory.mktemp("dist")
    # --no-isolation: the build backend is the test extra's setuptools, not one
    # installed twice more (sdist, wheel) into throw-away environments
    run(sys.executable, "-m", "build", "--no-isolation", "--outdir", out, src, cwd=src)
    return out


@pytest.fixture(scope="module")
def venv(dist, tmp_path_factory) -> Path:
    """A fresh environment holding the wheel and what it declares, nothing else.

    Made without pip of its own (``ensurepip`` costs as much as the rest). The
    wheel and its dependencies go in by uv where it is installed (`make`
    installs it: it takes the packages from its cache of the suite's own
    install, about a quarter of pip's time), else by this interpreter's pip
    through ``--python``; neither byte-compiles the ~600 MB of dependencies
    (pip by ``--no-compile``): Python compiles what it imports anyway, where
    this environment has not already (`seed_bytecode`).
    """
    env = tmp_path_factory.mktemp("fresh") / "venv"
    run(sys.executable, "-m", "venv", "--without-pip", env, cwd=env.parent)
    (wheel,) = dist.glob("qc_control-*.whl")
    python = venv_python(env)
    if importlib.util.find_spec("uv") is not None:
        install = [sys.executable, "-m", "uv", "pip", "install", "--python", python, "-q"]
    else:
        install = [sys.executable, "-m", "pip", "--python", python, "install", "-q", "--no-compile"]
    run(*install, wheel, cwd=env.parent)
    seed_bytecode(env)
    return env


#: One process of the fresh environment's interpreter: where qc_control is
#: imported from, and a response computed by it (`installed`).
INSTALLED_RUN = (
    "import json, qc_control as qc\n"
    "T = [0.001 * k for k in range(2001)]\n"
    "r = qc.initial_response(qc.quarter_car(), T, [0, 0, 0.05, 0], method='rk4')\n"
    "print(json.dumps({'file': qc.__file__, 'y': r.outputs.tolist(),"
    " 'labels': list(r.output_labels)}))\n"
)


@pytest.fixture(scope="module")
def installed(venv, tmp_path_factory) -> dict:
    """What `INSTALLED_RUN` prints, run from a folder outside the repository."""
    cwd = tmp_path_factory.mktemp("outside")
    return json.loads(run(venv_python(venv), "-c", INSTALLED_RUN, cwd=cwd))


def test_build_makes_a_wheel_and_an_sdist_that_twine_accepts(dist):
    (wheel,) = dist.glob("qc_control-*-py3-none-any.whl")
    (sdist,) = dist.glob("qc_control-*.tar.gz")
    with zipfile.ZipFile(wheel) as zf:
        names = set(zf.namelist())
        (entry_points,) = (n for n in names if n.endswith(".dist-info/entry_points.txt"))
        scripts = zf.read(entry_points).decode()
    # PEP 561: the marker ships, so users' type checkers read the annotations
    assert "qc_control/py.typed" in names
    assert "qc-control = qc_control.cli.console:main" in scripts
    assert not any(n.startswith(("tests/", "docs/", "examples/")) for n in names)
    run(sys.executable, "-m", "twine", "check", "--strict", wheel, sdist, cwd=dist)


def test_the_installed_package_comes_from_the_wheel(venv, installed):
    package = Path(installed["file"]).resolve()
    assert package.is_relative_to(venv.resolve()), package  # not the work tree
    assert (package.parent / "py.typed").exists()


def test_qc_control_modes_prints_the_seed_cars_modes(venv, tmp_path):
    out = run(venv_script(venv, "qc-control"), "modes", cwd=tmp_path)
    # the seed's car (Table 1): A from M, C, K here; cs = 2ζ√(ks·ms), ζ = 0.25
    ms, mu, ks, ku = 301.2, 100.0, 30000.0, 29530.0
    cs = 2 * 0.25 * np.sqrt(ks * ms)
    Minv = np.diag([1 / ms, 1 / mu])
    C = np.array([[cs, -cs], [-cs, cs]])
    K = np.array([[ks, -ks], [-ks, ks + ku]])
    A = np.block([[-Minv @ C, -Minv @ K], [np.eye(2), np.zeros((2, 2))]])
    lam = np.linalg.eigvals(A)
    body, wheel = sorted(lam[lam.imag > 0], key=abs)
    for mode, pole in (("body bounce", body), ("wheel hop", wheel)):
        line = next(row for row in out.splitlines() if row.startswith(mode))
        fn = float(line.split()[4])  # eigenvalue, ωn, fn: the table prints fn to 4 digits
        assert fn == pytest.approx(abs(pole) / (2 * np.pi), rel=5e-4), line


def test_qc_control_report_writes_the_report(venv, tmp_path):
    """Every writer (HTML, Markdown, PDF, CSV, figures) from the installed
    package; 2 s of the seed's scenario keep the computing short."""
    run(venv_script(venv, "qc-control"), "report", "--t-end", "2", "--out", "rep", "--quiet",
        cwd=tmp_path)  # fmt: skip
    report = tmp_path / "rep"
    for name in ("report.html", "report.md", "report.pdf", "methods.csv"):
        assert (report / name).stat().st_size > 0, name
    assert (report / "report.pdf").read_bytes()[:5] == b"%PDF-"


def test_initial_response_from_the_installed_package(installed):
    got = installed
    y = np.asarray(got["y"])
    # the exact response of the same car, by python-control here (this environment)
    import qc_control as qc

    sys_ = qc.quarter_car()
    assert got["labels"] == list(sys_.output_labels)
    T = np.linspace(0.0, 2.0, 2001)
    exact = control.initial_response(sys_, T, [0, 0, 0.05, 0]).outputs
    # RK4 at h = 1 ms: h·|λ|max = 0.025, local error (h|λ|)⁵/120 ≈ 8e-11 of the
    # mode per step, under 2e-7 of the 5 cm release after 2000 steps
    np.testing.assert_allclose(y, exact, rtol=0, atol=1e-6 * np.max(np.abs(exact)))

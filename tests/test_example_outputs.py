"""The examples take their output folder from an argument, never blindly from
``sys.argv[1]``: in a Jupyter kernel (the gallery's downloadable notebooks)
argv is ``ipykernel_launcher.py -f kernel.json``, and the examples wrote
into a folder named ``-f``."""

import re
from pathlib import Path

import pytest

from qc_control.report.outputs import in_notebook, output_folder

EXAMPLES = sorted((Path(__file__).parent.parent / "examples").glob("*.py"))
KERNEL_ARGV = ["/venv/lib/python3/site-packages/ipykernel_launcher.py", "-f", "/run/kernel-1.json"]


def test_a_kernels_arguments_are_not_a_folder(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert in_notebook(KERNEL_ARGV)
    folder = output_folder("four_methods", argv=KERNEL_ARGV)
    assert folder == Path("four_methods_output") and folder.is_dir()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["four_methods_output"]  # no "-f"


def test_a_scripts_only_argument_is_its_folder_and_parents_are_made(tmp_path):
    target = tmp_path / "a" / "b"
    assert output_folder("x", argv=["x.py", str(target)]) == target and target.is_dir()


def test_an_explicit_folder_wins_over_the_command_line(tmp_path):
    chosen = tmp_path / "chosen"
    assert output_folder("x", out=chosen, argv=["x.py", str(tmp_path / "other")]) == chosen
    assert not (tmp_path / "other").exists()


def test_a_script_given_an_unknown_option_says_so(tmp_path, capsys):
    with pytest.raises(SystemExit):
        output_folder("x", argv=["x.py", "--nonsense", str(tmp_path)])
    assert "unrecognized arguments: --nonsense" in capsys.readouterr().err


def test_a_name_that_is_not_a_string_is_refused():
    with pytest.raises(TypeError, match="non-empty string"):
        output_folder(None)


@pytest.mark.parametrize("path", EXAMPLES, ids=[p.stem for p in EXAMPLES])
def test_no_example_reads_argv_itself(path):
    text = path.read_text(encoding="utf-8")
    assert not re.search(r"sys\.argv", text)
    assert f'output_folder("{path.stem}")' in text


@pytest.mark.slow
def test_an_example_run_in_a_kernel_writes_its_default_folder(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    monkeypatch.setattr("sys.argv", KERNEL_ARGV)
    script = next(p for p in EXAMPLES if p.stem == "modal_analysis")
    # run as a kernel runs a notebook's cells: argv stays the kernel's
    # (runpy would set argv[0] to the script)
    exec(compile(script.read_text(encoding="utf-8"), str(script), "exec"), {"__name__": "__main__"})
    assert [p.name for p in tmp_path.iterdir()] == ["modal_analysis_output"]
    assert any(p.suffix == ".png" for p in (tmp_path / "modal_analysis_output").iterdir())


def test_show_inline_publishes_a_figure_in_a_kernel_and_is_silent_elsewhere(monkeypatch):
    import sys
    from types import SimpleNamespace

    from qc_control.report.outputs import show_inline

    published = []
    shell = SimpleNamespace(
        display_formatter=SimpleNamespace(format=lambda obj: ({"image/png": b"png"}, {})),
        display_pub=SimpleNamespace(publish=lambda data, metadata: published.append(data)),
    )
    monkeypatch.setitem(sys.modules, "IPython", SimpleNamespace(get_ipython=lambda: None))
    show_inline(object())
    assert published == []  # IPython imported, but no kernel: nothing shown
    monkeypatch.setitem(sys.modules, "IPython", SimpleNamespace(get_ipython=lambda: shell))
    show_inline(object())
    assert published == [{"image/png": b"png"}]


def test_save_and_show_writes_the_png_it_names_and_shows_it_in_a_kernel(tmp_path, monkeypatch):
    import sys
    from types import SimpleNamespace

    from matplotlib.figure import Figure

    from qc_control.report.outputs import save_and_show

    shown = []
    shell = SimpleNamespace(
        display_formatter=SimpleNamespace(format=lambda obj: (obj, {})),
        display_pub=SimpleNamespace(publish=lambda data, metadata: shown.append(data)),
    )
    monkeypatch.setitem(sys.modules, "IPython", SimpleNamespace(get_ipython=lambda: shell))
    fig = Figure(figsize=(2, 1))
    path = save_and_show(fig, tmp_path / "a.png", dpi=50)
    assert path == tmp_path / "a.png"
    # a PNG's signature, and 2 x 1 inches at 50 dpi: the size the call asked for
    data = path.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    assert int.from_bytes(data[16:20], "big") == 100 and int.from_bytes(data[20:24], "big") == 50
    assert shown == [fig]

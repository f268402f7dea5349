"""A Ctrl-C swallowed by a ``__del__`` or weakref callback still stops the report.

Python prints "Exception ignored in: ..." for a KeyboardInterrupt raised in
such a callback and carries on; matplotlib's figure teardown has both. The
run must still stop before it replaces the earlier report.
"""

import signal

import pytest

from qc_control.report import MARKER, Paragraph, write_document


class _SwallowedInterrupt:
    """An object whose finaliser receives the Ctrl-C, as a figure's teardown can."""

    def __del__(self):
        # what Python does on SIGINT: the current handler runs in this frame
        signal.getsignal(signal.SIGINT)(signal.SIGINT, None)


def _blocks_with_a_swallowed_interrupt():
    _SwallowedInterrupt()  # finalised at once: the interrupt is printed and lost
    return [Paragraph("new report")]


@pytest.fixture
def ctrl_c_raises():
    """Ctrl-C raises KeyboardInterrupt in this process, as in a terminal.

    A process started in the background by a shell without job control (``nohup``,
    ``cmd &`` in a script) inherits SIGINT ignored; the report then leaves it to
    the OS, and the interrupt this test delivers by hand would never be raised.
    """
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    yield
    signal.signal(signal.SIGINT, previous)


@pytest.mark.filterwarnings("ignore::pytest.PytestUnraisableExceptionWarning")
@pytest.mark.usefixtures("ctrl_c_raises")
def test_a_swallowed_ctrl_c_keeps_the_earlier_report(tmp_path):
    out = tmp_path / "rep"
    write_document(out, "Earlier", lambda: [Paragraph("earlier report")], formats=("md",))
    before = (out / "report.md").read_text(encoding="utf-8")
    with pytest.raises(KeyboardInterrupt):
        write_document(out, "Later", _blocks_with_a_swallowed_interrupt, formats=("md",))
    assert (out / "report.md").read_text(encoding="utf-8") == before
    assert (out / MARKER).exists()
    assert sorted(p.name for p in tmp_path.iterdir() if p.name.startswith(".rep.")) in (
        [],
        [".rep.lock"],
    )


def test_the_interrupt_handler_is_restored_and_a_clean_run_writes(tmp_path):
    handler = signal.getsignal(signal.SIGINT)
    out = write_document(tmp_path / "rep", "Clean", lambda: [Paragraph("x")], formats=("md",))
    assert signal.getsignal(signal.SIGINT) is handler
    assert "x" in (out / "report.md").read_text(encoding="utf-8")


@pytest.mark.filterwarnings("ignore::pytest.PytestUnraisableExceptionWarning")
@pytest.mark.usefixtures("ctrl_c_raises")  # which also puts the handler back afterwards
def test_a_report_after_a_swallowed_ctrl_c_writes_where_ctrl_c_is_ignored(tmp_path):
    """The interrupt an earlier report saw is that report's: a later one, in a
    process where Ctrl-C is ignored (a background job), writes as asked."""
    with pytest.raises(KeyboardInterrupt):
        write_document(
            tmp_path / "first", "First", _blocks_with_a_swallowed_interrupt, formats=("md",)
        )
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    out = write_document(tmp_path / "second", "Second", lambda: [Paragraph("y")], formats=("md",))
    assert "y" in (out / "report.md").read_text(encoding="utf-8")

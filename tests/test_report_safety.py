"""The report writer under faults: one complete report afterwards, no litter,
nothing of the user's lost (issue 14 items 15-19)."""

import os
import shutil
import subprocess
import sys
import threading
from pathlib import Path

import filelock
import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from reports_shared import use_placeholders

import qc_control as qc
from qc_control import report as rep
from qc_control.report import MARKER, ReportError, comparison, transaction, write_report, writer

pytestmark = pytest.mark.slow  # each case writes whole reports (every file, the PDF)


@pytest.fixture(autouse=True)
def _placeholder_figures(monkeypatch):
    """What is checked here is the writing, not the pictures: each figure is a
    blank one under its own name (tests/reports_shared.py), so that a report
    still has every file, and writes in a fraction of the time."""
    use_placeholders(monkeypatch)


@pytest.fixture(scope="module")
def cmp():
    return qc.compare_methods(qc.QuarterCarParams(), np.linspace(0, 1, 101), repeats=1)


def marker_command(out: Path) -> str:
    return (out / MARKER).read_text(encoding="utf-8").splitlines()[1]


def litter(parent: Path, name: str) -> list[str]:
    return sorted(p.name for p in parent.iterdir() if p.name.startswith(f".{name}."))


def test_stale_partials_of_a_killed_run_are_cleaned(cmp, tmp_path):
    """Item 15: a SIGKILL while writing leaves .R.partial-*; the next run removes it."""
    stale = tmp_path / ".R.partial-abc123"
    stale.mkdir()
    (stale / "report.md").write_text("half")
    write_report(cmp, tmp_path / "R", ("md",), command="second")
    assert litter(tmp_path, "R") == [] and marker_command(tmp_path / "R") == "second"


def test_a_report_stranded_between_the_renames_is_never_lost(cmp, tmp_path):
    """Item 16: killed between the two renames, R is missing and the old report
    sits in .R.old-*/R. The next run puts it back before anything else."""
    out = tmp_path / "R"
    write_report(cmp, out, ("md",), command="first")
    aside = tmp_path / ".R.old-xyz"
    aside.mkdir()
    out.rename(aside / "R")
    transaction._recover(out)  # what every run does first, under the lock
    assert marker_command(out) == "first" and litter(tmp_path, "R") == []


@pytest.mark.parametrize(
    ("stage", "fault"),
    [
        ("figure", OSError),
        ("pdf", KeyboardInterrupt),
        ("csv", OSError),
        ("swap", KeyboardInterrupt),
        ("swap", OSError),
        ("cleanup", KeyboardInterrupt),
    ],
)
def test_a_fault_at_any_stage_leaves_one_complete_report(cmp, tmp_path, monkeypatch, stage, fault):
    """Fault injection: raise at each stage of a replacing write. Afterwards R is
    the old report or the new one, complete (its marker lists every file it has),
    and the next run leaves exactly one report and no litter."""
    out = tmp_path / "R"
    # the PDF is the slowest part: written only where it is the stage under test
    fmts = rep.FORMATS if stage == "pdf" else tuple(f for f in rep.FORMATS if f != "pdf")
    write_report(cmp, out, fmts, command="old")

    def boom(*args, **kwargs):
        raise fault("injected")

    if stage == "figure":
        spec = rep.FigureSpec("broken.png", "Figure 1", "a figure that fails", boom)
        monkeypatch.setattr(comparison, "figure_specs", lambda cmp: [spec])
    elif stage == "pdf":
        monkeypatch.setattr(writer, "to_pdf", boom)
    elif stage == "csv":
        monkeypatch.setattr(comparison, "_csv_tables", boom)
    elif stage == "swap":  # between the two renames: the old report is aside
        real = Path.rename
        calls = []

        def second_fails(self, target):
            calls.append(target)
            if len(calls) == 2:
                raise fault("injected")
            return real(self, target)

        monkeypatch.setattr(Path, "rename", second_fails)
    else:  # removing the set-aside old report, after the swap
        monkeypatch.setattr(transaction.shutil, "rmtree", boom)
    with pytest.raises(fault):
        write_report(cmp, out, fmts, command="new")
    monkeypatch.undo()
    use_placeholders(monkeypatch)

    assert out.is_dir()
    files = {p.name for p in out.iterdir()} - {MARKER}
    listed = set((out / MARKER).read_text().split("files:\n")[1].split())
    assert files == listed and "report.md" in files
    expected = "new" if stage == "cleanup" else "old"
    assert marker_command(out) == expected
    # the next run, whose PDF stage is not under test (a PDF is 1.2 CPU-s of it)
    write_report(cmp, out, ("md", "html", "csv"), command="after")
    assert marker_command(out) == "after" and litter(tmp_path, "R") == []
    assert [p.name for p in tmp_path.iterdir()] == ["R"]


def test_a_second_run_into_the_same_place_stops_with_one_line(cmp, tmp_path):
    """Item 17: a run holding the lock makes another stop cleanly (not ENOTEMPTY).

    The other run is this test holding the report's lock file as a run does
    (filelock's locks exclude each other within one process too)."""
    held = filelock.FileLock(transaction._lock_file(tmp_path / "R"), timeout=0)
    with held:
        with pytest.raises(ReportError, match="another qc-control run is writing a report"):
            write_report(cmp, tmp_path / "R", ("md",))
        assert not (tmp_path / "R").exists()
    write_report(cmp, tmp_path / "R", ("md",))  # the lock is free again
    assert (tmp_path / "R" / "report.md").exists()
    assert [p.name for p in tmp_path.iterdir()] == ["R"]  # no lock file left behind


def test_a_writer_in_another_process_holds_off_a_second(cmp, tmp_path):
    """Two processes: one holds the report's lock as a run does while it
    swaps; the other's write_report stops with the one line, and succeeds
    once the first is done."""
    script = (
        "import sys, time\n"
        "from pathlib import Path\n"
        "from qc_control.report import transaction\n"
        "out = Path(sys.argv[1])\n"
        "with transaction._exclusive(out):\n"
        "    print('held', flush=True)\n"
        "    sys.stdin.readline()\n"
    )
    out = tmp_path / "R"
    holder = subprocess.Popen(
        [sys.executable, "-c", script, str(out)],
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        text=True,
    )
    try:
        assert holder.stdout is not None and holder.stdout.readline().strip() == "held"
        with pytest.raises(ReportError, match="another qc-control run is writing a report"):
            write_report(cmp, out, ("md",))
    finally:
        holder.communicate("done\n", timeout=60)
    assert holder.returncode == 0
    write_report(cmp, out, ("md",))
    assert (out / "report.md").exists() and [p.name for p in tmp_path.iterdir()] == ["R"]


def test_a_lock_file_left_by_a_killed_run_is_taken_and_removed(cmp, tmp_path):
    """A run killed while holding the lock leaves its lock file, unlocked (the
    system drops the lock with the process): the next run goes ahead."""
    transaction._lock_file(tmp_path / "R").write_text("")
    write_report(cmp, tmp_path / "R", ("md",))
    assert [p.name for p in tmp_path.iterdir()] == ["R"]


def test_the_report_directory_follows_the_umask(cmp, tmp_path):
    """Item 19: an empty user directory of mode 755 stays 755 (mkdtemp makes 0700)."""
    out = tmp_path / "R"
    out.mkdir(mode=0o755)
    old = os.umask(0o022)
    try:
        write_report(cmp, out, ("md",))
    finally:
        os.umask(old)
    assert (out.stat().st_mode & 0o777) == 0o755


def test_a_user_file_in_a_report_is_kept(cmp, tmp_path):
    """Item 18, through the command line: refused in one line, the file kept."""
    out = tmp_path / "R"
    write_report(cmp, out, ("md",))
    (out / "my notes.txt").write_text("keep me")
    with pytest.raises(ReportError, match="'my notes.txt', which qc-control did not write"):
        write_report(cmp, out, ("md",))
    assert (out / "my notes.txt").read_text() == "keep me"
    shutil.rmtree(out)


def test_a_run_holding_its_lock_writes_under_it_and_others_are_refused(cmp, tmp_path):
    """Issue 28 item 9: a command holds its report's lock from before computing
    (report_lock); its own write goes ahead under it, while a writer in another
    thread, like one in another process, is refused; nothing is left afterwards."""
    out = tmp_path / "R"
    refused = []

    def other_thread():
        try:
            write_report(cmp, out, ("md",))
        except ReportError as exc:
            refused.append(str(exc))

    with rep.report_lock(out) as held:
        assert held == out.resolve() and transaction._lock_file(held).exists()
        worker = threading.Thread(target=other_thread)
        worker.start()
        worker.join()
        assert len(refused) == 1 and "another qc-control run is writing a report" in refused[0]
        write_report(cmp, out, ("md",), command="mine")  # re-entrant in its own thread
    assert marker_command(out) == "mine"
    assert [p.name for p in tmp_path.iterdir()] == ["R"]  # no lock file left behind


def test_a_marker_without_its_file_list_keeps_the_users_files(cmp, tmp_path):
    """Issue 39 item 1: an older qc-control's marker lists no files, so which
    files are the report's cannot be proved; the run refuses and deletes nothing."""
    legacy = tmp_path / "legacy"
    legacy.mkdir()
    (legacy / MARKER).write_text("qc-control report\n")
    (legacy / "thesis_notes.txt").write_text("notes")
    with pytest.raises(ReportError, match=r"legacy.*does not list the files"):
        write_report(cmp, legacy, ("md",))
    assert sorted(p.name for p in legacy.iterdir()) == [MARKER, "thesis_notes.txt"]
    assert (legacy / "thesis_notes.txt").read_text() == "notes"


def test_a_folder_name_with_glob_characters_touches_no_other_report(cmp, tmp_path):
    """Issue 39 item 2: the recovery of 'r*' globbed '.r*.old-*' unescaped, and
    deleted the only copy of the report 'report', moved aside by a killed swap."""
    write_report(cmp, tmp_path / "report", ("md",), command="first")
    stranded = tmp_path / ".report.old-x"
    stranded.mkdir()
    (tmp_path / "report").rename(stranded / "report")
    partial = tmp_path / ".report.partial-y"  # another run's working copy
    partial.mkdir()
    write_report(cmp, tmp_path / "r*", ("md",), command="second")
    assert marker_command(stranded / "report") == "first"
    assert partial.is_dir()
    assert marker_command(tmp_path / "r*") == "second"


@pytest.mark.parametrize("out", ["", "  "])
def test_an_empty_report_folder_is_refused(cmp, tmp_path, monkeypatch, out):
    """``--out ''`` wrote the report's files into the working directory."""
    monkeypatch.chdir(tmp_path)
    with pytest.raises(ReportError, match=r"--out\) is empty"):
        write_report(cmp, out, ("md",))
    assert list(tmp_path.iterdir()) == []


@pytest.mark.skipif(sys.platform == "win32", reason="Windows cannot remove a process's cwd")
def test_a_removed_working_directory_is_a_clear_refusal(cmp, tmp_path, monkeypatch):
    gone = tmp_path / "gone"
    gone.mkdir()
    monkeypatch.chdir(gone)
    gone.rmdir()
    with pytest.raises(ReportError, match="working directory no longer exists"):
        write_report(cmp, "report", ("md",))


_names = st.text(alphabet="abcxyz*?[]._- 0123", min_size=1, max_size=12).filter(
    lambda n: n.strip(" .") == n and n not in {MARKER, "."} and not n.startswith(".qc")
)


@settings(
    max_examples=12, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(
    user_files=st.dictionaries(_names, st.binary(max_size=64), min_size=1, max_size=4),
    marker=st.sampled_from(["none", "no list", "listed report", "lists nothing"]),
    name=st.sampled_from(["R", "r*", "[R]", "R?"]),
)
def test_whatever_a_user_put_in_the_folder_is_kept_byte_for_byte(
    cmp, tmp_path_factory, user_files, marker, name
):
    """Issue 39: a run into a folder holding files the user put there, with an
    earlier report's marker of any kind or none, completes or refuses, and
    leaves each of those files as it was."""
    parent = tmp_path_factory.mktemp("folders")
    out = parent / name
    out.mkdir()
    for file, data in user_files.items():
        (out / file).write_bytes(data)
    marker_text = {
        "none": None,
        "no list": "qc-control report\n",
        "listed report": "qc-control report\n\nfiles:\nreport.md\n",
        "lists nothing": "qc-control report\n\nfiles:\n",
    }[marker]
    if marker_text is not None:
        (out / MARKER).write_text(marker_text)
    try:
        write_report(cmp, out, ("md",))
    except ReportError:
        pass
    for file, data in user_files.items():
        assert (out / file).read_bytes() == data, file

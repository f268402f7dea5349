"""The report's file transaction: a folder replaced whole, under a lock, safe from Ctrl-C.

A report is built in a working copy beside its target (``.NAME.partial-*``)
and swapped in by two renames; the earlier report waits aside
(``.NAME.old-*``) until the new one is in place. A lock file beside the
target (``.NAME.lock``) keeps a second run out, and an interrupted run's
leftovers are finished by the next one (`_recover`). An existing folder is
replaced only if it is an earlier report holding nothing foreign
(`check_target`).
"""

from __future__ import annotations

import contextlib
import glob
import os
import shutil
import signal
import tempfile
import threading
from collections.abc import Callable
from pathlib import Path

import filelock

__all__ = [
    "MARKER", "ReportError", "check_target", "report_lock", "replace_folder", "report_path"
]  # fmt: skip

#: A file that marks a directory as a qc-control report (safe to replace).
MARKER = ".qc-control-report"


class ReportError(ValueError):
    """The report cannot be written where it was asked to go."""


def _manifest(out: Path) -> set[str] | None:
    """The files an earlier report says it wrote (None for a report without a list)."""
    try:
        lines = (out / MARKER).read_text(encoding="utf-8", errors="replace").splitlines()
    except OSError as exc:
        raise ReportError(
            f"refusing to replace the report in {str(out)!r}: its {MARKER} cannot be read "
            f"({exc.strerror or exc})"
        ) from None
    if "files:" not in lines:
        return None
    return set(lines[lines.index("files:") + 1 :])


def report_path(out_dir) -> Path:
    """``out_dir`` as an absolute path; `ReportError` for an empty name (which
    would put the report's files in the working directory) or a relative one
    from a working directory that was removed."""
    if not str(out_dir).strip():
        raise ReportError("the report folder (--out) is empty: name a folder, e.g. --out report")
    try:
        return Path(out_dir).resolve()
    except OSError as exc:
        raise ReportError(
            f"cannot place the report folder {str(out_dir)!r}: the working directory no "
            f"longer exists ({exc.strerror or exc}); cd to a folder that does"
        ) from None


def check_target(out_dir, overwrite: bool = True) -> Path:
    """Where a report may go: a new or empty directory, or an earlier report.

    An earlier report is replaced only if it holds nothing but what
    qc-control wrote there (its `MARKER` lists the files): a file a user put
    inside it is never deleted. Raises `ReportError` naming the path, or the
    first foreign file.
    """
    out = report_path(out_dir)
    if out.exists():
        if not out.is_dir():
            raise ReportError(f"{str(out)!r} exists and is not a directory")
        if any(out.iterdir()):
            if not (out / MARKER).exists():
                raise ReportError(
                    f"refusing to overwrite {str(out)!r}: it is not a qc-control "
                    f"report (no {MARKER} file); choose another --out"
                )
            if not overwrite:
                raise ReportError(f"{str(out)!r} already holds a report")
            listed = _manifest(out)
            if listed is None:
                # a marker from before the files were listed: which of the files are
                # the report's cannot be proved, so none is removed
                raise ReportError(
                    f"refusing to replace the report in {str(out)!r}: its {MARKER} does not "
                    "list the files qc-control wrote (an older qc-control's), so a file of "
                    "yours cannot be told from the report's; move what you keep, or choose "
                    "another --out"
                )
            foreign = sorted(p.name for p in out.iterdir() if p.name not in listed | {MARKER})
            if foreign:
                raise ReportError(
                    f"refusing to replace the report in {str(out)!r}: it holds "
                    f"{foreign[0]!r}, which qc-control did not write; move it out first"
                )
    return out


def _lock_file(out: Path) -> Path:
    """The lock file beside the report directory ``out`` (see `write_document`)."""
    return out.parent / f".{out.name}.lock"


@contextlib.contextmanager
def _exclusive(out: Path):
    """Take the report's lock (`_lock_file`) for `report_lock`, or stop with one line.

    A second run into the same place stops with one clear line instead of
    racing. The lock file is removed while the lock is still held, so nothing
    is left behind: a run that opened the old file before the removal is
    refused its lock (filelock checks that the file it locked still has a
    name), and one that comes later locks a new file. Where a file cannot be
    removed while open (Windows), filelock removes it on release. A killed
    run leaves the file, unlocked: the next run takes it and removes it.
    """
    lock = filelock.FileLock(_lock_file(out), timeout=0)
    try:
        lock.acquire()
    except filelock.Timeout:
        raise ReportError(
            f"another qc-control run is writing a report into {str(out)!r}; wait for it "
            "to finish, or choose another --out"
        ) from None
    try:
        yield
    finally:
        with contextlib.suppress(OSError):
            _lock_file(out).unlink()
        lock.release()


#: The report locks this process holds, as (report directory, thread): a command takes
#: its report's lock before computing (`report_lock`), and the writer then runs under it.
_HELD: set[tuple[Path, int]] = set()


@contextlib.contextmanager
def report_lock(out_dir):
    """Hold the lock of the report ``out_dir`` (`_lock_file`, beside it) for a whole run.

    A command takes it before computing, so that a second run into the same
    report stops at once instead of after all its work; `write_document`
    under it does not lock again. Within one thread it is re-entrant; another
    thread or process is refused. The directory that will hold the report is
    created if missing (the lock file lives there).

    Yields
    ------
    Path
        The report directory, resolved.

    Raises
    ------
    ReportError
        If another run holds the lock.
    """
    out = Path(out_dir).resolve()
    key = (out, threading.get_ident())
    if key in _HELD:
        yield out
        return
    out.parent.mkdir(parents=True, exist_ok=True)
    with _exclusive(out), _interrupts_seen():
        _HELD.add(key)
        try:
            yield out
        finally:
            _HELD.discard(key)


#: Ctrl-C presses seen while a report lock is held (in the main thread).
_INTERRUPTED = threading.Event()


@contextlib.contextmanager
def _interrupts_seen():
    """Remember every Ctrl-C while a report is made, as well as raising it.

    A KeyboardInterrupt raised inside a weakref callback or a ``__del__``
    (matplotlib's figure teardown has both) is printed as "Exception ignored"
    and lost, and the run would go on to replace the earlier report. The
    flag it leaves makes `_write` stop before the swap. Only the main thread
    receives signals; Python's own handler still raises the interrupt.
    """
    if threading.current_thread() is not threading.main_thread():
        yield  # only the main thread receives signals: nothing to keep
        return
    # a flag an earlier report's Ctrl-C left belongs to that report, not this one
    _INTERRUPTED.clear()
    previous = signal.getsignal(signal.SIGINT)
    if not callable(previous):
        yield  # Ctrl-C ignored or left to the OS: nothing to keep
        return

    def remember(signum, frame):
        _INTERRUPTED.set()
        previous(signum, frame)

    signal.signal(signal.SIGINT, remember)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)


def _recover(out: Path) -> None:
    """Finish what an interrupted run left beside ``out`` (the caller holds the lock).

    Its working copies (``.NAME.partial-*``) are removed. A report moved aside
    for a swap (``.NAME.old-*/NAME``) is put back when ``out`` is missing,
    and removed when the swap had completed: it is never lost.
    """
    # the name is escaped: a folder called 'r*' must not match another report's copies
    name = glob.escape(out.name)
    for partial in out.parent.glob(f".{name}.partial-*"):
        shutil.rmtree(partial, ignore_errors=True)
    for old in sorted(out.parent.glob(f".{name}.old-*")):
        if (old / out.name).is_dir() and not out.exists():
            (old / out.name).rename(out)
        shutil.rmtree(old, ignore_errors=True)


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


def replace_folder(
    out_dir, build: Callable[[Path], None], *, command: str | None = None, overwrite: bool = True
) -> Path:
    """Replace the report folder ``out_dir`` by what ``build(tmp)`` writes, atomically.

    ``build`` writes the report's files into a working copy beside the
    target; its marker (`MARKER`, listing the files) is added, and the copy
    is swapped in under the lock (`report_lock`, the caller's when it holds
    it). An existing folder is replaced only if it is an earlier report
    holding nothing foreign (`check_target`).

    Returns
    -------
    Path
        The report directory, resolved.
    """
    out = check_target(out_dir, overwrite)
    with report_lock(out):
        _recover(out)
        check_target(out, overwrite)  # again: recovery may have put a report back
        return _swap_in(out, build, command)


def _swap_in(out: Path, build: Callable[[Path], None], command: str | None) -> Path:
    """Build the report in a working copy and swap it in (see `replace_folder`)."""
    tmp = Path(tempfile.mkdtemp(prefix=f".{out.name}.partial-", dir=out.parent))
    os.chmod(tmp, 0o777 & ~_umask())  # a directory as the user's umask makes it, not 0700
    moved: Path | None = None
    try:
        build(tmp)
        written = sorted(p.name for p in tmp.iterdir())
        (tmp / MARKER).write_text(
            f"qc-control report\n{command or ''}\nfiles:\n" + "\n".join(written) + "\n",
            encoding="utf-8",
        )
        if _INTERRUPTED.is_set():  # a Ctrl-C that something swallowed: keep the earlier report
            raise KeyboardInterrupt
        if out.exists():
            old = Path(tempfile.mkdtemp(prefix=f".{out.name}.old-", dir=out.parent))
            out.rename(old / out.name)
            moved = old
            tmp.rename(out)
            moved = None
            shutil.rmtree(old, ignore_errors=True)
        else:
            tmp.rename(out)
    except BaseException:
        # the earlier report goes back where it was; the unfinished one is dropped
        if moved is not None and not out.exists():
            (moved / out.name).rename(out)
            shutil.rmtree(moved, ignore_errors=True)
        shutil.rmtree(tmp, ignore_errors=True)
        raise
    return out

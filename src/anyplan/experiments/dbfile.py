"""The results database as a file: what may be opened, by whom, and how.

* :func:`check_database` tells an anyplan results database from anything else (a folder, an
  empty or text file, another program's SQLite file, a truncated or corrupt one) *before* it is
  opened, so a file that is not ours is never modified: it is refused with
  :class:`DatabaseFileError` (exit code 2 from the command line).
* :func:`connect_readonly` opens a database read-only (SQLite's ``mode=ro``): ``anyplan report``
  cannot change a byte of it.
* :class:`WriterLock` makes sure one process at a time writes a database: an exclusive
  ``flock`` on the side file ``DB.lock``, held while the database is open for writing. A second
  writer waits up to its timeout, then is refused. (Readers need no lock: SQLite serialises
  reads against the writer's transactions.)
"""

from __future__ import annotations

import contextlib
import os
import sqlite3
import stat
import time
from pathlib import Path

from anyplan.errors import AnyplanError, shorten

__all__ = ["DatabaseFileError", "check_database", "connect_readonly", "WriterLock",
           "SQLITE_MAGIC", "DEFAULT_LOCK_TIMEOUT_S"]

#: The first 16 bytes of every SQLite 3 database file.
SQLITE_MAGIC = b"SQLite format 3\x00"
#: How long a second writer waits for the lock [s] before it is refused.
DEFAULT_LOCK_TIMEOUT_S = 10.0


class DatabaseFileError(AnyplanError):
    """The file cannot be used as an anyplan results database (nothing was changed)."""


def _name(path: Path) -> str:
    return shorten(str(path), 160).strip("'")


def connect_readonly(path: str | Path) -> sqlite3.Connection:
    """A read-only connection to ``path`` (no file is created or changed)."""
    uri = Path(path).resolve().as_uri() + "?mode=ro"
    return sqlite3.connect(uri, uri=True, timeout=30.0)


def check_database(path: str | Path, who: str, *, must_exist: bool = True,
                   writable: bool = False) -> bool:
    """Check that ``path`` is an anyplan results database; False if it does not exist (allowed
    only without ``must_exist``).

    Args:
        path: The database file.
        who: The command, for messages (``"bench: --db"``).
        must_exist: A missing file is an error.
        writable: The file (and its folder, for SQLite's journal) must be writable.

    Raises:
        DatabaseFileError: a folder, not a regular file, empty, not SQLite, another program's
            SQLite database, damaged, or (``writable``) read-only.
    """
    path = Path(path)
    where = f"{who} {_name(path)}"
    try:
        st = os.stat(path)
    except FileNotFoundError:
        if must_exist:
            raise DatabaseFileError(f"{where}: no such database") from None
        return False
    except OSError as exc:
        raise DatabaseFileError(f"{where}: cannot read ({exc.strerror})") from None
    if stat.S_ISDIR(st.st_mode):
        raise DatabaseFileError(f"{where}: is a folder, not a results database")
    if not stat.S_ISREG(st.st_mode):
        raise DatabaseFileError(f"{where}: not a regular file")
    if st.st_size == 0:
        raise DatabaseFileError(f"{where}: is an empty file, not an anyplan results database "
                                "(remove it, or choose another file)")
    try:
        with open(path, "rb") as f:
            head = f.read(len(SQLITE_MAGIC))
    except OSError as exc:
        raise DatabaseFileError(f"{where}: cannot read ({exc.strerror})") from None
    if head != SQLITE_MAGIC:
        raise DatabaseFileError(f"{where}: not an SQLite database (left unchanged)")
    try:
        conn = connect_readonly(path)
        try:
            tables = {r[0] for r in conn.execute("SELECT name FROM sqlite_master WHERE type = 'table'")}
            if "anyplan_meta" not in tables or "runs" not in tables:
                raise DatabaseFileError(f"{where}: an SQLite database of another program, not an "
                                        "anyplan results database (left unchanged)")
            # Before writing, the full check (indexes against tables too); reading: the quick one.
            check = "integrity_check(1)" if writable else "quick_check(1)"
            ok = conn.execute(f"PRAGMA {check}").fetchone()
            if ok is None or ok[0] != "ok":
                raise DatabaseFileError(f"{where}: the database is damaged "
                                        f"({shorten(ok[0] if ok else 'no answer', 80)})")
        finally:
            conn.close()
    except (sqlite3.DatabaseError, UnicodeDecodeError) as exc:
        raise DatabaseFileError(f"{where}: damaged or not a database "
                                f"({shorten(str(exc), 80).strip(chr(39))})") from None
    if writable:
        if not os.access(path, os.W_OK) or not st.st_mode & 0o222:  # no write bit: read-only
            # (also for root, whom os.access lets write anything)
            raise DatabaseFileError(f"{where}: the database is read-only")
        if not os.access(path.parent if str(path.parent) else Path("."), os.W_OK | os.X_OK):
            raise DatabaseFileError(f"{where}: its folder is not writable (SQLite needs a journal "
                                    "file beside the database)")
    return True


class WriterLock:
    """An exclusive lock on ``DB.lock`` for the one writer of database ``DB``.

    Args:
        path: The database file.
        who: The command, for messages.
        timeout_s: How long to wait for another writer to finish [s] (0: do not wait).
    """

    def __init__(self, path: str | Path, who: str = "database",
                 timeout_s: float = DEFAULT_LOCK_TIMEOUT_S) -> None:
        self.path = Path(path)
        self.lock_path = self.path.with_name(self.path.name + ".lock")
        self.who = who
        self.timeout_s = float(timeout_s)
        self.fd: int | None = None

    def acquire(self) -> None:
        """Take the lock, waiting at most ``timeout_s``.

        Raises:
            DatabaseFileError: another process holds it, or the lock file cannot be made.
        """
        where = f"{self.who} {_name(self.path)}"
        try:
            fd = os.open(self.lock_path, os.O_RDWR | os.O_CREAT, 0o644)
        except OSError as exc:
            raise DatabaseFileError(f"{where}: cannot create the lock file "
                                    f"{_name(self.lock_path)} ({exc.strerror})") from None
        try:
            import fcntl
        except ImportError:  # not POSIX: no lock (documented)
            self.fd = fd
            return
        deadline = time.monotonic() + self.timeout_s
        while True:
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
                break
            except OSError:
                if time.monotonic() >= deadline:
                    holder = ""
                    with contextlib.suppress(OSError):
                        holder = os.pread(fd, 32, 0).decode(errors="replace").strip()
                    os.close(fd)
                    by = f" (pid {shorten(holder, 20)})" if holder else ""
                    raise DatabaseFileError(
                        f"{where}: in use by another anyplan process{by}; waited "
                        f"{self.timeout_s:g} s. Wait for it to finish, or use another file") from None
                time.sleep(0.1)
        os.ftruncate(fd, 0)
        os.pwrite(fd, str(os.getpid()).encode(), 0)
        self.fd = fd

    def release(self) -> None:
        """Release the lock (the lock file stays: removing it would race with a waiter)."""
        if self.fd is not None:
            os.close(self.fd)  # closing the descriptor drops the flock
            self.fd = None

    def __enter__(self) -> WriterLock:
        self.acquire()
        return self

    def __exit__(self, *exc: object) -> None:
        self.release()

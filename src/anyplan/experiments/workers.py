"""Worker processes that die with the bench's main process.

A ``spawn`` worker of a ``ProcessPoolExecutor`` does not notice that its parent was killed
(SIGKILL, the OOM killer): it keeps computing its task, and multiprocessing's resource tracker
(a child of the parent that holds a pipe every worker inherits) keeps running with it.
:func:`die_with_parent`, the pool's initializer, prevents that: on Linux it asks the kernel to
send the worker SIGKILL when its parent dies (``prctl(PR_SET_PDEATHSIG)``); everywhere it also
starts a daemon thread that polls the parent's pid once a second and exits the worker when the
parent is gone. With the workers gone, the resource tracker reads end-of-file and exits too.
"""

from __future__ import annotations

import ctypes
import ctypes.util
import os
import signal
import sys
import threading
import time

__all__ = ["die_with_parent", "POLL_PERIOD_S"]

#: How often the watchdog thread checks the parent [s].
POLL_PERIOD_S = 1.0
_PR_SET_PDEATHSIG = 1


def _set_pdeathsig() -> bool:
    if not sys.platform.startswith("linux"):
        return False
    try:
        libc = ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6", use_errno=True)
        return libc.prctl(_PR_SET_PDEATHSIG, int(signal.SIGKILL), 0, 0, 0) == 0
    except (OSError, AttributeError):
        return False


def _watch(parent_pid: int) -> None:
    while True:
        time.sleep(POLL_PERIOD_S)
        if os.getppid() != parent_pid:
            os._exit(1)  # the parent is gone: stop at once, without cleanup of its work


def die_with_parent(parent_pid: int) -> None:
    """Make this (worker) process end when process ``parent_pid`` ends (see the module doc)."""
    _set_pdeathsig()
    if os.getppid() != parent_pid:  # the parent died before the signal was armed
        os._exit(1)
    threading.Thread(target=_watch, args=(parent_pid,), name="anyplan-parent-watchdog",
                     daemon=True).start()

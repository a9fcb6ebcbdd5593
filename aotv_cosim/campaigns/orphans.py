"""Local worker processes die with their campaign: none is left running when the parent ends.

`worker_started()` is the process pool's initializer. It asks Linux to send the worker SIGKILL
when its parent dies (prctl PR_SET_PDEATHSIG; also when the parent is SIGKILLed), and exits at
once if the parent is already gone. It also ignores SIGINT, so a Ctrl-C sent to the whole
process group reaches only the parent, which stops the campaign and ends the workers itself
(`terminate`), and drops any signal recorded by the parent before the fork.
"""

import ctypes
import os
import signal
import sys

from aotv_cosim.simulation import interrupts

PR_SET_PDEATHSIG = 1


def worker_started(parent_pid: int) -> None:
    """Initializer of a local pool worker whose parent is `parent_pid`."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    interrupts.RECEIVED.clear()
    if sys.platform.startswith("linux"):
        libc = ctypes.CDLL(None, use_errno=True)
        libc.prctl(PR_SET_PDEATHSIG, signal.SIGKILL, 0, 0, 0)
    if os.getppid() != parent_pid:  # the parent died before the request took effect
        os._exit(1)


def terminate(pool) -> None:
    """Kill the worker processes of a `pool.WorkerPool` whose running tasks are no longer wanted
    (`shutdown` alone would wait for them to finish)."""
    pool.terminate()

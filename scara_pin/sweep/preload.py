"""Run by each local worker process as it starts (Dask's ``distributed.worker.preload``): Ctrl-C is the client's.

A terminal's Ctrl-C reaches every process of the command's group, the workers too; the client writes the finished
rows and closes the cluster (:mod:`~scara_pin.sweep.engine`), so a worker ignores SIGINT instead of printing
asyncio's traceback as it dies.
"""

from __future__ import annotations

import signal
import threading
from typing import Any

__all__ = ["dask_setup"]


def dask_setup(worker: Any) -> None:
    """Dask's preload hook: SIGINT ignored in this worker process (its main thread sets handlers)."""
    if threading.current_thread() is threading.main_thread():
        signal.signal(signal.SIGINT, signal.SIG_IGN)

"""Child processes that receive Ctrl-C as a terminal sends it."""

from __future__ import annotations

import signal


def default_sigint() -> None:
    """``preexec_fn``: SIGINT back to its default disposition in the child, before exec.

    A shell that starts the suite as a background job (``make test &`` in a script) ignores SIGINT, and an
    ignored signal is inherited across exec: Python then installs no KeyboardInterrupt handler and the
    Ctrl-C a test sends never reaches the command under test.
    """
    signal.signal(signal.SIGINT, signal.SIG_DFL)

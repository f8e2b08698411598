"""Results that print as their summary: a short ``repr`` (the command line's text) and ``_repr_html_``.

A result object (a cycle, a jump, a trajectory, a verification, a workspace, ...) holds arrays of thousands
of samples; the dataclass ``repr`` of it printed them all (22,848 characters for a cycle). A class that
mixes in :class:`Summarized` and defines ``summary(units)`` prints that instead, in a terminal and in a
notebook (Jupyter shows ``_repr_html_``: the same lines, preformatted). Its dataclass decorator says
``repr=False`` (else the dataclass writes its own ``__repr__`` over this one).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from .units import DisplayUnits

__all__ = ["MAX_REPR_CHARS", "Summarized"]

MAX_REPR_CHARS = 4000
"""The longest summary a result prints (a few dozen lines); the rest is cut with a note (tests hold every
result well under it)."""


class Summarized:
    """Mixin: ``repr(obj)`` is ``obj.summary()`` (SI units), and Jupyter shows it as preformatted HTML."""

    def summary(self, units: DisplayUnits | None = None) -> str:
        """The result in a few lines, lengths and angles in ``units`` (default SI)."""
        raise NotImplementedError

    def __repr__(self) -> str:
        text = self.summary()
        if len(text) > MAX_REPR_CHARS:
            text = text[:MAX_REPR_CHARS] + f"\n... ({len(text) - MAX_REPR_CHARS} more characters)"
        return text

    def _repr_html_(self) -> str:
        from html import escape  # here: a command that prints a result does not pay for the html package

        return f'<pre class="scara-pin-summary">{escape(repr(self))}</pre>'

"""The ``scara-pin`` command line.

Conventions shared by every command:

- SI units by default; ``--deg`` gives and prints angles in degrees, ``--mm`` lengths in millimetres.
- Joint vectors are in URDF joint order (joint1..joint4); q3 grows as the quill moves down. A palletizer's
  q is (q1, q2, theta3, q4), four angles, theta3 the small arm's absolute angle (scara_pin.palletizer).
- ``--json`` prints one JSON object on stdout.
- Exit codes: 0 ok, 2 invalid input, 3 infeasible request (unreachable, limits), 1 internal error;
  ``check`` also exits 4 when the URDF is usable but has warnings; ``validate-ik`` exits 5 when the
  validation fails; 130 after Ctrl-C, 143 after SIGTERM (temporary files removed in both cases).
- ``--json`` output is always in SI units (m, rad, s), whatever ``--deg``/``--mm`` (which scale the inputs
  and the text output); its ``units`` field says so.
  Errors are one line on stderr starting with ``error:``; warnings start with ``warning:``.

Heavy packages (toppra, matplotlib, yourdfpy, meshcat) are imported only inside the commands that need
them, so ``fk`` starts about as fast as ``import pinocchio``.
"""

from __future__ import annotations

import argparse
import importlib
import logging
import os
import sys
from collections.abc import Callable, Sequence
from typing import Any

from .._version import __version__
from ..errors import ScaraError
from ..limits import files_recorded
from ..signals import Terminated, kept, raise_pending
from ._options import Parser, UsageError
from ._outputs import log

__all__ = ["COMMANDS", "build_parser", "main"]

COMMANDS: dict[str, str] = {
    "robots": "describe", "urdf": "describe", "check": "describe",
    "fk": "kinematics", "jacobian": "kinematics", "ik": "kinematics", "validate-ik": "kinematics",
    "traj": "motion", "jog": "motion",
    "cycle": "cycle",
    "job": "job",
    "sweep": "sweep",
    "workspace": "workspace",
    "view": "view",
    "teach": "teach",
    "calibrate": "calibrate",
}  # fmt: skip
"""Each command and the module of ``scara_pin.cli`` that registers it (in ``--help``'s order): ``main`` imports
only the module of the command it runs (``scara-pin fk`` loads neither the motion nor the calibration
commands). tests/test_cli.py checks it against what each module registers."""


def build_parser(command: str | None = None) -> argparse.ArgumentParser:
    """The argument parser of ``scara-pin``.

    Args:
        command: build only this command's parser (what :func:`main` does once it knows the command:
            building every command's options costs more than the rest of a ``scara-pin fk`` run above
            ``import pinocchio``); a name that is no command builds them all, for argparse's message.
            None: every command.
    """
    parser = Parser(
        prog="scara-pin",
        description="Kinematics of SCARA robots from one xacro/URDF description (Pinocchio inside). "
        "SI units unless --deg/--mm (JSON output always SI); exit codes: 0 ok, 2 invalid input, 3 infeasible, "
        "4 check: warnings, 5 validate-ik: failed, 1 internal error.",
    )
    parser.add_argument("--version", action="version", version=f"scara-pin {__version__}")
    parser.add_argument("-v", "--verbose", action="store_true", help="log details to stderr")
    sub = _Commands(parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=Parser))
    target: Any = sub if command is None else _OneCommand(sub, command)
    names = list(dict.fromkeys(COMMANDS.values())) if command not in COMMANDS else [COMMANDS[command]]
    for name in names:
        importlib.import_module(f"{__name__}.{name}").register(target)
    if command is not None and not target.found:
        return build_parser(None)
    return parser


def _command_of(argv: Sequence[str]) -> str | None:
    """The command named in ``argv``: its first word that is not an option (the top level's take no value)."""
    return next((a for a in argv if not a.startswith("-")), None)


class _Ignored:
    """Takes a command's option declarations and keeps none (the command is not the one being run)."""

    def add_argument(self, *args: Any, **kwargs: Any) -> None:  # noqa: D102
        return None

    def add_argument_group(self, *args: Any, **kwargs: Any) -> _Ignored:  # noqa: D102
        return self

    def set_defaults(self, **kwargs: Any) -> None:  # noqa: D102
        return None


class _Commands:
    """The subparsers; every command takes ``-v`` after its name too (``scara-pin job J.yaml -v``, as docs write)."""

    def __init__(self, sub: Any) -> None:
        self._sub = sub

    def add_parser(self, name: str, **kwargs: Any) -> Any:  # noqa: D102
        p = self._sub.add_parser(name, **kwargs)
        # SUPPRESS: given before the command, the top level's value stands (a default here would overwrite it)
        p.add_argument("-v", "--verbose", action="store_true", default=argparse.SUPPRESS, help="log details to stderr")
        return p


class _OneCommand:
    """The subparsers, as the commands' ``register`` functions see them, when one command will run."""

    def __init__(self, sub: Any, command: str) -> None:
        self._sub = sub
        self._command = command
        self.found = False

    def add_parser(self, name: str, **kwargs: Any) -> Any:  # noqa: D102
        if name != self._command:
            return _Ignored()
        self.found = True
        return self._sub.add_parser(name, **kwargs)


class _Formatter(logging.Formatter):
    def format(self, record: logging.LogRecord) -> str:
        return f"{record.levelname.lower()}: {record.getMessage()}"


def main(argv: Sequence[str] | None = None) -> int:
    """Run ``scara-pin`` with ``argv`` (default: ``sys.argv[1:]``) and return the exit code."""
    handler = logging.StreamHandler(sys.stderr)
    handler.setFormatter(_Formatter())
    log.addHandler(handler)
    try:
        parser = build_parser(_command_of(sys.argv[1:] if argv is None else argv))
        try:
            args = parser.parse_args(argv)
        except UsageError as exc:
            print(f"error: {exc} (see scara-pin --help)", file=sys.stderr)
            return 2
        except SystemExit as exc:  # --help, --version
            return exc.code if isinstance(exc.code, int) else 0
        log.setLevel(logging.DEBUG if args.verbose else logging.WARNING)
        func: Callable[[argparse.Namespace], int] | None = getattr(args, "func", None)
        if func is None:
            print("error: no command given (see scara-pin --help)", file=sys.stderr)
            return 2
        with kept(), files_recorded():  # SIGINT / SIGTERM raise (one a library swallowed again); the files read
            try:
                code = func(args)
            except Exception:
                raise_pending()  # a signal swallowed meanwhile wins over what followed it
                raise
            raise_pending()
            return code
    except ScaraError as exc:
        print(f"error: {_one_line(exc)}", file=sys.stderr)
        return exc.exit_code
    except Terminated:
        print("error: terminated (SIGTERM)", file=sys.stderr)
        return 143
    except KeyboardInterrupt:
        print("error: interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:
        # the reader went away (e.g. `| head`): not an error of ours
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        return 0
    except Exception as exc:  # a bug: say so in one line; SCARA_PIN_DEBUG=1 shows the traceback
        if os.environ.get("SCARA_PIN_DEBUG"):
            raise
        print(f"error: internal error ({type(exc).__name__}: {_one_line(exc)}); "
              "please report it; SCARA_PIN_DEBUG=1 shows the traceback", file=sys.stderr)  # fmt: skip
        return 1
    finally:
        log.removeHandler(handler)


def _one_line(exc: BaseException) -> str:
    return " ".join(str(exc).split())


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())

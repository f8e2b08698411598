"""The README's first hour (issue 31 item 8): its quick start prints what the command line prints, the demo
prints in the quick start's units, and the quick start says what to do next."""

from __future__ import annotations

import contextlib
import io
import re
import shlex
from pathlib import Path

import pytest

from scara_pin.cli import main

ROOT = Path(__file__).resolve().parents[1]
README = (ROOT / "README.md").read_text(encoding="utf-8")


def _console_blocks() -> list[tuple[list[str], list[str]]]:
    """(argv, the lines shown up to an elision "...") of each ``$ .venv/bin/scara-pin`` line of the README."""
    runs = []
    for block in re.findall(r"```console\n(.*?)```", README, flags=re.DOTALL):
        current: tuple[list[str], list[str]] | None = None
        for line in block.splitlines():
            if line.startswith("$ .venv/bin/scara-pin "):
                argv = shlex.split(line[len("$ .venv/bin/scara-pin ") :], comments=True)
                current = (argv, [])
                runs.append(current)
            elif current is not None and not line.startswith("..."):
                current[1].append(line)
            else:
                current = None  # what follows an elision is not compared
    return runs


RUNS = [run for run in _console_blocks() if run[0][0] != "job"]
"""The README's commands, but its job: the 4 x 6 tray plans 97 steps (about 20 s of CPU), and
benchmarks/bench_job.py compares the README's table with what the command prints (and each move with the same
move planned alone)."""


@pytest.mark.parametrize("argv, shown", RUNS, ids=[" ".join(a) for a, _ in RUNS])
def test_the_quick_start_prints_what_the_readme_shows(argv: list[str], shown: list[str]) -> None:
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        assert main(argv) == 0
    printed = out.getvalue().splitlines()
    assert printed[: len(shown)] == shown


def test_the_readme_runs_fk_ik_and_cycle() -> None:
    assert {a[0] for a, _ in RUNS} >= {"fk", "ik", "cycle"}


def test_the_demo_prints_in_the_quick_starts_units() -> None:
    demo = re.search(r"^demo:.*?(?=^\S)", (ROOT / "Makefile").read_text(), flags=re.DOTALL | re.MULTILINE)
    assert demo is not None
    lines = {cmd.split()[0]: cmd.split() for cmd in re.findall(r"\$\(BIN\)/scara-pin ([^\n]+)", demo[0])}
    quick = {a[0]: a for a, _ in RUNS}
    assert lines["fk"] == quick["fk"] and lines["ik"] == quick["ik"]  # the same commands as the quick start
    assert lines["jacobian"][1:] == quick["fk"][1:]
    assert all("--mm" in lines[c] and "--deg" in lines[c] for c in ("fk", "jacobian", "ik", "traj"))


def test_the_quick_start_says_what_to_do_next() -> None:
    start = README.index("## Quick start")
    nxt = README[start : README.index("\n## ", start + 10)]
    assert "**Next:**" in nxt
    for what in ("scara-pin robots", "scara-pin teach", "docs/tour.ipynb", "make docs", "site/index.html"):
        assert what in nxt, what

"""The `scara-pin view` command: the standalone page, the live server until Ctrl-C, and bad input."""

from __future__ import annotations

import os
import re
import signal
import subprocess
import sys
import time
import urllib.request
from pathlib import Path

import psutil
import pytest
from sigint import default_sigint

from scara_pin.cli import main


def run(capsys: pytest.CaptureFixture[str], argv: list[str]) -> tuple[int, str, str]:
    rc = main(argv)
    out, err = capsys.readouterr()
    assert "Traceback" not in err
    return rc, out, err


def test_html_page_of_a_trajectory_with_the_workspace(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    traj, page = tmp_path / "t.csv", tmp_path / "t.html"
    assert run(capsys, ["traj", "--robot", "s1", "--from", "0", "0", "0", "0", "--to", "1", "1", "0.05", "-1",
                        "--duration", "1", "--out", str(traj), "--rate", "100"])[0] == 0  # fmt: skip
    rc, out, err = run(capsys, ["view", "--robot", "s1", "--traj", str(traj), "--workspace", "--html", str(page)])
    assert rc == 0, err
    html = page.read_text(encoding="utf-8")
    assert html.lstrip().lower().startswith("<!doctype html") or html.lstrip().lower().startswith("<html")
    assert len(html) > 500_000  # meshcat's viewer script is embedded: the page works offline
    assert not re.search(r"""<script[^>]+src=["']https?://""", html)  # no external script
    assert sorted(p.name for p in tmp_path.iterdir()) == ["t.csv", "t.html"]  # no temporary file left


@pytest.mark.parametrize(
    ("argv", "code"),
    [
        (["view", "--q", "0", "0", "abc", "0", "--html", "PAGE"], 2),
        (["view", "--traj", "MISSING.csv", "--html", "PAGE"], 2),
        (["view", "--q", "0", "0", "0", "0", "--html", "/nonexistent/dir/p.html"], 2),
    ],
)
def test_bad_input(capsys: pytest.CaptureFixture[str], tmp_path: Path, argv: list[str], code: int) -> None:
    argv = [a.replace("PAGE", str(tmp_path / "p.html")).replace("MISSING", str(tmp_path / "missing")) for a in argv]
    rc, _, err = run(capsys, argv)
    assert rc == code
    assert len([ln for ln in err.splitlines() if ln.startswith("error:")]) == 1
    assert not (tmp_path / "p.html").exists()


def test_live_viewer_serves_on_loopback_until_ctrl_c() -> None:
    script = Path(sys.executable).parent / "scara-pin"
    cmd = [str(script)] if script.exists() else [sys.executable, "-m", "scara_pin.cli"]
    proc = subprocess.Popen([*cmd, "view", "--q", "0.3", "0.4", "0.02", "-0.5"], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, preexec_fn=default_sigint)  # fmt: skip
    try:
        line = proc.stdout.readline()  # type: ignore[union-attr]
        match = re.search(r"(http://127\.0\.0\.1:\d+/static/)", line)
        assert match, line
        with urllib.request.urlopen(match.group(1), timeout=10) as reply:  # the page is served
            assert reply.status == 200
        children = psutil.Process(proc.pid).children(recursive=True)
        assert children, "the meshcat server runs as a child process"
        for child in children:  # bound to loopback only
            for conn in child.net_connections(kind="inet"):
                if conn.status == psutil.CONN_LISTEN:
                    assert conn.laddr.ip in ("127.0.0.1", "::1"), conn
        proc.send_signal(signal.SIGINT)
        assert proc.wait(timeout=20) == 0
        deadline = time.monotonic() + 10
        while any(c.is_running() and c.status() != psutil.STATUS_ZOMBIE for c in children):
            assert time.monotonic() < deadline, "the meshcat server outlived the command"
            time.sleep(0.1)
        assert "Traceback" not in proc.stderr.read()  # type: ignore[union-attr]
    finally:
        if proc.poll() is None:
            os.kill(proc.pid, signal.SIGKILL)
            proc.wait()

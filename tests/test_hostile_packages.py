"""The hostile-input matrix of issue 24 for package folders, xacro includes, signals and ``--rate``.

Every row that could hang runs the real command line in a subprocess under the limits of ``test_hostile.py``
(address space, CPU time) and a timeout, and asserts the exit code, ONE ``error:`` line, the time taken and
the old output file (or none). The fixtures are made here: symbolic link loops, FIFOs named ``package.xml``
or included by a xacro, relative includes run from another folder.
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from sigint import default_sigint
from test_hostile import RUN, Done, _env, _limited, assert_one_error, cli, default_urdf

from scara_pin import load_robot
from scara_pin.cli import main
from scara_pin.description import packages
from scara_pin.description.packages import PackagePath
from scara_pin.errors import UrdfError

PKG = "robot_pkg"
Q = ["0.3", "-0.5", "0.02", "0.7"]
SECONDS = 10.0
"""Wall-clock bound of one command here [s] (each takes about 1 s alone; the machine may be loaded)."""


def expected_fk() -> list[float]:
    """The default robot's tool position at Q, by Pinocchio on the shipped description (the included file)."""
    return [float(v) for v in load_robot("default").tool_pose(np.array([float(v) for v in Q]))[:3]]


def top_xacro(include: str) -> str:
    return (f'<?xml version="1.0"?>\n<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">\n'
            f'  <xacro:include filename="{include}"/>\n</robot>\n')  # fmt: skip


def make_package(folder: Path, name: str = PKG) -> Path:
    """A package ``name`` at ``folder`` whose urdf/arm.xacro is the default robot's URDF."""
    (folder / "urdf").mkdir(parents=True)
    (folder / "package.xml").write_text(f"<package><name>{name}</name></package>")
    (folder / "urdf" / "arm.xacro").write_text(default_urdf())
    return folder


def fk_json(done: Done) -> list[float]:
    assert done.code == 0, done.err
    return list(json.loads(done.out)["position"])


# --------------------------------------------------------------------------------------------- 1. loops
def link_loops(ws: Path, levels: int = 12) -> None:
    """Two links back up at each of ``levels`` nested folders: 2^24 paths for a walk that follows links blindly."""
    folder = ws
    for i in range(levels):
        folder = folder / f"d{i}"
        folder.mkdir()
        (folder / "up").symlink_to("..")
        (folder / "top").symlink_to(os.path.relpath(ws, folder))


def test_symlink_loops_in_a_package_path_are_walked_once(tmp_path: Path) -> None:
    ws = tmp_path / "ws"
    ws.mkdir()
    link_loops(ws)
    make_package(ws / "zz" / PKG)  # sorted last: the search goes through the loops first
    (tmp_path / "top.xacro").write_text(top_xacro(f"$(find {PKG})/urdf/arm.xacro"))
    done = cli(["fk", "--urdf", "top.xacro", "--package-path", "ws", "--json", *Q], cwd=tmp_path)
    np.testing.assert_allclose(fk_json(done), expected_fk(), rtol=0, atol=1e-12)
    assert done.seconds < SECONDS
    (tmp_path / "missing.xacro").write_text(top_xacro("$(find no_such_pkg)/urdf/arm.xacro"))
    done = cli(["check", "missing.xacro", "--package-path", "ws"], cwd=tmp_path)  # the whole folder searched
    assert done.code == 2 and done.err == "" and "package 'no_such_pkg' not found" in done.out
    assert done.seconds < SECONDS


def test_the_package_search_caps_depth_and_entries(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    deep = tmp_path / "ws"
    folder = deep
    for i in range(packages.MAX_WALK_DEPTH + 1):
        folder = folder / f"d{i}"
    make_package(folder)
    with pytest.raises(UrdfError, match=f"more than {packages.MAX_WALK_DEPTH} levels below .* not searched"):
        PackagePath((deep,)).find(PKG)
    make_package(deep / "d0" / "shallow", "shallow_pkg")
    assert PackagePath((deep,)).find("shallow_pkg") == (deep / "d0" / "shallow").resolve()
    wide = tmp_path / "wide"
    for i in range(30):
        (wide / f"f{i:02d}").mkdir(parents=True)
    make_package(wide / "zz", "late_pkg")
    monkeypatch.setattr(packages, "MAX_WALK_ENTRIES", 20)
    with pytest.raises(UrdfError, match="stopped after 20 folder entries"):
        PackagePath((wide,)).find("late_pkg")


# --------------------------------------------------------------------------------------------- 2. FIFOs
def test_a_fifo_named_package_xml_in_a_package_path_is_skipped(tmp_path: Path) -> None:
    ws = tmp_path / "ws"
    (ws / "aa_evil").mkdir(parents=True)
    os.mkfifo(ws / "aa_evil" / "package.xml")
    make_package(ws / PKG)
    (tmp_path / "top.xacro").write_text(top_xacro(f"$(find {PKG})/urdf/arm.xacro"))
    done = cli(["fk", "--urdf", "top.xacro", "--package-path", "ws", "--json", *Q], cwd=tmp_path)
    np.testing.assert_allclose(fk_json(done), expected_fk(), rtol=0, atol=1e-12)
    assert done.seconds < SECONDS


def test_a_fifo_named_package_xml_above_the_robot_file_is_named_not_waited_for(tmp_path: Path) -> None:
    os.mkfifo(tmp_path / "package.xml")
    (tmp_path / "robot").mkdir()
    (tmp_path / "robot" / "top.xacro").write_text(top_xacro(f"$(find {PKG})/urdf/arm.xacro"))
    done = cli(["fk", "--urdf", "robot/top.xacro", *Q], cwd=tmp_path)
    assert_one_error(done, 2)
    assert f"package '{PKG}' not found" in done.err and f"{tmp_path / 'package.xml'}" in done.err
    assert "not a regular file" in done.err and done.seconds < SECONDS


# --------------------------------------------------------------------------------------------- 3. includes
@pytest.mark.parametrize("kind", ["fifo", "dev-zero"])
def test_a_xacro_include_that_is_not_a_regular_file_is_refused(tmp_path: Path, kind: str) -> None:
    if kind == "fifo":
        os.mkfifo(tmp_path / "part.xacro")
    else:
        (tmp_path / "part.xacro").symlink_to("/dev/zero")
    (tmp_path / "top.xacro").write_text(top_xacro("part.xacro"))
    (tmp_path / "out.urdf").write_text("old")
    done = cli(["check", "top.xacro"], cwd=tmp_path)
    assert done.code == 2 and "not a regular file" in done.out and done.seconds < SECONDS
    done = cli(["fk", "--urdf", "top.xacro", *Q], cwd=tmp_path)
    assert_one_error(done, 2)
    assert f"{tmp_path / 'part.xacro'}: not a regular file" in done.err and done.seconds < SECONDS


def test_a_missing_optional_include_is_still_skipped(tmp_path: Path) -> None:
    """xacro's own rule, kept: only a file that is not there is skipped; one that is not regular is an error."""
    text = top_xacro("part.xacro").replace('filename="part.xacro"', 'filename="part.xacro" optional="true"')
    (tmp_path / "top.xacro").write_text(text.replace("</robot>", '<link name="only"/></robot>'))
    assert '<link name="only"/>' in PackagePath((), tmp_path).expand_xacro(tmp_path / "top.xacro")
    os.mkfifo(tmp_path / "part.xacro")
    with pytest.raises(UrdfError, match="not a regular file"):
        PackagePath((), tmp_path).expand_xacro(tmp_path / "top.xacro")


def test_the_files_one_expansion_reads_are_bounded_together(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """An include of itself would recurse; ten includes of a 1 KB file over a 5 KB budget are refused."""
    (tmp_path / "part.xacro").write_text(top_xacro("leaf.xacro"))
    (tmp_path / "leaf.xacro").write_text("<robot>" + " " * 1000 + "</robot>")
    (tmp_path / "top.xacro").write_text(top_xacro("part.xacro").replace(
        "</robot>", "".join(f'<xacro:include filename="leaf.xacro" ns="n{i}"/>' for i in range(10)) + "</robot>"))
    monkeypatch.setattr(packages, "MAX_DOCUMENT_BYTES", 5000)
    with pytest.raises(UrdfError, match="exceed 5,000 bytes, the cap"):
        PackagePath((), tmp_path).expand_xacro(tmp_path / "top.xacro")
    monkeypatch.setattr(packages, "MAX_DOCUMENT_BYTES", 1 << 20)
    monkeypatch.setattr(packages, "MAX_XACRO_FILES", 5)
    with pytest.raises(UrdfError, match="more than 5 files read"):
        PackagePath((), tmp_path).expand_xacro(tmp_path / "top.xacro")


# --------------------------------------------------------------------------------------------- 12. relative
def test_a_relative_include_resolves_against_the_including_file(tmp_path: Path) -> None:
    """As ROS's xacro: robot/top.xacro includes part.xacro (robot/), which includes sub/leaf.xacro
    (robot/sub/); run from an unrelated folder."""
    robot, elsewhere = tmp_path / "robot", tmp_path / "elsewhere"
    (robot / "sub").mkdir(parents=True)
    elsewhere.mkdir()
    (robot / "top.xacro").write_text(top_xacro("part.xacro"))
    (robot / "part.xacro").write_text(top_xacro("sub/leaf.xacro"))
    (robot / "sub" / "leaf.xacro").write_text(default_urdf())
    (elsewhere / "part.xacro").write_text("<robot><link name='decoy'/></robot>")  # never the one read
    done = cli(["fk", "--urdf", "../robot/top.xacro", "--json", *Q], cwd=elsewhere)
    np.testing.assert_allclose(fk_json(done), expected_fk(), rtol=0, atol=1e-12)


# --------------------------------------------------------------------------------------------- 4. signals
SWALLOWING_READER = """
import sys, trimesh.exchange.load as _load
_real = _load.mesh_loaders["stl"]
def _blocked(*args, **kwargs):  # as trimesh's texture loads: blocked on a file, BaseException caught
    try:
        sys.stderr.write("blocked\\n"); sys.stderr.flush()
        open({fifo!r}).read()
    except BaseException:
        pass
    return _real(*args, **kwargs)
_load.mesh_loaders["stl"] = _blocked
"""


def mesh_robot(folder: Path, stl: bytes) -> Path:
    (folder / "part.stl").write_bytes(stl)
    mesh = '<visual><geometry><mesh filename="part.stl"/></geometry></visual>'
    (folder / "r.urdf").write_text(default_urdf().replace('<link name="tool0"/>', f'<link name="tool0">{mesh}</link>'))
    (folder / "v.html").write_text("old page")
    return folder / "r.urdf"


def box_stl(facets: int, seed: int = 0) -> bytes:
    corners = np.random.default_rng(seed).uniform(-0.05, 0.05, (facets, 3, 3)).tolist()
    body = "".join("facet normal 0 0 1\nouter loop\n" + "".join(f"vertex {a!r} {b!r} {c!r}\n" for a, b, c in t)
                   + "endloop\nendfacet\n" for t in corners)  # fmt: skip
    return f"solid part\n{body}endsolid part\n".encode()


def signalled(folder: Path, args: list[str], sig: int, ready: str,
              prelude: str = "") -> subprocess.CompletedProcess[str]:  # fmt: skip
    """Run the command, wait for ``ready`` on its stderr, send ``sig``; the finished process."""
    code = prelude + RUN
    proc = subprocess.Popen([sys.executable, "-c", code, *args], cwd=folder, stdin=subprocess.DEVNULL,
                            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True, preexec_fn=_limited,
                            env=_env())  # fmt: skip
    assert proc.stderr is not None
    lines = []
    deadline = time.monotonic() + 30
    while time.monotonic() < deadline:
        line = proc.stderr.readline()
        lines.append(line)
        if not line or ready in line:
            break
    assert ready in lines[-1], lines
    proc.send_signal(sig)
    try:
        _, rest = proc.communicate(timeout=30)
    except subprocess.TimeoutExpired:
        proc.kill()
        proc.communicate()
        raise AssertionError("the command went on after the signal") from None
    return subprocess.CompletedProcess(args, proc.returncode, "", "".join(lines) + rest)


@pytest.mark.parametrize(("sig", "code", "message"), [(signal.SIGINT, 130, "error: interrupted"),
                                                      (signal.SIGTERM, 143, "error: terminated (SIGTERM)")])
def test_a_signal_swallowed_by_a_blocked_mesh_reader_still_ends_the_command(tmp_path: Path, sig: int, code: int,
                                                                             message: str) -> None:  # fmt: skip
    """Item 4: the reader catches BaseException around a blocked open (as trimesh does): the command still
    ends with 130 / 143, and the old page stays."""
    os.mkfifo(tmp_path / "fifo")
    urdf = mesh_robot(tmp_path, box_stl(12))
    prelude = SWALLOWING_READER.format(fifo=str(tmp_path / "fifo"))
    done = signalled(tmp_path, ["view", "--urdf", str(urdf), "--html", "v.html"], sig, "blocked", prelude)
    assert done.returncode == code, done.stderr
    assert done.stderr.splitlines()[1:] == [message], done.stderr
    assert (tmp_path / "v.html").read_text() == "old page"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["fifo", "part.stl", "r.urdf", "v.html"]


def test_ctrl_c_while_trimesh_parses_a_mesh(tmp_path: Path) -> None:
    """Item 4, with the real reader: Ctrl-C lands while trimesh parses a 6 MB ASCII STL (in code that may catch
    it or not): 130, the old page."""
    urdf = mesh_robot(tmp_path, box_stl(40_000, seed=1))
    done = signalled(tmp_path, ["-v", "view", "--urdf", str(urdf), "--html", "v.html"], signal.SIGINT,
                     "reading mesh")  # fmt: skip
    assert done.returncode == 130, done.stderr
    assert done.stderr.splitlines()[-1] == "error: interrupted"
    assert (tmp_path / "v.html").read_text() == "old page"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["part.stl", "r.urdf", "v.html"]


@pytest.mark.parametrize(("sig", "code", "err"), [(signal.SIGINT, 0, "stopped\n"),
                                                  (signal.SIGTERM, 143, "error: terminated (SIGTERM)\n")])
def test_a_server_stops_on_ctrl_c_and_ends_143_on_sigterm(tmp_path: Path, sig: int, code: int, err: str) -> None:
    """Ctrl-C is how a server is stopped (exit 0); SIGTERM keeps its meaning (143), as README says."""
    proc = subprocess.Popen([sys.executable, "-c", RUN, "teach"], cwd=tmp_path, stdin=subprocess.DEVNULL,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, preexec_fn=_limited,
                            env=_env())  # fmt: skip
    assert proc.stdout is not None
    try:
        assert proc.stdout.readline().startswith("teach pendant: http://127.0.0.1:")
        proc.send_signal(sig)
        _, got = proc.communicate(timeout=30)
    finally:
        proc.kill()
        proc.communicate()
    assert (proc.returncode, got) == (code, err)


def test_children_get_sigint_default() -> None:
    """The helper the signal tests use: a child that ignored SIGINT would never see the Ctrl-C."""
    p = subprocess.run([sys.executable, "-c", "import signal; print(signal.getsignal(signal.SIGINT))"],
                       capture_output=True, text=True, preexec_fn=default_sigint, timeout=30)  # fmt: skip
    assert "default_int_handler" in p.stdout


# --------------------------------------------------------------------------------------------- 9. --rate
@pytest.mark.parametrize(("args", "needle"), [
    (["cycle", "--rate", "1_000"], "plain number"),
    (["cycle", "--rate", "\u0661\u0660\u0660\u0660"], "plain number"),
    (["cycle", "--rate", "1e-300"], "magnitude within"),
    (["traj", "--from", "0", "0", "0", "0", "--to", "0.1", "0", "0", "0", "--rate", "1e-50"],
     "last sample would be at t = 1e+50 s"),  # cycle --rate samples through the same Trajectory.times
    (["traj", "--from", "0", "0", "0", "0", "--to", "0.1", "0", "0", "0", "--rate", "0.2"], "t = 5 s"),
])  # fmt: skip
def test_rates_take_the_one_number_grammar(args: list[str], needle: str, tmp_path: Path,
                                           capsys: pytest.CaptureFixture[str]) -> None:  # fmt: skip
    out = tmp_path / "t.csv"
    assert main([*args, "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: ") and len(err.splitlines()) == 1 and needle in err, err
    assert not out.exists()


@pytest.mark.parametrize("port", ["8_000", "\u0668\u0660\u0660\u0660", "65536", "-1"])
def test_the_teach_port_takes_the_integer_grammar(port: str) -> None:
    """Parsed only (a port taken would start a server): 8_000 and Arabic-Indic digits are refused."""
    from scara_pin.cli import build_parser
    from scara_pin.cli._options import UsageError

    with pytest.raises(UsageError, match="--port"):
        build_parser().parse_args(["teach", "--port", port])
    assert build_parser().parse_args(["teach", "--port", "8000"]).port == 8000


def test_a_low_rate_of_a_long_motion_is_fine(tmp_path: Path) -> None:
    """The rule refuses a sample period longer than the motion and 1 s, nothing else: 0.5 Hz over a 10 s move."""
    out = tmp_path / "t.csv"
    assert main(["traj", "--from", "0", "0", "0", "0", "--to", "1", "0", "0", "0", "--duration", "10",
                 "--rate", "0.5", "--out", str(out)]) == 0  # fmt: skip
    t = np.loadtxt(out, delimiter=",", skiprows=1)[:, 0]
    np.testing.assert_allclose(t, np.arange(6) * 2.0)

"""The hostile-input matrix of issue 14, kept as tests: every row runs the real command line in a subprocess
under resource limits (address space, CPU time, wall clock) and asserts the exit code, ONE ``error:`` line on
stderr, no traceback, and no partial or replaced output file.

Rows that held before issue 14 are kept too (symlinked outputs, SIGINT during writes, xacro injection
through ``--set``, XXE and billion-laughs URDFs). The progress bar row runs under a pseudo-terminal.
Process-wide state (fd 2, the umask) is checked in-process with threads.
"""

from __future__ import annotations

import json
import math
import os
import pty
import resource
import signal
import stat
import subprocess
import sys
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from functools import cache
from pathlib import Path

import numpy as np
import pytest
from sigint import default_sigint

from scara_pin import load_robot
from scara_pin.cli import main
from scara_pin.cli._numbers import number
from scara_pin.description import generate_urdf
from scara_pin.errors import InvalidInputError, ParameterError, UrdfError
from scara_pin.files import atomic_output, write_text_atomic
from scara_pin.limits import MAX_SAMPLES, MAX_URDF_ELEMENTS
from scara_pin.robots import Robot

RUN = "import sys; from scara_pin.cli import main; sys.exit(main(sys.argv[1:]))"
MEMORY = 3 << 30  # bytes of address space per command
CPU_SECONDS = 60
WALL_SECONDS = 60.0
MOVE = ["--from", "0", "0.1", "0", "0", "--to", "0.5", "0.6", "0.02", "0.3"]  # the issue's move


def _limited() -> None:  # in the child, before exec
    default_sigint()
    resource.setrlimit(resource.RLIMIT_AS, (MEMORY, MEMORY))
    resource.setrlimit(resource.RLIMIT_CPU, (CPU_SECONDS, CPU_SECONDS))


def _env() -> dict[str, str]:
    env = dict(os.environ)
    env.pop("SCARA_PIN_DEBUG", None)
    env.update(OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1", MPLBACKEND="Agg")
    return env


@dataclass
class Done:
    code: int
    out: str
    err: str
    seconds: float


def cli(args: list[str], cwd: Path, timeout: float = WALL_SECONDS, **kwargs: object) -> Done:
    """Run ``scara-pin ARGS`` in a subprocess under the resource limits."""
    start = time.monotonic()
    p = subprocess.run([sys.executable, "-c", RUN, *args], cwd=cwd, capture_output=True, text=True, timeout=timeout,
                       preexec_fn=_limited, env=_env(), stdin=subprocess.DEVNULL, **kwargs)  # type: ignore[call-overload]  # fmt: skip
    return Done(p.returncode, p.stdout, p.stderr, time.monotonic() - start)


def assert_one_error(done: Done, code: int) -> None:
    """Exit ``code``, exactly one stderr line, starting with ``error:``, no traceback."""
    lines = done.err.splitlines()
    assert done.code == code, (done.code, done.err[-2000:])
    assert "Traceback" not in done.err and "internal error" not in done.err, done.err[-2000:]
    assert len(lines) == 1 and lines[0].startswith("error: "), done.err[-2000:]


# --------------------------------------------------------------------------------------------- input files
@cache
def default_urdf() -> str:
    return generate_urdf("default")


def traj_csv(rows: list[list[float]]) -> str:
    head = "t," + ",".join(f"{k}{i}" for k in ("q", "qd", "qdd") for i in range(1, 5))
    return head + "\n" + "\n".join(",".join(repr(float(v)) for v in r) for r in rows) + "\n"


def batch_csv(n: int, seed: int = 0) -> str:
    """n reachable targets of the default robot (x, y, z, yaw), by FK of random joint values."""
    rng = np.random.default_rng(seed)
    a = rng.uniform(-1.5, 1.5, n)
    b = rng.uniform(0.3, 2.0, n)
    r = 0.2 * np.hypot(1 + np.cos(b), np.sin(b))  # l1 = l2 = 0.2
    xs, ys = (r * np.cos(a)).tolist(), (r * np.sin(a)).tolist()
    lines = ["x,y,z,yaw"] + [f"{x!r},{y!r},-0.08,0.1" for x, y in zip(xs, ys)]
    return "\n".join(lines) + "\n"


def many_links(n: int) -> str:
    links = "".join(f'<link name="l{i}"/>' for i in range(n))
    joints = "".join(f'<joint name="j{i}" type="fixed"><parent link="l{i}"/><child link="l{i + 1}"/></joint>'
                     for i in range(n - 1))  # fmt: skip
    return f'<robot name="big">{links}{joints}</robot>'


def nan_mass() -> str:
    text = default_urdf()
    start = text.index('<mass value="') + len('<mass value="')
    return text[:start] + "nan" + text[text.index('"', start):]


def with_mesh() -> str:
    text = default_urdf()
    mesh = '<visual><geometry><mesh filename="/nonexistent/part.stl"/></geometry></visual>'
    return text.replace('<link name="tool0"/>', f'<link name="tool0">{mesh}</link>', 1)


XXE = ('<?xml version="1.0"?><!DOCTYPE robot [<!ENTITY x SYSTEM "file:///etc/passwd">]>'
       '<robot name="&x;"><link name="a"/></robot>')  # fmt: skip
LAUGHS = ('<?xml version="1.0"?><!DOCTYPE r [<!ENTITY a "aaaaaaaaaa">'
          + "".join(f'<!ENTITY {c} "{("&" + p + ";") * 10}">' for p, c in zip("abcdefgh", "bcdefghi"))
          + ']><robot name="&i;"><link name="a"/></robot>')  # fmt: skip


# --------------------------------------------------------------------------------------------- the matrix
@dataclass(frozen=True)
class Row:
    """One hostile call: ``args`` ({tmp} is the scratch folder), the files to create, the expected exit code."""

    id: str
    args: list[str]
    code: int = 2
    files: dict[str, Callable[[], str | bytes]] = field(default_factory=dict)
    untouched: tuple[str, ...] = ()  # outputs that must not exist (or keep their content) afterwards
    seconds: float = 20.0
    report: bool = False  # `check`: the findings go to stdout (exit 2 = unusable), stderr stays empty


DEVICE_WRITERS = [
    ("urdf-o", ["urdf", "-o", "/dev/null"]),
    ("traj-out", ["traj", *MOVE, "--out", "/dev/null"]),
    ("traj-plot", ["traj", *MOVE, "--plot", "/dev/null"]),
    ("traj-setpoints", ["traj", *MOVE, "--setpoints", "/dev/null"]),
    ("view-html", ["view", "--html", "/dev/null"]),
    ("workspace-plot", ["workspace", "--plot", "/dev/null"]),
    ("ik-output", ["ik", "--input", "{tmp}/in.csv", "--output", "/dev/null"]),
    ("urdf-o-fifo", ["urdf", "-o", "{tmp}/fifo"]),
    ("urdf-o-folder", ["urdf", "-o", "{tmp}"]),
    ("workspace-plot-folder", ["workspace", "--plot", "{tmp}/sub"]),
    ("workspace-plot-missing-folder", ["workspace", "--plot", "{tmp}/missing/w.png"]),
]

ROWS = [
    # 1. safety: the limit check on the law, not on samples
    Row("1-short-duration-strict", ["traj", *MOVE, "--duration", "0.0009", "--strict", "--out", "{tmp}/d.csv"], 3,
        untouched=("d.csv",)),
    Row("1-duration-1e-320", ["traj", *MOVE, "--duration", "1e-320", "--out", "{tmp}/d.csv"], untouched=("d.csv",)),
    # 2. devices, FIFOs and folders are never written nor replaced
    *(Row(f"2-{name}", args, files={"in.csv": lambda: batch_csv(3)}) for name, args in DEVICE_WRITERS),
    # 4. unbounded reads
    Row("4-ik-input-dev-zero", ["ik", "--input", "/dev/zero", "--output", "{tmp}/o.csv"], untouched=("o.csv",)),
    Row("4-check-dev-zero", ["check", "/dev/zero"], report=True),
    Row("4-fk-urdf-dev-zero", ["fk", "--urdf", "/dev/zero", "0", "0", "0", "0"]),
    Row("4-urdf-dh-dev-zero", ["urdf", "--dh", "/dev/zero"]),
    Row("4-view-traj-dev-zero", ["view", "--traj", "/dev/zero", "--html", "{tmp}/v.html"], untouched=("v.html",)),
    # 5. unbounded work: sized before it is done
    Row("5-rate-5e7", ["traj", *MOVE, "--rate", "5e7", "--out", "{tmp}/big.csv"], untouched=("big.csv",)),
    Row("5-rate-2.2e8", ["traj", *MOVE, "--rate", "2.2e8", "--out", "{tmp}/big.csv"], untouched=("big.csv",)),
    Row("5-tool-speed-1e-5", ["traj", *MOVE, "--tool-speed", "1e-5"], seconds=40),
    Row("5-delays-1e5", ["traj", *MOVE, "--delays", "1e5", "0", "0", "0", "--setpoints", "{tmp}/s.csv"],
        untouched=("s.csv",)),
    Row("5-torque-tiny-effort", ["traj", *MOVE, "--torque", "--set", "joint1_effort=1e-9"], seconds=40),
    Row("5-view-two-rows-1e5-s", ["view", "--traj", "{tmp}/t.csv", "--html", "{tmp}/v.html"],
        files={"t.csv": lambda: traj_csv([[0] + [0] * 12, [1e5, 0.1] + [0] * 11])}, untouched=("v.html",)),
    Row("5-urdf-200k-links", ["fk", "--urdf", "{tmp}/big.urdf", "0", "0", "0", "0"],
        files={"big.urdf": lambda: many_links(200_000)}),
    Row("5-check-200k-links", ["check", "{tmp}/big.urdf"], files={"big.urdf": lambda: many_links(200_000)},
        report=True, seconds=10),
    Row("5-urdf-5000-deep-chain", ["fk", "--urdf", "{tmp}/deep.urdf", "0", "0", "0", "0"],
        files={"deep.urdf": lambda: many_links(5_000)}),  # once a segmentation fault in urdfdom/Pinocchio
    Row("5-linear-yaw-1e12", ["traj", "--linear", "--from-pose", "0.3", "0", "-0.1", "1e12", "--to-pose", "0.3", "0.1",
                              "-0.1", "0.5"]),  # once a MemoryError (364 TiB)  # fmt: skip
    # 6. plain user input, never an internal error
    Row("6-ik-numeric-1e308", ["ik", "--numeric", "1e308", "0", "0", "0"]),
    Row("6-robot-5000-chars", ["fk", "--robot", "r" * 5000, "0", "0", "0", "0"]),
    Row("6-set-1e155", ["fk", "--set", "l1=1e155", "0", "0", "0", "0"]),
    Row("6-set-1e154", ["fk", "--set", "l1=1e154", "0", "0", "0", "0"]),
    Row("6-duration-1e308", ["traj", *MOVE, "--duration", "1e308"]),
    Row("6-tool-speed-1e308", ["traj", *MOVE, "--tool-speed", "1e308"]),
    Row("6-delays-1e308", ["traj", *MOVE, "--delays", "1e308", "0", "0", "0", "--setpoints", "{tmp}/s.csv"],
        untouched=("s.csv",)),
    Row("6-validate-ik-seed-minus-1", ["validate-ik", "--seed", "-1", "--samples", "2"]),
    Row("6-batch-bad-utf8", ["ik", "--input", "{tmp}/in.csv", "--output", "{tmp}/o.csv"],
        files={"in.csv": lambda: b"x,y,z,yaw\n0.3,0.1,-0.08,\xff\xfe\n"}, untouched=("o.csv",)),
    Row("6-batch-field-200kB", ["ik", "--input", "{tmp}/in.csv", "--output", "{tmp}/o.csv"],
        files={"in.csv": lambda: "x,y,z,yaw\n" + "1" * 200_000 + ",0,0,0\n"}, untouched=("o.csv",)),
    Row("6-batch-open-quote", ["ik", "--input", "{tmp}/in.csv", "--output", "{tmp}/o.csv"],
        files={"in.csv": lambda: 'x,y,z,yaw\n"0.3,0.1\n' + "0,0,0,0\n" * 20_000}, untouched=("o.csv",)),
    Row("6-view-traj-t-1e308", ["view", "--traj", "{tmp}/t.csv", "--html", "{tmp}/v.html"],
        files={"t.csv": lambda: traj_csv([[-1e308] + [0] * 12, [1e308] + [0] * 12])}, untouched=("v.html",)),
    # 8. silent wrong answers
    Row("8-jog-urdf-no-acceleration", ["jog", "--urdf", "{tmp}/r.urdf", "--from", "0", "0.5", "0.02", "0",
                                       "--direction", "1", "0"], files={"r.urdf": default_urdf}),  # fmt: skip
    Row("8-setpoint-rate-0", ["traj", *MOVE, "--setpoints", "{tmp}/s.csv", "--setpoint-rate", "0"],
        untouched=("s.csv",)),
    Row("8-numeric-with-input", ["ik", "--numeric", "--input", "{tmp}/in.csv", "--output", "{tmp}/o.csv"],
        files={"in.csv": lambda: batch_csv(3)}, untouched=("o.csv",)),
    # 10. noise: one line, no RuntimeWarning, no urdfdom lines, no "computed anyway" before the error
    Row("10-rate-1e-320", ["traj", *MOVE, "--rate", "1e-320", "--out", "{tmp}/d.csv"], untouched=("d.csv",)),
    Row("10-gear-1e308", ["traj", *MOVE, "--setpoints", "{tmp}/s.csv", "--gear", "1e308", "1", "1", "1",
                          "--steps-per-rev", "1", "1", "1", "1", "--screw-lead", "0.01"], untouched=("s.csv",)),
    Row("10-gear-1e12-steps-1e12", ["traj", *MOVE, "--setpoints", "{tmp}/s.csv", "--gear", "1e12", "1", "1", "1",
                                    "--steps-per-rev", "1e12", "1", "1", "1", "--screw-lead", "0.01"],
        untouched=("s.csv",)),  # fmt: skip
    Row("10-workspace-ray-1e308", ["workspace", "--ray", "1e308", "0", "1", "0"]),
    Row("10-fk-q-1e7", ["fk", "1e7", "0", "0", "0"]),
    Row("10-underscore-number", ["fk", "1_000", "0", "0", "0"]),
    Row("10-unicode-digits", ["fk", "\u0661", "0", "0", "0"]),
    Row("10-fullwidth-digits", ["fk", "\uff11", "0", "0", "0"]),
    Row("10-nan", ["fk", "nan", "0", "0", "0"]),
    # held before issue 14: kept
    Row("held-xacro-injection", ["urdf", "--set", "l1=${__import__('os').system('touch pwned')}"],
        untouched=("pwned",)),
    Row("held-xxe-urdf", ["fk", "--urdf", "{tmp}/x.urdf", "0", "0", "0", "0"], files={"x.urdf": lambda: XXE}),
    Row("held-billion-laughs-urdf", ["fk", "--urdf", "{tmp}/b.urdf", "0", "0", "0", "0"],
        files={"b.urdf": lambda: LAUGHS}),
    Row("held-check-billion-laughs", ["check", "{tmp}/b.urdf"], files={"b.urdf": lambda: LAUGHS}, report=True),
]


@pytest.mark.parametrize("row", ROWS, ids=[r.id for r in ROWS])
def test_hostile_row(row: Row, tmp_path: Path) -> None:
    for name, make in row.files.items():
        data = make()
        (tmp_path / name).write_bytes(data if isinstance(data, bytes) else data.encode())
    if any("fifo" in a for a in row.args):
        os.mkfifo(tmp_path / "fifo")
    (tmp_path / "sub").mkdir()
    before = {p.name for p in tmp_path.iterdir()}
    done = cli([a.replace("{tmp}", str(tmp_path)) for a in row.args], cwd=tmp_path)
    if row.report:
        assert (done.code, done.err) == (2, ""), done.err
        assert "error:" in done.out and "unusable" in done.out
    else:
        assert_one_error(done, row.code)
    assert done.seconds < row.seconds, done.seconds
    after = {p.name for p in tmp_path.iterdir()}
    assert after == before, f"files appeared or vanished: {after ^ before}"  # no partial file, no .tmp
    for name in row.untouched:
        assert not (tmp_path / name).exists()
    assert stat.S_ISCHR(os.stat("/dev/null").st_mode)
    assert stat.S_ISFIFO(os.lstat(tmp_path / "fifo").st_mode) if (tmp_path / "fifo").exists() else True


# --------------------------------------------------------------------------------------------- outputs
def test_symlinked_output_replaces_the_link_never_its_target(tmp_path: Path) -> None:
    target = tmp_path / "target.png"
    target.write_text("precious\n")
    for args in (["urdf", "-o", "link"], ["workspace", "--plot", "link"], ["workspace", "--robot", "palletizer",
                                                                          "--plot", "link"]):  # fmt: skip
        link = tmp_path / "link"
        link.unlink(missing_ok=True)
        link.symlink_to(target)
        done = cli(args, cwd=tmp_path)
        assert done.code == 0, done.err
        assert target.read_text() == "precious\n"  # the target is untouched
        assert link.is_file() and not link.is_symlink()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["link", "target.png"]


def test_stdout_dash_is_the_one_non_file_output(tmp_path: Path) -> None:
    done = cli(["urdf", "-o", "-"], cwd=tmp_path)
    assert done.code == 0 and done.out.startswith("<?xml") and done.out == default_urdf()
    done = cli(["traj", *MOVE, "--out", "-", "--rate", "10"], cwd=tmp_path)
    assert done.code == 0 and done.out.startswith("t,q1,q2,q3,q4,")
    assert list(tmp_path.iterdir()) == []


def test_plot_disk_full_is_exit_2_and_leaves_nothing(tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
                                                     capsys: pytest.CaptureFixture[str]) -> None:  # fmt: skip
    from matplotlib.figure import Figure

    def full(self: object, fname: object, **kwargs: object) -> None:
        Path(str(fname)).write_bytes(b"partial")
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(Figure, "savefig", full)
    (tmp_path / "w.png").write_text("old")
    assert main(["workspace", "--plot", str(tmp_path / "w.png")]) == 2
    assert capsys.readouterr().err.strip().splitlines() == [f"error: cannot write {tmp_path / 'w.png'}: No space "
                                                            "left on device"]  # fmt: skip
    assert (tmp_path / "w.png").read_text() == "old"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["w.png"]


@pytest.mark.skipif(os.geteuid() == 0, reason="root writes in any folder")
def test_unwritable_folder_is_exit_2(tmp_path: Path) -> None:
    folder = tmp_path / "ro"
    folder.mkdir()
    folder.chmod(0o500)
    try:
        assert_one_error(cli(["workspace", "--plot", str(folder / "w.png")], cwd=tmp_path), 2)
    finally:
        folder.chmod(0o700)


# --------------------------------------------------------------------------------------------- signals
@pytest.mark.parametrize(("sig", "code"), [(signal.SIGINT, 130), (signal.SIGTERM, 143)])
def test_signal_during_a_batch_write_leaves_no_file(sig: int, code: int, tmp_path: Path) -> None:
    (tmp_path / "in.csv").write_text(batch_csv(400_000, seed=3))
    proc = subprocess.Popen([sys.executable, "-c", RUN, "ik", "--input", "in.csv", "--output", "out.csv"],
                            cwd=tmp_path, stderr=subprocess.PIPE, stdout=subprocess.DEVNULL, text=True,
                            preexec_fn=_limited, env=_env())  # fmt: skip
    deadline = time.monotonic() + 30
    while not any(p.name.endswith(".tmp") for p in tmp_path.iterdir()) and time.monotonic() < deadline:
        time.sleep(0.01)
    assert proc.poll() is None, "the batch ended before the signal: make the input bigger"
    proc.send_signal(sig)
    _, err = proc.communicate(timeout=30)
    assert proc.returncode == code, err
    assert err.splitlines() == [f"error: {'interrupted' if sig == signal.SIGINT else 'terminated (SIGTERM)'}"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["in.csv"]  # no out.csv, no hidden .tmp


# --------------------------------------------------------------------------------------------- 7. a terminal
def test_batch_of_70k_rows_with_stderr_on_a_terminal(tmp_path: Path) -> None:
    """The old progress line called handle.tell() inside csv iteration: failed after 65,536 rows on a TTY."""
    n = 70_000
    (tmp_path / "in.csv").write_text(batch_csv(n, seed=5))
    master, slave = pty.openpty()
    chunks: list[bytes] = []

    def drain() -> None:
        while True:
            try:
                data = os.read(master, 65536)
            except OSError:
                return
            if not data:
                return
            chunks.append(data)

    reader = threading.Thread(target=drain, daemon=True)
    reader.start()
    try:
        p = subprocess.run([sys.executable, "-c", RUN, "ik", "--input", "in.csv", "--output", "out.csv"],
                           cwd=tmp_path, stderr=slave, stdout=subprocess.DEVNULL, timeout=WALL_SECONDS,
                           preexec_fn=_limited, env=_env())  # fmt: skip
    finally:
        os.close(slave)
        reader.join(timeout=5)
        os.close(master)
    err = b"".join(chunks).decode(errors="replace")
    assert p.returncode == 0, err
    assert f"wrote out.csv: {n} targets, {n} solved, 0 without solution" in err
    assert "\r" in err, "no progress bar on the terminal"
    assert len((tmp_path / "out.csv").read_text().splitlines()) == n + 1


def test_no_progress_bar_when_stderr_is_not_a_terminal(tmp_path: Path) -> None:
    (tmp_path / "in.csv").write_text(batch_csv(10, seed=6))
    done = cli(["ik", "--input", "in.csv", "--output", "out.csv"], cwd=tmp_path)
    assert done.code == 0 and done.err == "wrote out.csv: 10 targets, 10 solved, 0 without solution\n"


# --------------------------------------------------------------------------------------------- 1. the law itself
def test_limit_ratios_use_the_law_extrema_for_a_move_shorter_than_a_sample() -> None:
    from scara_pin.motion.timing import limit_ratios
    from scara_pin.motion.trajectory import quintic, trapezoidal

    robot = load_robot("default")
    q0, q1 = np.array([0, 0.1, 0, 0]), np.array([0.5, 0.6, 0.02, 0.3])
    T = 0.0009
    r = limit_ratios(robot, quintic(q0, q1, T), rate=1000.0)
    # independent route: s(x) = 10 x^3 - 15 x^4 + 6 x^5 differentiated by hand, maximised on a fine grid
    x = np.linspace(0.0, 1.0, 200_001)
    sd = np.max(30 * x**2 * (1 - x) ** 2) / T
    sdd = np.max(np.abs(60 * x - 180 * x**2 + 120 * x**3)) / T**2
    dq = np.abs(q1 - q0)
    assert r.velocity == pytest.approx(np.max(dq * sd / np.array(robot.limits.velocity)), rel=1e-9)
    assert r.acceleration == pytest.approx(np.max(dq * sdd / np.array(robot.limits.acceleration)), rel=1e-8)
    assert r.velocity > 100  # the issue's move: far beyond the limits, once printed as 0.000000
    # the time-optimal trapezoid touches its binding limit exactly
    r = limit_ratios(robot, trapezoidal(q0, q1, robot.limits.velocity, robot.limits.acceleration), rate=7.0)
    assert max(r.velocity, r.acceleration) == pytest.approx(1.0, abs=1e-12)


def test_short_duration_without_strict_warns_with_the_true_ratio(tmp_path: Path) -> None:
    done = cli(["traj", *MOVE, "--duration", "0.0009", "--json", "--rate", "10000"], cwd=tmp_path)
    assert done.code == 0
    assert done.err.startswith("warning: the trajectory exceeds a limit") and len(done.err.splitlines()) == 1
    assert json.loads(done.out)["limit_ratios"]["velocity"] > 100


# --------------------------------------------------------------------------------------------- 8. silent answers
def test_jog_on_a_urdf_robot_takes_acceleration_limits_from_the_command_line(tmp_path: Path) -> None:
    (tmp_path / "r.urdf").write_text(default_urdf())
    base = ["jog", "--from", "0", "0.5", "0.02", "0", "--direction", "1", "0", "--margin", "0.001", "--json"]
    configured = json.loads(cli(base, cwd=tmp_path).out)
    acc = [str(v) for v in load_robot("default").limits.acceleration]
    done = cli([*base, "--urdf", "r.urdf", "--acceleration", *acc], cwd=tmp_path)
    assert done.code == 0, done.err
    got = json.loads(done.out)
    assert got["duration"] == pytest.approx(configured["duration"], rel=1e-12)  # the same limits, the same move
    assert got["limit_ratio"] <= 1 + 1e-9


def test_setpoint_rate_is_honoured(tmp_path: Path) -> None:
    done = cli(["traj", *MOVE, "--duration", "2", "--setpoints", "s.csv", "--setpoint-rate", "250", "--rate", "1000"],
               cwd=tmp_path)  # fmt: skip
    assert done.code == 0, done.err
    t = np.loadtxt(tmp_path / "s.csv", delimiter=",", skiprows=1)[:, 0]
    assert np.allclose(np.diff(t), 1 / 250)


def test_check_flags_non_finite_masses_and_inertias(tmp_path: Path) -> None:
    from scara_pin.lint import check_urdf

    report = check_urdf(nan_mass())
    assert int(report.exit_code) == 2 and "bad-inertial" in report.codes()
    bad = default_urdf().replace('izz="', 'izz="1e999', 1)  # 1e999... overflows to inf
    assert "bad-inertial" in check_urdf(bad).codes()
    assert "bad-inertial" not in check_urdf(default_urdf()).codes()


# --------------------------------------------------------------------------------------------- 9. process state
def test_loading_urdfs_in_threads_never_touches_fd_2(monkeypatch: pytest.MonkeyPatch) -> None:
    calls: list[tuple[object, ...]] = []
    real_dup, real_dup2 = os.dup, os.dup2
    working = threading.Event()  # pytest's own capture dups fds too: count only the calls while loading

    def dup(*args: object) -> int:
        if working.is_set():
            calls.append(("dup", *args))
        return real_dup(*args)  # type: ignore[arg-type]

    def dup2(*args: object) -> int:
        if working.is_set():
            calls.append(("dup2", *args))
        return real_dup2(*args)  # type: ignore[arg-type]

    monkeypatch.setattr(os, "dup", dup)
    monkeypatch.setattr(os, "dup2", dup2)
    before = os.fstat(2)
    good, bad = default_urdf(), default_urdf().replace('link="link1"', 'link="ghost"', 1)
    errors: list[BaseException] = []

    def work(k: int) -> None:
        try:
            for _ in range(3):
                Robot(good)
                with pytest.raises(UrdfError, match="ghost"):
                    Robot(bad)
        except BaseException as exc:  # noqa: BLE001 - reported below
            errors.append(exc)

    threads = [threading.Thread(target=work, args=(k,)) for k in range(4)]
    working.set()
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    working.clear()
    assert errors == [] and calls == []
    after = os.fstat(2)
    assert (after.st_dev, after.st_ino) == (before.st_dev, before.st_ino)


def test_atomic_writes_in_threads_never_touch_the_umask(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    mask = os.umask(0o022)
    os.umask(mask)

    def forbidden(*args: object) -> int:
        raise AssertionError("the process umask was changed")

    monkeypatch.setattr(os, "umask", forbidden)
    errors: list[BaseException] = []

    def work(k: int) -> None:
        try:
            for i in range(50):
                write_text_atomic(tmp_path / f"f{k}-{i}.txt", f"{k} {i}\n")
        except BaseException as exc:  # noqa: BLE001 - reported below
            errors.append(exc)

    threads = [threading.Thread(target=work, args=(k,)) for k in range(8)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert errors == []
    modes = {p.stat().st_mode & 0o777 for p in tmp_path.iterdir()}
    assert modes == {0o666 & ~mask}
    assert len(list(tmp_path.iterdir())) == 400


def test_fsync_before_rename(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    calls: list[str] = []
    real_fsync, real_replace = os.fsync, os.replace
    monkeypatch.setattr(os, "fsync", lambda fd: (calls.append("fsync"), real_fsync(fd))[1])
    monkeypatch.setattr(os, "replace", lambda a, b: (calls.append("replace"), real_replace(a, b))[1])
    write_text_atomic(tmp_path / "a.txt", "data\n")
    assert calls[:2] == ["fsync", "replace"]


def test_the_writer_refuses_devices_in_the_library_too(tmp_path: Path) -> None:
    with pytest.raises(InvalidInputError, match="character device"):
        with atomic_output("/dev/null"):
            pass
    assert stat.S_ISCHR(os.stat("/dev/null").st_mode)


# --------------------------------------------------------------------------------------------- 10. numbers
@pytest.mark.parametrize(("text", "value"), [
    ("0.25", 0.25), ("-1.5e-3", -1.5e-3), ("+2", 2.0), (".5", 0.5), ("3.", 3.0), (" 7 ", 7.0), ("1E3", 1000.0),
    ("0", 0.0), ("-0", 0.0), ("1e12", 1e12), ("1e-100", 1e-100),
])  # fmt: skip
def test_numbers_a_robotics_user_types(text: str, value: float) -> None:
    assert number("x", text) == value


@pytest.mark.parametrize("text", [
    "1_000", "\u0661\u0662", "\uff11", "nan", "NaN", "inf", "-inf", "Infinity", "0x10", "1e400", "1e13", "1e-320",
    "", " ", "1,5", "1.2.3", "e5", "--1", "1e", "\u22121",
])  # fmt: skip
def test_numbers_refused(text: str) -> None:
    with pytest.raises(ParameterError) as info:
        number("x", text)
    assert "\n" not in str(info.value)


def test_validate_ik_failure_has_its_own_exit_code(monkeypatch: pytest.MonkeyPatch,
                                                   capsys: pytest.CaptureFixture[str]) -> None:  # fmt: skip
    import scara_pin.kinematics.validate as validate

    class Failed:
        ok = False

        def table(self) -> str:
            return "failed"

    monkeypatch.setattr(validate, "validate_ik", lambda *args, **kwargs: Failed())
    assert main(["validate-ik", "--samples", "3"]) == 5


@pytest.mark.parametrize("args", [
    ["fk", "--json", "--deg", "--mm", "90", "0", "10", "0"],
    ["jacobian", "--json", "--deg", "--mm", "90", "0", "10", "0"],
    ["ik", "--json", "--deg", "--mm", "0", "400", "-60", "90"],
    ["traj", "--json", "--deg", "--mm", "--from", "0", "0", "0", "0", "--to", "90", "0", "10", "0", "--out", "-"],
    ["workspace", "--json", "--mm"],
])  # fmt: skip
def test_json_is_always_si(args: list[str], capsys: pytest.CaptureFixture[str], tmp_path: Path,
                           monkeypatch: pytest.MonkeyPatch) -> None:  # fmt: skip
    monkeypatch.chdir(tmp_path)
    if "--out" in args:  # the samples would go to stdout: write them to a file instead
        args = [*args[:-1], "t.csv"]
    assert main(args) == 0
    data = json.loads(capsys.readouterr().out)
    assert {data["units"]["length"], data["units"]["angle"]} == {"m", "rad"}
    if "q" in data:
        assert data["q"] == pytest.approx([math.pi / 2, 0, 0.01, 0], abs=1e-12)
    if "q_to" in data:
        assert data["q_to"] == pytest.approx([math.pi / 2, 0, 0.01, 0], abs=1e-12)
    if "solutions" in data:
        assert any(np.allclose(s["q"], [math.pi / 2, 0, 0.01, 0], atol=1e-9) for s in data["solutions"])


def test_caps_are_what_the_docs_say() -> None:
    """Every cap of scara_pin/limits.py is in the caps table of docs/cli.md, with its value."""
    import scara_pin.limits as caps

    reference = (Path(__file__).resolve().parents[1] / "docs" / "cli.md").read_text()
    assert f"{MAX_SAMPLES:,}" in reference and f"{MAX_URDF_ELEMENTS:,}" in reference
    names = [n for n in vars(caps) if n.startswith("MAX_") and n != "MAX_NUMBER"]  # numbers: the grammar's own line
    assert len(names) >= 20
    missing = [f"{n} = {getattr(caps, n):,}" for n in names if f"{getattr(caps, n):,}" not in reference]
    assert not missing, missing


def test_the_caps_table_of_hostile_inputs_is_limits_py() -> None:
    """docs/hostile-inputs.md names each cap's constant: its value there is the constant's (issue 30)."""
    import re

    import scara_pin.limits as caps

    text = (Path(__file__).resolve().parents[1] / "docs" / "hostile-inputs.md").read_text()
    rows = re.findall(r"^\|[^|\n]+\| `(MAX_\w+)` \| ([\d,]+)(?: (KiB|MiB|GiB))? \|$", text, re.MULTILINE)
    assert {"MAX_YAML_NODES", "MAX_YAML_DEPTH", "MAX_MESH_BYTES"} <= {name for name, _, _ in rows}, rows
    unit = {"": 1, "KiB": 1 << 10, "MiB": 1 << 20, "GiB": 1 << 30}
    for name, value, scale in rows:
        assert int(value.replace(",", "")) * unit[scale] == getattr(caps, name), name


def test_urdf_elements_cap_in_the_library() -> None:
    with pytest.raises(UrdfError, match="cap"):
        Robot(many_links(MAX_URDF_ELEMENTS))


@pytest.mark.parametrize(("part", "needle"), [
    ("<visual><geometry/></visual>", "holds nothing"),
    ('<collision><geometry><capsule radius="1" length="1"/></geometry></collision>', "<capsule>"),
    ('<inertial><mass value="1"/></inertial>', "no <inertia>"),
    ('<visual><geometry><box/></geometry></visual>', "no size"),
    ('<visual><origin xyz="0 0"/><geometry><sphere radius="1"/></geometry></visual>', "3 finite numbers"),
])  # fmt: skip
def test_what_urdfdom_would_refuse_is_one_clear_error_and_nothing_on_fd_2(
    part: str, needle: str, capfd: pytest.CaptureFixture[str]
) -> None:
    """urdfdom prints these on the C stderr (and loads the rest); they are refused first, in Python."""
    text = default_urdf().replace('<link name="tool0"/>', f'<link name="tool0">{part}</link>', 1)
    assert text != default_urdf()
    with pytest.raises(UrdfError, match="not a valid URDF") as info:
        Robot(text)
    assert needle in str(info.value) and "tool0" in str(info.value)
    assert capfd.readouterr() == ("", "")


@pytest.mark.parametrize("hostile", ["bad-utf8", "dev-zero"])
def test_a_config_folder_with_a_hostile_yaml_file(hostile: str, tmp_path: Path) -> None:
    shipped = Path(__file__).resolve().parents[1] / "urdf" / "config" / "default"
    folder = tmp_path / "cfg"
    folder.mkdir()
    for f in shipped.glob("*.yaml"):
        (folder / f.name).write_bytes(f.read_bytes())
    if hostile == "bad-utf8":
        with (folder / "kinematics.yaml").open("ab") as handle:
            handle.write(b"l1: \xff\n")
    else:
        (folder / "joint_limits.yaml").unlink()
        (folder / "joint_limits.yaml").symlink_to("/dev/zero")
    done = cli(["fk", "--robot", str(folder), "0", "0", "0", "0"], cwd=tmp_path)
    assert_one_error(done, 2)
    assert done.seconds < 20


def _first_value(text: str, attr: str, new: str) -> str:
    start = text.index(f'{attr}="') + len(attr) + 2
    return text[:start] + new + text[text.index('"', start):]


@pytest.mark.parametrize("colour", ["", '<color rgba="0x1 0 0 1"/>', '<color rgba="1 2 3 4"/>'])
def test_a_global_material_without_a_readable_colour_loads_quietly(
    colour: str, capfd: pytest.CaptureFixture[str], caplog: pytest.LogCaptureFixture
) -> None:
    """urdfdom (so Pinocchio) loads it, complaining on fd 2; the loader removes what urdfdom ignores first and says
    it once (issue 29 item 7: the pre-check refuses what Pinocchio refuses, no more)."""
    text = default_urdf()
    start = text.index("<color ", text.index('<material name="scara_orange">'))
    text = text[:start] + colour + text[text.index("/>", start) + 2:]
    with caplog.at_level("WARNING", logger="scara_pin"):
        Robot(text)
    assert capfd.readouterr() == ("", "")
    assert "'scara_orange'" in caplog.text and "ignored" in caplog.text


@pytest.mark.parametrize(("attr", "value"), [("ixz", "1_0"), ("effort", "1_0"), ("xyz", "0 0 1_0")])
def test_numbers_urdfdom_refuses_are_refused_first(attr: str, value: str, capfd: pytest.CaptureFixture[str]) -> None:
    """Python's float() takes "1_0" where urdfdom does not (found by a mutation fuzz of the shipped URDF)."""
    text = _first_value(default_urdf(), attr, value)
    with pytest.raises(UrdfError, match="not a valid URDF") as info:
        Robot(text)
    assert repr(value)[:10] in str(info.value)
    assert capfd.readouterr() == ("", "")


def test_a_file_on_stdout_keeps_stdout_clean(tmp_path: Path) -> None:
    """`--plot -`: the PNG alone on stdout, the summary on stderr; two outputs on stdout are refused."""
    p = subprocess.run([sys.executable, "-c", RUN, "traj", *MOVE, "--plot", "-"], cwd=tmp_path, capture_output=True,
                       timeout=WALL_SECONDS, preexec_fn=_limited, env=_env())  # fmt: skip
    assert p.returncode == 0 and p.stdout.startswith(b"\x89PNG\r\n\x1a\n") and b"wrote     plot: -" in p.stderr
    assert_one_error(cli(["traj", *MOVE, "--out", "-", "--json"], cwd=tmp_path), 2)
    assert_one_error(cli(["traj", *MOVE, "--out", "-", "--setpoints", "-"], cwd=tmp_path), 2)
    assert list(tmp_path.iterdir()) == []


def test_a_missing_mesh_is_one_warning_and_a_placeholder(tmp_path: Path) -> None:
    """A mesh that cannot be read is the user's file, not a bug: one ``warning:`` naming it, the page written
    with a placeholder (issue 13's rule; exit 0, never exit 1)."""
    (tmp_path / "m.urdf").write_text(with_mesh())
    done = cli(["view", "--urdf", str(tmp_path / "m.urdf"), "--html", str(tmp_path / "v.html")], cwd=tmp_path)
    assert done.code == 0, done.err
    lines = done.err.splitlines()
    assert len(lines) == 1 and lines[0].startswith("warning:") and "/nonexistent/part.stl" in lines[0], lines
    assert "Traceback" not in done.out + done.err
    assert (tmp_path / "v.html").stat().st_size > 0

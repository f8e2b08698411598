"""Numbers for people (issue 22, items 3 and 6): text rounded to the printed resolution (no -0, no 1e-17),
JSON exact; one units rule for --deg/--mm/--units that never reads a millimetre value as metres."""

from __future__ import annotations

import json
import math
import re

import numpy as np
import pytest

from scara_pin.cli import main
from scara_pin.errors import InvalidInputError, ParameterError
from scara_pin.units import HUMAN, SI, DisplayUnits, decimals_for, format_number, format_vector

NUMBER = re.compile(r"-?\d+(?:\.\d+)?(?:[eE][-+]?\d+)?")


def run(capsys: pytest.CaptureFixture[str], argv: list[str]) -> tuple[int, str, str]:
    rc = main(argv)
    out, err = capsys.readouterr()
    assert "Traceback" not in out + err
    return rc, out, err


def one_error_line(err: str, needle: str) -> None:
    lines = err.splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: ") and needle in lines[0], err


# ------------------------------------------------------------------------------------ the helper
@pytest.mark.parametrize(("value", "decimals", "text"), [
    (2.4492936e-14, 6, "0"),  # cos(pi/2) * 400 mm: the issue's noise
    (-6.245004513516506e-17, 9, "0"),  # never "-0"
    (-0.0, 9, "0"),
    (-4e-10, 9, "0"),  # rounds to -0.000000000
    (0.18999999999999986, 9, "0.19"),
    (-1.5, 3, "-1.5"),
    (400.0, 6, "400"),
    (123.4567891234, 6, "123.456789"),
    (-0.0000026, 6, "-0.000003"),
    (1e12, 9, "1000000000000"),
    (float("nan"), 9, "nan"),
    (float("-inf"), 9, "-inf"),
])  # fmt: skip
def test_format_number(value: float, decimals: int, text: str) -> None:
    assert format_number(value, decimals) == text


def test_decimals_follow_the_unit() -> None:
    # 1e-9 SI in the unit shown: m and rad 9 decimals, mm 6, deg 7 (1e-7 deg = 1.75e-9 rad), mm^2 3
    assert [decimals_for(s) for s in (1.0, 1000.0, 180 / math.pi, 1e6)] == [9, 6, 7, 3]
    assert (SI.decimals("length"), SI.decimals("angle"), HUMAN.decimals("length"), HUMAN.decimals("angle")) == (9, 9,
                                                                                                                 6, 7)
    assert HUMAN.format(math.pi / 2, "angle") == "90" and HUMAN.format(0.0100000000001, "length") == "10"
    assert format_vector([1.0, -2e-17, 0.5], 9, width=4) == "[   1,    0,  0.5]"
    with pytest.raises(ParameterError):
        decimals_for(0.0)


@pytest.mark.parametrize(("text", "length", "angle"), [
    ("mm,deg", "mm", "deg"), ("deg,mm", "mm", "deg"), ("deg", "m", "deg"), ("mm", "mm", "rad"),
    ("m,rad", "m", "rad"), (" mm , deg ", "mm", "deg"),
])  # fmt: skip
def test_units_list(text: str, length: str, angle: str) -> None:
    assert DisplayUnits.parse(text) == DisplayUnits(length, angle)


@pytest.mark.parametrize("text", ["mm,m", "deg,rad", "inch", "", "mm;deg", "MM,DEG"])
def test_units_list_refused(text: str) -> None:
    with pytest.raises(ParameterError):
        DisplayUnits.parse(text)


# ------------------------------------------------------------------------------------ text output of the commands
def test_fk_text_of_the_issue(capsys: pytest.CaptureFixture[str]) -> None:
    """``fk --deg --mm 90 0 10 0`` of the default robot (l1 = l2 = 200 mm, tool0 50 mm below the base, q3 = 10 mm
    down): x = 200 cos 90 + 200 cos 90 = 0, y = 400, z = -60, yaw 90, as a person writes them."""
    rc, out, err = run(capsys, ["fk", "--deg", "--mm", "90", "0", "10", "0"])
    assert rc == 0 and err == ""
    lines = out.splitlines()
    assert "position  [0, 400, -60]  [mm]" in lines
    assert "yaw       90  [deg]" in lines
    assert "q         [90, 0, 10, 0]  [deg, deg, mm, deg]" in lines
    matrix = [line for line in lines if line.startswith("          [")]
    assert [[float(v) for v in NUMBER.findall(row)] for row in matrix] == [
        [0, 1, 0, 0], [1, 0, 0, 400], [0, 0, -1, -60], [0, 0, 0, 1]]  # fmt: skip
    assert "e-" not in out and not re.search(r"(?<![\w.])-0(?![.\d])", out)


def _printed_numbers(line: str) -> list[float]:
    inside = line[line.index("[") + 1 : line.index("]")]
    return [float(v) for v in inside.split(",")]


@pytest.mark.parametrize("flags", [[], ["--deg", "--mm"]])
def test_fk_text_is_the_json_rounded(flags: list[str], capsys: pytest.CaptureFixture[str]) -> None:
    """On random configurations, including exact multiples of 90 deg where the noise lives, every printed value
    is the exact (JSON) value rounded to the unit's resolution: within half a unit of the last digit."""
    rng = np.random.default_rng(7)
    L, A = (1000.0, 180 / math.pi) if flags else (1.0, 1.0)
    dl, da = (6, 7) if flags else (9, 9)
    for k in range(12):
        q = rng.uniform([-2.2, -2.5, -0.1, -3.0], [2.2, 2.5, 0.0, 3.0])
        if k % 3 == 0:
            q[[0, 1, 3]] = rng.integers(-1, 2, 3) * (math.pi / 2)
        typed = [repr(float(v * s)) for v, s in zip(q, (A, A, -L, A))]  # q3 is typed negative: upward, within limits
        typed[2] = repr(float(-abs(q[2]) * L))
        rc, out, _ = run(capsys, ["fk", *flags, "--", *typed])
        assert rc == 0
        rc, js, _ = run(capsys, ["fk", "--json", *flags, "--", *typed])
        data = json.loads(js)
        lines = {line.split()[0]: line for line in out.splitlines() if line.split()}
        pos = _printed_numbers(lines["position"])
        assert np.abs(np.array(pos) - np.array(data["position"]) * L).max() <= 0.5 * 10.0**-dl * (1 + 1e-6)
        yaw = float(lines["yaw"].split()[1])
        assert abs(yaw - data["yaw"] * A) <= 0.5 * 10.0**-da * (1 + 1e-6)
        for token in NUMBER.findall(out):
            assert "e" not in token.lower() and token != "-0"
            if "." in token:
                assert len(token.split(".")[1]) <= max(dl, da, 9) and not token.endswith("0")


def test_ik_and_jacobian_text_are_rounded(capsys: pytest.CaptureFixture[str]) -> None:
    rc, out, _ = run(capsys, ["ik", "--deg", "--mm", "0", "400", "-60", "90"])  # stretched along y: q = (90, 0, 10, 0)
    assert rc == 0
    q_lines = [line for line in out.splitlines() if line.startswith(("right", "left"))]
    assert q_lines and all(_printed_numbers(line) == [90, 0, 10, 0] for line in q_lines)
    rc, out, _ = run(capsys, ["jacobian", "--deg", "--mm", "90", "0", "10", "0"])
    assert rc == 0 and "e-" not in out
    rows = {line.split()[0]: line.split()[2:] for line in out.splitlines() if line.startswith(("x ", "y ", "z "))}
    # d(x, y)/dq1 at q1 = 90 deg, stretched: (-400, 0) mm/rad = (-400 pi/180, 0) mm/deg
    assert float(rows["x"][0]) == pytest.approx(-400 * math.pi / 180, abs=1e-8) and rows["y"][0] == "0"


def test_workspace_text_is_rounded(capsys: pytest.CaptureFixture[str]) -> None:
    rc, out, _ = run(capsys, ["workspace", "--mm", "--ray", "300", "100", "1", "0"])
    assert rc == 0
    lines = {line.split()[0]: line for line in out.splitlines()}
    # outer circle r = 400 mm from (0, 0): the ray y = 100 meets it at x = sqrt(400^2 - 100^2)
    assert _printed_numbers(lines["edge"]) == [pytest.approx(math.sqrt(400**2 - 100**2), abs=5e-7), 100]
    assert "e-" not in out and " -0 " not in out


# ------------------------------------------------------------------------------------ the units rule
@pytest.mark.parametrize(("argv", "needle"), [
    (["fk", "90", "0", "10", "0", "--deg"], "--deg without --mm: q3 = 10 is a length"),  # the issue's command
    (["jacobian", "--deg", "90", "0", "0.01", "0"], "q3 = 0.01 is a length"),
    (["ik", "--deg", "0.3", "0.1", "-0.1", "45"], "target x = 0.3 is a length"),
    (["ik", "--mm", "300", "100", "-60", "0.7"], "--mm without --deg: target yaw = 0.7 is an angle"),
    (["fk", "--mm", "1.5", "0", "10", "0"], "q1 = 1.5 is an angle"),
    (["traj", "--deg", "--from", "0", "0", "0", "0", "--to", "90", "60", "0.05", "-180", "--duration", "5"],
     "--from q3 = 0 is a length"),
    (["jog", "--mm", "--from", "0.3", "1.0", "20", "0.2", "--direction", "1", "0"], "--from q1 = 0.3 is an angle"),
    (["cycle", "--deg", "--span", "300"], "--span = 300 is a length"),
    (["workspace", "--units", "mm", "--mm", "--ray", "300", "100", "1", "0"], "not both"),
    (["fk", "--units", "mm,m", "0", "0", "0", "0"], "two length units"),
    (["fk", "--units", "inch", "0", "0", "0", "0"], "must list units"),
])  # fmt: skip
def test_a_lone_unit_flag_never_reads_the_other_kind(argv: list[str], needle: str,
                                                     capsys: pytest.CaptureFixture[str]) -> None:  # fmt: skip
    rc, out, err = run(capsys, argv)
    assert rc == 2 and out == ""
    one_error_line(err, needle)


@pytest.mark.parametrize(("argv", "q_si"), [
    (["fk", "--json", "--deg", "--mm", "90", "0", "10", "0"], [math.pi / 2, 0, 0.01, 0]),
    (["fk", "--json", "--units", "mm,deg", "90", "0", "10", "0"], [math.pi / 2, 0, 0.01, 0]),
    (["fk", "--json", "--units", "deg,m", "90", "0", "0.01", "0"], [math.pi / 2, 0, 0.01, 0]),
    (["fk", "--json", "--units", "deg", "90", "0", "0.01", "0"], [math.pi / 2, 0, 0.01, 0]),
    (["fk", "--json", "--units", "mm", "1.5", "0", "10", "0"], [1.5, 0, 0.01, 0]),
    # the palletizer's q are four angles: --deg alone reads no length
    (["fk", "--json", "--robot", "palletizer", "--deg", "0", "10", "20", "0"], [0, math.pi / 18, math.pi / 9, 0]),
])  # fmt: skip
def test_explicit_units_are_read(argv: list[str], q_si: list[float], capsys: pytest.CaptureFixture[str]) -> None:
    rc, out, err = run(capsys, argv)
    assert rc == 0 and err == ""
    assert json.loads(out)["q"] == pytest.approx(q_si, abs=1e-15)


def test_a_lone_flag_is_fine_without_the_other_kind(capsys: pytest.CaptureFixture[str]) -> None:
    # workspace reads lengths only (the ray's direction has no unit)
    rc, out, _ = run(capsys, ["workspace", "--mm", "--json", "--ray", "300", "100", "1", "0"])
    assert rc == 0 and json.loads(out)["ray"]["start"] == pytest.approx([0.3, 0.1], abs=1e-15)


def test_defaults_stay_si_whatever_the_units(capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
                                             ) -> None:  # fmt: skip
    """``cycle --mm`` used to read its default span "0.305" as 0.305 mm; a default is SI, a typed value is not.

    The cycle itself is not computed (seconds): what the command passes to it is caught on the way.
    """
    import scara_pin.motion.cycle as cycle

    def caught(robot: object, **kw: float) -> None:
        raise InvalidInputError(f"span={kw['span']!r} rise={kw['rise']!r}")

    monkeypatch.setattr(cycle, "standard_cycle", caught)
    rc, _, err = run(capsys, ["cycle", "--mm", "--deg"])
    assert rc == 2 and "span=0.305 rise=0.025" in err
    rc, _, err = run(capsys, ["cycle", "--mm", "--deg", "--span", "200", "--rise", "30"])
    assert rc == 2 and "span=0.2 rise=0.03" in err

"""The one CSV reader (scara_pin.tables) and the library's batch IK between files (kinematics.batch_io)."""

from __future__ import annotations

import csv
import io
import math
from pathlib import Path

import numpy as np
import pytest

from scara_pin import InvalidInputError, Robot
from scara_pin.kinematics.batch_io import OUTPUT_COLUMNS, solve_csv
from scara_pin.tables import csv_rows, read_csv


def _rows(text: str, columns: tuple[str, ...], **kw: object) -> list[tuple[int, list[float]]]:
    return list(csv_rows(io.BytesIO(text.encode()), "mem.csv", columns, **kw))  # type: ignore[arg-type]


def test_columns_by_name_comments_blanks_and_quotes() -> None:
    text = "# made by hand\n\n B , A ,note\n1,2,x\n\n# a comment\n\"3\",4.5e-1,\"a, b\"\n"
    assert _rows(text, ("a", "b")) == [(4, [2.0, 1.0]), (7, [0.45, 3.0])]


def test_optional_columns_read_when_present_nan_when_absent() -> None:
    assert _rows("a,yaw,b\n1,0.5,2\n", ("a", "b"), optional=("YAW",)) == [(2, [1.0, 2.0, 0.5])]
    (line, values), = _rows("a,b\n1,2\n", ("a", "b"), optional=("yaw",))
    assert line == 2 and values[:2] == [1.0, 2.0] and math.isnan(values[2])
    with pytest.raises(InvalidInputError, match="line 2: yaw = 'nan' is not a plain number"):
        _rows("a,b,yaw\n1,2,nan\n", ("a", "b"), optional=("yaw",))


def test_exact_header() -> None:
    assert _rows("t,q\n0,1\n", ("t", "q"), exact=True) == [(2, [0.0, 1.0])]
    with pytest.raises(InvalidInputError, match="first line must be the header t,q"):
        _rows("t,q,extra\n0,1,2\n", ("t", "q"), exact=True)


@pytest.mark.parametrize(
    ("text", "needle"),
    [("", "empty file"), ("x,y\n1,2\n", "no column z"), ("x,y,z\n1,2\n", "line 2: 2 values, expected 3"),
     ("x,y,z\n1,2,3\n1,nan,3\n", "line 3: y = 'nan'"), ("x,y,z\n1,1_0,3\n", "not a plain number"),
     ("x,y,z\n1,2,1e13\n", "beyond"), ("x,y,z\n\"1,2,3\n" + "4,5,6\n" * 3, "1 values, expected 3"),
     ("x,y,z\n1,2,\xff\n", "not UTF-8")],
    ids=["empty", "missing", "short", "nan", "underscore", "huge", "open-quote", "utf8"],
)  # fmt: skip
def test_refusals_name_the_line(text: str, needle: str) -> None:
    raw = text.encode("latin-1") if "\xff" in text else text.encode()
    with pytest.raises(InvalidInputError, match=needle):
        list(csv_rows(io.BytesIO(raw), "mem.csv", ("x", "y", "z")))


def test_progress_counts_every_byte() -> None:
    text = "x\n1\n# c\n\n2\n"
    seen: list[int] = []
    list(csv_rows(io.BytesIO(text.encode()), "mem.csv", ("x",), progress=seen.append))
    assert sum(seen) == len(text.encode())


def test_read_csv_files(tmp_path: Path) -> None:
    path = tmp_path / "t.csv"
    path.write_text("x,y\n1,2\n3,4\n", encoding="utf-8")
    np.testing.assert_array_equal(read_csv(path, ("y", "x")), [[2.0, 1.0], [4.0, 3.0]])
    path.write_text("x,y\n", encoding="utf-8")
    with pytest.raises(InvalidInputError, match="no data row"):
        read_csv(path, ("x",))
    with pytest.raises(InvalidInputError, match="cannot be read"):
        read_csv(tmp_path / "missing.csv", ("x",))
    with pytest.raises(InvalidInputError, match="max|cap"):
        path.write_text("x\n" + "1\n" * 5, encoding="utf-8")
        read_csv(path, ("x",), max_rows=3)


# ------------------------------------------------------------------------------------------ batch IK
def test_solve_csv_in_the_library(robot_default: Robot, tmp_path: Path, rng: np.random.Generator) -> None:
    """Targets made by FK of random q; every output row reproduces its target under FK to 1e-9."""
    lo, hi = np.array(robot_default.limits.lower), np.array(robot_default.limits.upper)
    Q = rng.uniform(np.maximum(lo, -3.0), np.minimum(hi, 3.0), size=(40, 4))
    T = np.array([robot_default.tool_pose(q) for q in Q]).tolist()
    src, dst = tmp_path / "in.csv", tmp_path / "out.csv"
    # mm and degrees in the file, columns in another order, an extra column
    lines = ["yaw,id,x,y,z"] + [f"{math.degrees(t[3])!r},{i},{t[0] * 1e3!r},{t[1] * 1e3!r},{t[2] * 1e3!r}"
                                for i, t in enumerate(T)]  # fmt: skip
    src.write_text("\n".join(lines + ["0,99,5000,0,0"]) + "\n", encoding="utf-8")  # + one out of reach
    scale = (1e3, 1e3, 1e3, 180 / math.pi)
    q_scale = (180 / math.pi, 180 / math.pi, 1e3, 180 / math.pi)
    summary = solve_csv(robot_default, src, dst, pose_scale=scale, q_scale=q_scale)
    assert (summary.total, summary.failed, summary.solved) == (41, 1, 40)
    with dst.open(encoding="utf-8") as f:
        rows = list(csv.DictReader(f))
    assert tuple(rows[0].keys()) == OUTPUT_COLUMNS and len(rows) == 41
    for t, row in zip(np.array(T), rows):
        assert row["status"] == "OK"
        q = np.array([float(row[f"q{j}"]) for j in range(1, 5)]) / np.array(q_scale)
        p = np.array(robot_default.tool_pose(q))
        assert np.abs(p[:3] - t[:3]).max() <= 1e-9 and abs(math.remainder(p[3] - t[3], 2 * math.pi)) <= 1e-9
    assert rows[-1]["status"] == "OUT_OF_REACH" and rows[-1]["q1"] == "" and rows[-1]["branch"] == ""


def test_solve_csv_refusals(robot_default: Robot, tmp_path: Path) -> None:
    src, dst = tmp_path / "in.csv", tmp_path / "out.csv"
    src.write_text("x,y,z,yaw\n0.3,0.1,-0.07,0.2\n", encoding="utf-8")
    with pytest.raises(InvalidInputError, match="not a branch"):
        solve_csv(robot_default, src, dst, branch="up")
    src.write_text("x,y,z,yaw\n0.3,0.1,-0.07,0.2\n0.3,oops,0,0\n", encoding="utf-8")
    with pytest.raises(InvalidInputError, match="line 3"):
        solve_csv(robot_default, src, dst)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["in.csv"]  # nothing written, no temporary left

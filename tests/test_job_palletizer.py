"""The palletizer stacks 2 layers of 3 boxes from a conveyor (issue 28, Must hold): docs/examples/palletizer/.

``scara-pin job docs/examples/palletizer/job.yaml --json --out job.csv --rate 10000 --plot --html`` is run once;
then, by independent routes:

- the clearance: coal called HERE at every 10 kHz row of the CSV, on Pinocchio's collision model of the robot
  (``buildGeomFromUrdfString`` on ``robot.urdf``), the cell file's boxes read here with ``yaml.safe_load``, the
  carried box from the job file's ``carry`` (while the JSON's step says the tool holds it) and the boxes placed so
  far rebuilt from the ``--json`` steps' ``box`` (their shape, centre and rpy): no link and no carried box comes
  closer than the margin to a placed box or another obstacle (not the package's Scene: a broad phase of bounding
  spheres against the boxes, exact for every pair it cannot clear, then coal's distance);
- where the boxes are: the pallet's grid written here from the taught ends S1, S3 (1 row of 3, 2 layers 0.16 m
  apart), the box hanging 0.095 m below tool0 (z down);
- the time: each jump planned alone (``jump_move`` between the same configurations, no cell: the boxes never bind
  in this cell, 20 mm apart) and the grips' 0.1 s; the boxes per hour are 6 boxes over that total, printed;
- the picture and the page: the figure's two views and the page's data (each box shown from its place's end,
  the part on the tool while held), then the page in Chromium.
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import coal
import numpy as np
import pinocchio as pin
import pytest
import yaml

from scara_pin import load_robot
from scara_pin.cli import main
from scara_pin.job import Job
from scara_pin.motion.jump import jump_move

EXAMPLE = Path(__file__).resolve().parent.parent / "docs" / "examples" / "palletizer"
RATE = 10_000.0
GRIP = 0.1  # [s] each pick and place of the example
DISTANCE_TOL = 1e-6  # [m] the "margin - 1e-6"


@pytest.fixture(scope="module")
def robot() -> Any:
    return load_robot("palletizer")


@pytest.fixture(scope="module")
def run(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    """The example planned once: its JSON, its 10 kHz CSV, its figure and page; the table printed from the same plan."""
    out = tmp_path_factory.mktemp("palletizer")
    planned: dict[Path, Any] = {}
    original = Job.plan

    def plan_once(self: Job, robot: Any, **kwargs: Any) -> Any:  # the table's run reuses the JSON's plan
        if self.path not in planned:
            planned[self.path] = original(self, robot, **kwargs)
        return planned[self.path]

    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(Job, "plan", plan_once)
        argv = ["job", str(EXAMPLE / "job.yaml"), "--out", str(out / "job.csv"), "--rate", str(RATE), "--plot",
                str(out / "job.png"), "--html", str(out / "job.html")]  # fmt: skip
        import contextlib
        import io

        text = io.StringIO()
        with contextlib.redirect_stdout(text):
            assert main([*argv, "--json"]) == 0
        data = json.loads(text.getvalue())
        table = io.StringIO()
        with contextlib.redirect_stdout(table):
            assert main(["job", str(EXAMPLE / "job.yaml")]) == 0
    return {"json": data, "table": table.getvalue(), "csv": out / "job.csv", "png": out / "job.png",
            "html": out / "job.html"}  # fmt: skip


# ---------------------------------------------------------------------------------------------- geometry, here
def _box(size: list[float], xyz: list[float], rpy: list[float]) -> tuple[Any, pin.SE3, np.ndarray]:
    """(coal box, its placement in the base frame, its half sizes)."""
    return coal.Box(*size), pin.SE3(pin.rpy.rpyToMatrix(*rpy), np.array(xyz, dtype=float)), np.array(size) / 2.0


def _radius(geometry: Any) -> float:
    """The radius of a sphere around a link's shape, about its centre."""
    if isinstance(geometry, coal.Box):
        return float(np.linalg.norm(geometry.halfSide))
    if isinstance(geometry, coal.Cylinder):
        return math.hypot(geometry.radius, geometry.halfLength)
    raise AssertionError(f"unexpected collision shape {type(geometry).__name__}")


def _to_box(centres: np.ndarray, M: pin.SE3, half: np.ndarray) -> np.ndarray:
    """Distances of points to a solid box (0 inside): a lower bound for any shape around them."""
    local = (centres - M.translation) @ M.rotation
    return np.linalg.norm(np.maximum(np.abs(local) - half, 0.0), axis=-1)


def independent_clearance(data: dict[str, Any], csv: Path, robot: Any, folder: Path = EXAMPLE
                          ) -> tuple[float, str, float, int, float]:  # fmt: skip
    """(smallest distance [m], its pair, its time [s], exact distances computed, the margin) over every 10 kHz row.

    Every link's collision shape (Pinocchio, from ``robot.urdf``) and, while a move holds it, the carried box
    (the job file's ``carry``) against the cell file's boxes and each box placed so far (the JSON's place steps),
    each read here; coal's distance for every pair a sphere around the shape does not clear by 10 mm.
    """
    cell = yaml.safe_load((folder / "cell.yaml").read_text())
    job = yaml.safe_load((folder / "job.yaml").read_text())
    margin = float(cell["margin"])
    obstacles = [(o["name"], *_box(o["size"], o["xyz"], o.get("rpy", [0, 0, 0]))) for o in cell["obstacles"]]
    steps = data["steps"]
    placed_by_step = {s["index"]: s["box"] for s in steps if s["kind"] == "place"}
    assert len(placed_by_step) == 6
    rows = np.loadtxt(csv, delimiter=",", skiprows=1)
    t, q = rows[:, 0], rows[:, 1:5]
    assert len(t) >= data["total"] * RATE and np.allclose(np.diff(t), 1.0 / RATE, atol=1e-9)  # every 10 kHz row
    # the step of each row: [t_start, t_end), the last one closed
    starts = np.array([s["t_start"] for s in steps])
    k = np.clip(np.searchsorted(starts, t, side="right") - 1, 0, len(steps) - 1)
    # the robot's collision geometry, by Pinocchio from its URDF; the tool frame for the carried box
    model = robot.model
    gm = pin.buildGeomFromUrdfString(model, robot.urdf, pin.GeometryType.COLLISION)
    gd, md = gm.createData(), model.createData()
    base = model.getFrameId("base")
    tool = model.getFrameId("tool0")
    pin.framesForwardKinematics(model, md, pin.neutral(model))
    oMb = md.oMf[base].copy()
    carry = job["carry"]
    carried_geometry = coal.Box(*carry["size"])
    tMc = pin.SE3(np.eye(3), np.array(carry["xyz"], dtype=float))
    links = [(o.name, o.geometry, _radius(o.geometry)) for o in gm.geometryObjects]
    names = [name for name, _, _ in links] + ["carried"]
    radii = np.array([r for _, _, r in links] + [float(np.linalg.norm(carried_geometry.halfSide))])
    n = len(t)

    def placements(qi: np.ndarray) -> list[pin.SE3]:
        """Every link's shape and the carried box, placed in the base frame at qi."""
        pin.updateGeometryPlacements(model, md, gm, gd, qi)  # forward kinematics too
        pin.updateFramePlacement(model, md, tool)
        return [oMb.actInv(gd.oMg[g]) for g in range(gm.ngeoms)] + [oMb.actInv(md.oMf[tool]) * tMc]

    centres = np.empty((n, len(names), 3))
    for i in range(n):
        centres[i] = [M.translation for M in placements(q[i])]
    carrying = np.array([s["carrying"] for s in steps])[k] & np.isin(np.array([s["kind"] for s in steps])[k],
                                                                     ["jump", "move", "go"])  # fmt: skip
    index = np.array([s["index"] for s in steps])[k]
    # the pairs a sphere around the shape cannot clear, by row: (shape, obstacle's name, coal box, its placement)
    near: dict[int, list[tuple[int, str, Any, pin.SE3]]] = {}
    for step_index, box in [(0, None), *sorted(placed_by_step.items())]:  # the obstacles, then each box once placed
        if box is None:
            targets, rows_in = obstacles, np.ones(n, dtype=bool)
        else:
            targets = [(box["name"], *_box([box["x"], box["y"], box["z"]], box["xyz"], box["rpy"]))]
            rows_in = index > step_index  # the steps after its place
        for name, geometry, M, half in targets:
            for g in range(len(names)):
                sel = rows_in & carrying if g == len(names) - 1 else rows_in
                lower = _to_box(centres[:, g], M, half) - radii[g]
                for i in np.nonzero(sel & (lower < margin + 0.01))[0]:
                    near.setdefault(int(i), []).append((g, name, geometry, M))
    request = coal.DistanceRequest()
    request.gjk_tolerance = request.epa_tolerance = 1e-10
    worst = (math.inf, "", 0.0)
    exact = 0
    for i, pairs in near.items():
        here = placements(q[i])
        for g, name, geometry, M in pairs:
            shape = carried_geometry if g == len(names) - 1 else links[g][1]
            d = coal.distance(shape, coal.Transform3s(here[g].rotation, here[g].translation), geometry,
                              coal.Transform3s(M.rotation, M.translation), request, coal.DistanceResult())  # fmt: skip
            exact += 1
            if d < worst[0]:
                worst = (d, f"{names[g]} - {name}", float(t[i]))
    return worst[0], worst[1], worst[2], exact, margin


def test_no_link_and_no_carried_box_comes_closer_than_the_margin_at_10_khz(run: dict[str, Any], robot: Any) -> None:
    data = run["json"]
    distance, pair, when, exact, margin = independent_clearance(data, run["csv"], robot)
    worst = (distance, pair, when)
    assert exact > 1000  # the boxes come near: the check is not vacuous
    assert worst[0] >= margin - DISTANCE_TOL, worst
    # the package's own figure for the same motion says no less (its closest pair, from the 10 kHz verifier)
    assert data["closest"]["distance"] <= worst[0] + 1e-6, (data["closest"], worst)


def test_the_boxes_are_left_where_the_pallet_s_places_are(run: dict[str, Any]) -> None:
    boxes = run["json"]["boxes"]
    points = {p["name"]: p["pose"] for p in yaml.safe_load((EXAMPLE / "points.yaml").read_text())["points"]}
    s1, s3 = np.array(points["S1"][:3]), np.array(points["S3"][:3])
    expected = []
    for layer in range(2):  # 1 row of 3 (S1 to S3), 2 layers 0.16 m apart; the box's centre 0.095 m below tool0
        for c in range(3):
            p = s1 + c / 2.0 * (s3 - s1) + np.array([0.0, 0.0, 0.16 * layer - 0.095])
            expected.append(p)
    assert [b["name"] for b in boxes] == [f"box{i}" for i in range(1, 7)]
    assert [b["at"] for b in boxes] == [f"stack[{i}]" for i in range(1, 7)]
    assert np.allclose([b["xyz"] for b in boxes], expected, atol=1e-9)
    assert all((b["x"], b["y"], b["z"]) == (0.2, 0.3, 0.15) for b in boxes)
    steps = run["json"]["steps"]
    for b in boxes:  # a box is left at the end of its place step; the moves after it count it
        step = steps[b["step"] - 1]
        assert step["kind"] == "place" and step["box"]["name"] == b["name"] and b["time"] == step["t_end"]
    assert [s["boxes_placed"] for s in steps if s["kind"] == "jump"] == [0, 1, 1, 2, 2, 3, 3, 4, 4, 5, 5, 6]
    assert [s["carrying"] for s in steps if s["kind"] == "jump"] == [True, False] * 6


def test_the_job_takes_its_jumps_alone_and_the_grips_and_prints_the_boxes_per_hour(run: dict[str, Any],
                                                                                  robot: Any) -> None:  # fmt: skip
    data = run["json"]
    jumps = [s for s in data["steps"] if s["kind"] == "jump"]
    alone = []
    for there, back in zip(jumps[0::2], jumps[1::2]):  # each jump to the stack planned alone: same q, no cell
        qA = np.array(data["steps"][there["index"] - 2]["q"])
        qB = np.array(there["q"])
        assert np.array_equal(qB, data["steps"][back["index"] - 2]["q"]) and np.array_equal(qA, back["q"])
        move = jump_move(robot, robot.tool_pose(qA), robot.tool_pose(qB), start=qA, end=qB, torque=False)
        # the way back is the same jump reversed (minimum time under symmetric limits is symmetric in time)
        for s in (there, back):
            assert abs(s["duration"] - move.duration) <= 1e-6, (s["target"], s["duration"], move.duration)
        alone += [move.duration, move.duration]
    total = sum(alone) + 12 * GRIP
    assert abs(data["total"] - total) <= 12e-6
    per_hour = 6 * 3600.0 / total
    assert abs(data["boxes_per_hour"] - per_hour) <= 1e-3
    table = run["table"]
    assert f"boxes     6 placed, {data['boxes_per_hour']:,.1f} boxes per hour" in table, table
    assert f"{per_hour:,.0f}" in f"{data['boxes_per_hour']:,.0f}"
    assert "closest carried - box" in table or "closest " in table


def test_the_picture_and_the_page_show_the_cell_and_the_growing_stack(run: dict[str, Any], page: Any) -> None:
    from PIL import Image

    assert Image.open(run["png"]).size[1] > Image.open(run["png"]).size[0]  # the two views above the timeline
    html = run["html"].read_text()
    start = html.index('id="scara-data">') + len('id="scara-data">')
    data = json.loads(html[start : html.index("</script>", start)])
    shown = {s["path"].split("/")[-1]: s["spans"] for s in data["motion"]["shown"]}
    boxes = run["json"]["boxes"]
    T = run["json"]["total"]
    for b in boxes:
        assert shown[b["name"]] == [[b["time"], T + 1.0]]
    held = [[s["t_start"], s["t_end"]] for s in run["json"]["steps"] if s["kind"] in ("pick", "jump", "place")
            and (s["carrying"] or s["kind"] == "place")]  # fmt: skip
    assert shown["cell_carried"] == [[held[i][0], held[i + 2][1]] for i in range(0, len(held), 3)]
    # in Chromium: each box appears once placed, the part rides on the tool while held
    page.goto(run["html"].as_uri())
    page.evaluate("window.scaraPlayer.pause()")

    def visible(t: float) -> dict[str, bool]:
        page.evaluate(f"window.scaraPlayer.seek({t!r})")
        return page.evaluate("""() => Object.fromEntries(
            JSON.parse(document.getElementById('scara-data').textContent).motion.shown.map(
                s => [s.path.split('/').pop(), viewer.scene_tree.find(s.path.split('/')).object.visible]))""")

    middle_of_second_jump = (run["json"]["steps"][5]["t_start"] + run["json"]["steps"][5]["t_end"]) / 2.0
    seen = visible(middle_of_second_jump)  # carrying box2 to stack[2]: box1 stands
    assert seen == {"box1": True, **{f"box{i}": False for i in range(2, 7)}, "cell_carried": True}
    seen = visible(T - 0.01)  # back at the conveyor, empty: the six boxes stand
    assert seen == {**{f"box{i}": True for i in range(1, 7)}, "cell_carried": False}
    assert page.errors == []

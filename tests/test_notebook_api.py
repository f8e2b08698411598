"""The Python API as a notebook user meets it (issue 22, item 5): a robot's repr and HTML table, real
docstrings on every public callable (help(robot.ik_nearest) included), named batch codes, the inline 3-D
view, and the tour notebook run in a real Jupyter kernel."""

from __future__ import annotations

import importlib
import inspect
import json
import math
import pkgutil
import pydoc
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import scara_pin
from scara_pin import ParameterError, load_robot
from scara_pin.ik_results import BatchBranch
from scara_pin.kinematics.palletizer import PalletizerIKStatus
from scara_pin.kinematics.scara_geometry import IKStatus

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def robot():  # type: ignore[no-untyped-def]
    return load_robot("default")


# ------------------------------------------------------------------------------------ repr and _repr_html_
def test_repr_is_a_table_of_joints_and_limits(robot) -> None:  # type: ignore[no-untyped-def]
    text = repr(robot)
    head, *lines = text.splitlines()
    # the default robot's zero pose: l1 + l2 = 400 mm along x, tool0 50 mm below the base (docs/robots.md)
    assert head == "Robot 'default': scara, 4 joints, tool0 in base; tool0 at q = 0: (400, 0, -50) mm, yaw 0 deg"
    assert lines[0].split() == ["#", "joint", "type", "lower", "upper", "velocity", "acceleration", "effort"]
    rows = [line.split() for line in lines[1:]]
    assert [r[1:3] for r in rows] == [["joint1", "revolute"], ["joint2", "revolute"], ["joint3", "prismatic"],
                                      ["joint4", "revolute"]]  # fmt: skip
    lim = robot.limits
    for i, r in enumerate(rows):
        angle = r[2] != "prismatic"
        scale, unit = (180 / math.pi, "deg") if angle else (1000.0, "mm")
        assert (r[4], r[6], r[8], r[10]) == (unit, unit, f"{unit}/s", f"{unit}/s²")
        for value, si in ((r[3], lim.lower[i]), (r[5], lim.upper[i]), (r[7], lim.velocity[i]),
                          (r[9], lim.acceleration[i])):  # fmt: skip
            assert float(value) == pytest.approx(si * scale, abs=5e-4)  # printed to 0.001
        assert float(r[11]) == pytest.approx(lim.effort[i], abs=5e-4) and r[12] == ("N·m" if angle else "N")


def test_repr_html_is_a_table(robot) -> None:  # type: ignore[no-untyped-def]
    page = robot._repr_html_()
    assert page.count("<tr>") == 1 + 4 and "<th>acceleration</th>" in page and "&#x27;default&#x27;" in page


def test_repr_of_a_urdf_file_says_what_it_does_not_know(tmp_path: Path) -> None:
    from scara_pin.description import generate_urdf

    path = tmp_path / "arm.urdf"
    path.write_text(generate_urdf("default"))
    text = repr(load_robot(urdf=str(path)))
    assert text.count("unknown") == 4  # URDF has no acceleration limits


# ------------------------------------------------------------------------------------ docstrings
def _public_modules() -> list[str]:
    names = []
    for info in pkgutil.walk_packages(scara_pin.__path__, "scara_pin."):
        if not any(part.startswith("_") for part in info.name.split(".")[1:]):
            names.append(info.name)
    return names


def test_every_public_callable_has_a_docstring() -> None:
    missing = []
    for name in _public_modules():
        module = importlib.import_module(name)
        if not inspect.getdoc(module):
            missing.append(name)
        for attr, obj in vars(module).items():
            if attr.startswith("_") or getattr(obj, "__module__", None) != name:
                continue
            if inspect.isfunction(obj) or inspect.isclass(obj):
                if not (obj.__doc__ or "").strip():
                    missing.append(f"{name}.{attr}")
            if inspect.isclass(obj):
                for meth, fn in vars(obj).items():
                    fn = fn.fget if isinstance(fn, property) else fn
                    fn = getattr(fn, "func", fn)  # cached_property
                    if meth.startswith("_") or not inspect.isfunction(fn):
                        continue
                    if not inspect.getdoc(getattr(obj, meth, fn)) and not (fn.__doc__ or "").strip():
                        missing.append(f"{name}.{attr}.{meth}")
    assert missing == []


def test_help_of_the_per_call_paths_is_their_own(robot) -> None:  # type: ignore[no-untyped-def]
    """``help(robot.ik_nearest)`` printed functools.partial's docstring; now the solver's own."""
    page = pydoc.render_doc(robot.ik_nearest, renderer=pydoc.plaintext)
    assert "The one solution nearest to ``reference``" in page and "partial" not in page
    assert str(inspect.signature(robot.ik_nearest)).startswith("(target")
    for attr in ("tool_placement", "task_jacobian", "ik", "ik_batch"):
        assert len(inspect.getdoc(getattr(robot, attr)) or "") > 40, attr
    pal = load_robot("palletizer")
    assert "nearest" in (inspect.getdoc(pal.ik_nearest) or "")


# ------------------------------------------------------------------------------------ batch codes
def test_batch_status_and_branch_are_named(robot) -> None:  # type: ignore[no-untyped-def]
    T = np.array([[0.3, 0.1, -0.1, 0.5], [5.0, 0.0, -0.1, 0.0], [0.2, -0.25, -0.06, 1.0]])
    res = robot.ik_batch(T)
    assert res.statuses() == [IKStatus.OK, IKStatus.OUT_OF_REACH, IKStatus.OK]  # 5 m is beyond l1 + l2 = 0.4 m
    assert res.ok.tolist() == [True, False, True] and res.counts() == {"OK": 2, "OUT_OF_REACH": 1}
    labels = res.branch_labels()
    # the documented convention: right = elbow turning counterclockwise seen from above, q2 > 0 here
    for i in (0, 2):
        assert labels[i] == ("right" if res.q[i, 1] > 0 else "left")
        assert res.branch[i] == (BatchBranch.FIRST if labels[i] == "right" else BatchBranch.SECOND)
    assert labels[1] == "" and res.branch[1] == BatchBranch.NONE
    assert repr(res) == f"BatchIKResult(3 targets: OK 2, OUT_OF_REACH 1; branches right {labels.count('right')}, " \
        f"left {labels.count('left')})"  # fmt: skip
    pal = load_robot("palletizer")
    res = pal.ik_batch(np.array([[1.5, 0.0, 1.5, 0.0], [9.0, 0.0, 0.0, 0.0]]))
    assert res.statuses()[1] == PalletizerIKStatus.OUT_OF_REACH and res.branch_labels()[0] in ("up", "down")


# ------------------------------------------------------------------------------------ inline 3-D view
def test_show_is_an_inline_self_contained_page(robot) -> None:  # type: ignore[no-untyped-def]
    from scara_pin.motion.trajectory import quintic
    from scara_pin.viz import SceneView, show

    view = show(robot, [0.3, 0.5, 0.02, 0.1], workspace=True, height=320)
    assert isinstance(view, SceneView)
    cell = view._repr_html_()
    assert cell.startswith('<iframe srcdoc="&lt;!DOCTYPE html&gt;') and "height: 320px" in cell
    assert '"q":[0.3,0.5,0.02,0.1]' in view.html and "http://" not in view.html.split("<script")[0]
    moving = show(robot, trajectory=quintic(np.zeros(4), np.array([0.5, 0.5, 0.05, 1.0]), 1.0))
    assert '"motion":' in moving.html
    with pytest.raises(ParameterError):
        show(robot, height=10)
    with pytest.raises(ParameterError):
        show(robot, [0.0, 0.0, math.nan, 0.0])


def test_importing_viz_imports_neither_meshcat_nor_matplotlib() -> None:
    code = "import sys, scara_pin.viz; print(sorted(m for m in ('meshcat', 'matplotlib') if m in sys.modules))"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0 and out.stdout.strip() == "[]", out.stderr


# ------------------------------------------------------------------------------------ the tour notebook
def test_the_tour_notebook_runs_in_a_jupyter_kernel() -> None:
    """docs/tour.ipynb, executed cell by cell in a real IPython kernel (nbclient), as a reader would run it."""
    import nbformat
    from nbclient import NotebookClient

    path = ROOT / "docs" / "tour.ipynb"
    nb = nbformat.read(path, as_version=4)
    assert all(not cell.get("outputs") for cell in nb.cells if cell.cell_type == "code")  # stored clean
    NotebookClient(nb, timeout=120, kernel_name="python3", resources={"metadata": {"path": str(ROOT / "docs")}}
                   ).execute()  # fmt: skip
    outputs = [o for cell in nb.cells if cell.cell_type == "code" for o in cell.outputs]
    assert not [o for o in outputs if o.output_type == "error"]
    html = [o["data"]["text/html"] for o in outputs if "text/html" in o.get("data", {})]
    assert any("<table>" in h for h in html)  # the robot's table
    assert any(h.startswith("<iframe srcdoc=") for h in html)  # the inline 3-D view
    assert sum("image/png" in o.get("data", {}) for o in outputs) >= 2  # the trajectory and workspace figures
    text = "".join(o.get("text", "") + json.dumps(o.get("data", {}).get("text/plain", "")) for o in outputs)
    assert re.search(r"array\(\[", text)  # FK and IK answers printed
    # the cell and the job (issue 34): the 3-D view names the post and the points; the job's table, short; a
    # variant with the tray moved plans only the moves to and from the places that moved
    assert sum(h.startswith("<iframe srcdoc=") for h in html) >= 2 and any("post" in h and "T11" in h for h in html)
    assert re.search(r"total     2\.\d+ s: 2 places, [\d,.]+ parts per hour", text)
    assert "2 moves planned, 2 jumps reversed, 0 repeated, 1 from the cache" in text  # the way home from the cache

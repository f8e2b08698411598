"""Golden URDFs: the URDF generated for each shipped robot must match ``tests/data/<robot>.urdf``.

The comparison is semantic, not textual: both documents are parsed with ``xml.etree`` (comments and
layout whitespace ignored) and compared element by element, in order: tag, attribute names, attribute
values and text. A value whose whitespace-separated tokens all parse as floats (``xyz="0 0 0.4"``,
``value="9.0"``) is compared number by number at ``ABS_TOL`` = 1e-12; any other value as a string.
Every difference is reported with the path of its element, e.g.
``/robot[@name='default']/joint[@name='joint2']/origin @xyz: token 0: 0.200000001 != 0.2``.

Refreshing the golden files, after a deliberate change of the description (review the diff!):

    SCARA_PIN_UPDATE_GOLDEN=1 .venv/bin/python -m pytest -q tests/test_golden.py

rewrites ``tests/data/<robot>.urdf`` from ``generate_urdf(robot)`` and skips the comparison.
"""

from __future__ import annotations

import os
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

from scara_pin import generate_urdf

DATA = Path(__file__).resolve().parent / "data"
GOLDEN_ROBOTS = ["default", "s1", "palletizer"]
ABS_TOL = 1e-12
UPDATE_ENV = "SCARA_PIN_UPDATE_GOLDEN"


def _floats(text: str) -> list[float] | None:
    """The numbers of a value made only of numbers, else ``None`` (an empty value is not numeric)."""
    tokens = text.split()
    if not tokens:
        return None
    try:
        return [float(t) for t in tokens]
    except ValueError:
        return None


def _compare_values(where: str, actual: str, expected: str) -> list[str]:
    a, e = _floats(actual), _floats(expected)
    if a is None or e is None:
        if a is None and e is None and " ".join(actual.split()) == " ".join(expected.split()):
            return []
        return [f"{where}: {actual!r} != {expected!r}"]
    if len(a) != len(e):
        return [f"{where}: {len(a)} numbers {actual!r} != {len(e)} numbers {expected!r}"]
    return [
        f"{where}: token {i}: {x!r} != {y!r} (|diff| = {abs(x - y):.3g} > {ABS_TOL:g})"
        for i, (x, y) in enumerate(zip(a, e))
        if not abs(x - y) <= ABS_TOL  # `not <=` also flags NaN
    ]


def _label(element: ET.Element) -> str:
    name = element.get("name")
    return f"{element.tag}[@name={name!r}]" if name is not None else element.tag


def compare_elements(actual: ET.Element, expected: ET.Element, here: str | None = None) -> list[str]:
    """All semantic differences between two element trees, each naming the element's path.

    ``here`` is the path of ``expected`` (``/robot[@name='default']`` for a root); children are labelled
    by tag and name, with ``#n`` for the n-th repeat of a label among siblings (the 2nd ``visual`` is
    ``visual#1``).
    """
    if here is None:
        here = f"/{_label(expected)}"
    if actual.tag != expected.tag:
        return [f"{here}: tag <{actual.tag}> != <{expected.tag}>"]
    diffs: list[str] = []
    a_keys, e_keys = set(actual.attrib), set(expected.attrib)
    if a_keys != e_keys:
        diffs.append(
            f"{here}: attributes differ: extra {sorted(a_keys - e_keys)}, missing {sorted(e_keys - a_keys)}"
        )
    for key in sorted(a_keys & e_keys):
        diffs += _compare_values(f"{here} @{key}", actual.attrib[key], expected.attrib[key])
    a_text, e_text = (actual.text or "").strip(), (expected.text or "").strip()
    if a_text or e_text:
        diffs += _compare_values(f"{here} text", a_text, e_text)
    a_children, e_children = list(actual), list(expected)
    if len(a_children) != len(e_children):
        diffs.append(
            f"{here}: {len(a_children)} children {[_label(c) for c in a_children]} != "
            f"{len(e_children)} children {[_label(c) for c in e_children]}"
        )
    # children are compared in order; a same-sized mismatch shows up as tag/name differences
    seen: dict[str, int] = {}
    for a, e in zip(a_children, e_children):
        label = _label(e)
        n = seen.get(label, 0)
        seen[label] = n + 1
        diffs += compare_elements(a, e, f"{here}/{label}" + (f"#{n}" if n else ""))
    return diffs


def compare_urdf(actual: str, expected: str) -> list[str]:
    """Semantic differences between two URDF documents (comments and whitespace ignored)."""
    return compare_elements(ET.fromstring(actual), ET.fromstring(expected))


def _golden_path(robot: str) -> Path:
    return DATA / f"{robot}.urdf"


@pytest.mark.parametrize("robot", GOLDEN_ROBOTS)
def test_generated_urdf_matches_golden(robot: str) -> None:
    generated = generate_urdf(robot)
    path = _golden_path(robot)
    if os.environ.get(UPDATE_ENV) == "1":
        path.write_text(generated, encoding="utf-8")
        pytest.skip(f"{UPDATE_ENV}=1: rewrote {path}")
    assert path.is_file(), f"missing golden file {path}; create it with {UPDATE_ENV}=1"
    diffs = compare_urdf(generated, path.read_text(encoding="utf-8"))
    assert not diffs, f"generate_urdf({robot!r}) differs from {path.name}:\n" + "\n".join(diffs)


# ---------------------------------------------------------------------------- the comparison can fail
def test_compare_detects_a_changed_length() -> None:
    """l1 changed by 1e-9 m: the joint2 origin and link1's drawing move; the report names joint2's origin."""
    golden = _golden_path("default").read_text(encoding="utf-8")
    diffs = compare_urdf(generate_urdf("default", {"l1": 0.200 + 1e-9}), golden)
    joint2 = "/robot[@name='default']/joint[@name='joint2']/origin @xyz: token 0: 0.200000001 != 0.2"
    assert any(d.startswith(joint2) for d in diffs), diffs
    assert all("link1" in d or "joint2" in d for d in diffs), diffs  # nothing else changed


def test_compare_detects_small_edits_and_tolerates_rounding() -> None:
    base = (
        '<robot name="r"><!-- c --><joint name="j" type="fixed"><origin xyz="0 0 0.4" rpy="0 0 0"/></joint></robot>'
    )
    assert compare_urdf(base, base) == []
    # layout, comments and number spelling do not matter
    same = (
        '<robot name="r">\n  <joint type="fixed" name="j">\n'
        '    <origin rpy="0.0 0 0e0"  xyz="0 0 4e-1"/>\n  </joint>\n</robot>'
    )
    assert compare_urdf(same, base) == []
    assert compare_urdf(base.replace("0.4", "0.4000000000001"), base) == []  # 1e-13 < ABS_TOL
    cases = {
        "0 0 0.400000000002": "/robot[@name='r']/joint[@name='j']/origin @xyz: token 2:",  # 2e-12 > ABS_TOL
        "0 0": "/robot[@name='r']/joint[@name='j']/origin @xyz: 2 numbers",
        "0 0 nan": "/robot[@name='r']/joint[@name='j']/origin @xyz: token 2:",
        "0 0 x": "/robot[@name='r']/joint[@name='j']/origin @xyz: '0 0 x' != '0 0 0.4'",
    }
    for xyz, expected in cases.items():
        diffs = compare_urdf(base.replace("0 0 0.4", xyz), base)
        assert len(diffs) == 1 and diffs[0].startswith(expected), (xyz, diffs)
    assert compare_urdf(base.replace('type="fixed"', 'type="revolute"'), base) == [
        "/robot[@name='r']/joint[@name='j'] @type: 'revolute' != 'fixed'"
    ]
    assert "attributes differ" in compare_urdf(base.replace(' rpy="0 0 0"', ""), base)[0]
    assert "children" in compare_urdf(base.replace("<origin", "<axis/><origin"), base)[0]
    tag_diff = compare_urdf(base.replace("origin", "axis"), base)
    assert tag_diff == ["/robot[@name='r']/joint[@name='j']/origin: tag <axis> != <origin>"], tag_diff

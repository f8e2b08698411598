"""The one yaml loader (scara_pin.description.yaml_units) reads unit tags exactly as xacro's load_yaml does."""

from __future__ import annotations

import json
import math
import re
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from scara_pin.description.yaml_units import load_yaml, unit_tags, yaml_line
from scara_pin.errors import YamlError

TEXT = textwrap.dedent("""
    a: !radians 0.25
    b: !degrees 132
    c: !meters 1.5
    d: !millimeters 200
    e: !foot 3
    f: !inches -7.5
    nested: {g: !degrees -45.5, h: [!millimeters 1e3, 2]}
    plain: 0.1
""")


def test_same_values_as_xacro_load_yaml(tmp_path: Path) -> None:
    """xacro's own load_yaml (run in a subprocess: it registers its tags on PyYAML's global SafeLoader)."""
    path = tmp_path / "units.yaml"
    path.write_text(TEXT, encoding="utf-8")
    code = f"import json, xacro; xacro.init_stacks(None); print(json.dumps(xacro.load_yaml({str(path)!r})))"
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert proc.returncode == 0, proc.stderr
    assert load_yaml(TEXT) == json.loads(proc.stdout)  # exact: the same float products
    # and the SI values, written here
    expected = {"a": 0.25, "b": 132 * math.pi / 180, "c": 1.5, "d": 0.2, "e": 3 * 0.3048, "f": -7.5 * 0.0254}
    data = load_yaml(TEXT)
    for key, value in expected.items():
        assert data[key] == pytest.approx(value, rel=1e-15)
    assert set(unit_tags()) == {"!radians", "!degrees", "!meters", "!millimeters", "!foot", "!inches"}


def test_tagged_text_is_never_evaluated() -> None:
    """xacro would evaluate ``90/2``; here it stays text for the caller to refuse (no user string is run)."""
    assert load_yaml("a: !degrees 90/2\nb: !millimeters __import__('os')") == {
        "a": "!degrees 90/2", "b": "!millimeters __import__('os')"}  # fmt: skip


def test_safe_loader_only() -> None:
    with pytest.raises(YamlError, match="not valid YAML .*python/object"):
        load_yaml("a: !!python/object/apply:os.system ['true']")
    # PyYAML's own SafeLoader is left untouched (xacro's load_yaml changes it: checked in a fresh process)
    code = ("import yaml; from scara_pin.description.yaml_units import load_yaml; load_yaml('a: !degrees 1'); "
            "print('!degrees' in yaml.SafeLoader.yaml_constructors)")
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert (proc.returncode, proc.stdout.strip()) == (0, "False"), proc.stderr


# ------------------------------------------------------------------------ issue 30 item 1: bounded, with lines
def _bomb(levels: int = 9, width: int = 9) -> str:
    """The issue's alias bomb: ``&a`` a list of 9 strings, each next level 9 aliases of the previous (9^9 leaves)."""
    text = "[&a [" + ", ".join(['"lol"'] * width) + "]"
    for prev, name in zip("abcdefgh"[: levels - 1], "bcdefghi"[: levels - 1]):
        text += f", &{name} [" + ", ".join([f"*{prev}"] * width) + "]"
    return text + "]"


def test_the_alias_bomb_is_refused_at_once() -> None:
    import time

    text = f"q: {_bomb()}\n"
    assert len(text) < 600  # the 520 bytes
    start = time.monotonic()
    with pytest.raises(YamlError, match=r"^bomb\.yaml line 1: .*more than 500,000 values .*the cap$") as info:
        load_yaml(text, "bomb.yaml")
    assert time.monotonic() - start < 2.0 and info.value.refused and info.value.line == 1


@pytest.mark.parametrize(("cap", "ok"), [(11, True), (10, False)])
def test_an_alias_counts_as_all_it_stands_for(cap: int, ok: bool, monkeypatch: pytest.MonkeyPatch) -> None:
    """Counted here: the mapping 1, key a 1, the list 1 and its 3 items, key b 1, the alias 1 + 3 = 11 values."""
    import scara_pin.description.yaml_units as units

    monkeypatch.setattr(units, "MAX_YAML_NODES", cap)
    text = "a: &x [1, 2, 3]\nb: *x\n"
    if ok:
        assert load_yaml(text) == {"a": [1, 2, 3], "b": [1, 2, 3]}
    else:
        with pytest.raises(YamlError, match="line 2: the document holds more than 10 values"):
            load_yaml(text)


@pytest.mark.parametrize(
    ("text", "words"),
    [
        ("a: &a {x: 1}\n" + "".join(f"{c}: &{c} {{<<: [{', '.join(['*' + p] * 9)}]}}\n"
                                    for p, c in zip("abcdefgh", "bcdefghi")), "more than 500,000 values"),
        ("a: &a [1, *a]\n", "inside its own anchor"),
        ("a: &a {b: *a}\n", "inside its own anchor"),
        ("a: " + "[" * 65 + "]" * 65 + "\n", "more than 64 levels"),
        ("a: *nowhere\n", "not valid YAML (found undefined alias"),
        ("a: !!int 0x1f\n", "not valid YAML (int '0x1f' is not a plain number"),
        ("a: !!timestamp 2001-13-45\n", "a value cannot be read"),
    ],
    ids=["merge-bomb", "recursive-list", "recursive-map", "deep", "undefined-alias", "tagged-hex", "bad-date"],
)
def test_other_documents_that_lie(text: str, words: str) -> None:
    with pytest.raises(YamlError, match=re.escape(words)):
        load_yaml(text, "f.yaml")


def test_numbers_follow_the_command_line_grammar() -> None:
    """YAML 1.1's other spellings of numbers stay text (the readers refuse them naming the item); the grammar's
    numbers are read as Python reads them, 1e-05 too (YAML 1.1 reads it as text: a points file written with
    repr() did not read back)."""
    data = load_yaml("[0x1, 0b0, 0_1, '0:0.5', 0:0.5, 0o7, 1_000.5, +.5e1, 1e-05, -3, +2, .5, 3., 1E+3, "
                     "123456789012345678, 1234567890123456789, .inf, -.Inf, .nan, 2001-12-14, !degrees 1_0]")
    assert data[:7] == ["0x1", "0b0", "0_1", "0:0.5", "0:0.5", "0o7", "1_000.5"]
    assert data[7:13] == [5.0, 1e-05, -3, 2, 0.5, 3.0] and all(type(v) is float for v in (data[7], data[8], data[12]))
    assert type(data[9]) is int and data[13] == 1000.0
    assert data[14] == 123456789012345678 and type(data[14]) is int
    assert data[15] == 1.234567890123456789e18 and type(data[15]) is float  # past 18 digits: a float
    assert data[16] == math.inf and data[17] == -math.inf and math.isnan(data[18])
    assert data[19] == "2001-12-14" and data[20] == "!degrees 1_0"
    assert load_yaml("a: " + "1" * 5000) == {"a": math.inf}  # not Python's 4300-digit error


def test_lines_of_the_data() -> None:
    text = textwrap.dedent("""\
        # a comment
        robot: s1
        points:
        - name: P1
          q: [0.1,
              0.2]
        - {name: P2, q: [1, 2]}
    """)
    data = load_yaml(text)
    assert yaml_line(data) == 2 and yaml_line(data, "robot") == 2 and yaml_line(data, "points") == 4
    points = data["points"]
    assert yaml_line(points, 0) == 4 and yaml_line(points, 1) == 7
    assert yaml_line(points[0], "q") == 5 and yaml_line(points[0]["q"], 1) == 6 and yaml_line(points[1], "q") == 7
    assert yaml_line(data, "missing") is None and yaml_line({"a": 1}, "a") is None and yaml_line(3) is None
    assert json.loads(json.dumps(data)) == data  # plain data: dicts and lists


def test_a_big_value_in_a_message_is_shown_briefly() -> None:
    """Under the cap, a value may still be large: a message shows only its start (never the whole value)."""
    from scara_pin.errors import ParameterError, brief

    big = load_yaml("[" + ", ".join(["[1, 2, 3, 4, 5, 6, 7, 8]"] * 5_000) + "]")
    for text in (brief(big), str(ParameterError("q", big, "must be 4 numbers"))):
        assert len(text) <= 120 and text.count("[") >= 2, text
    assert "..." in brief("x" * 1000) and len(brief("x" * 1000)) <= 60

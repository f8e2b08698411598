"""The one yaml loader (scara_pin.description.yaml_units) reads unit tags exactly as xacro's load_yaml does."""

from __future__ import annotations

import json
import math
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from scara_pin.description.yaml_units import load_yaml, unit_tags

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
    import yaml

    with pytest.raises(yaml.YAMLError):
        load_yaml("a: !!python/object/apply:os.system ['true']")
    # PyYAML's own SafeLoader is left untouched (xacro's load_yaml changes it: checked in a fresh process)
    code = ("import yaml; from scara_pin.description.yaml_units import load_yaml; load_yaml('a: !degrees 1'); "
            "print('!degrees' in yaml.SafeLoader.yaml_constructors)")
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert (proc.returncode, proc.stdout.strip()) == (0, "False"), proc.stderr

"""The description cache (scara_pin.description.cache): what it gives back is what generation makes.

Every expected value comes from making the robot without the cache (``SCARA_PIN_NO_CACHE=1``, or the
generator called directly), never from the cache itself.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from scara_pin import load_robot, urdf_dir
from scara_pin.description import configured, generate_urdf, load_parameters
from scara_pin.description.cache import DescriptionCache


@pytest.fixture
def cache_dir(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    folder = tmp_path / "cache"
    monkeypatch.setenv("SCARA_PIN_CACHE_DIR", str(folder))
    monkeypatch.delenv("SCARA_PIN_NO_CACHE", raising=False)
    return folder


@pytest.mark.parametrize("name", ["default", "s1", "palletizer"])
def test_a_hit_is_what_generation_makes(name: str, cache_dir: Path) -> None:
    fresh = generate_urdf(load_parameters(name))
    first = configured(name)  # made, then kept
    assert len(list(cache_dir.glob("*.json"))) == 1
    second = configured(name)  # from the file
    assert first[1] == second[1] == fresh
    assert dict(second[0].values) == dict(load_parameters(name).values) and second[0].kind == first[0].kind


def test_overrides_are_part_of_the_key(cache_dir: Path) -> None:
    a = configured("default", {"l1": 0.25})
    b = configured("default", {"l1": "0.26"})
    assert a[1] != b[1] and len(list(cache_dir.glob("*.json"))) == 2
    assert b[1] == generate_urdf(load_parameters("default", {"l1": 0.26})) and b[0]["l1"] == 0.26


def test_an_edited_yaml_is_a_new_key(tmp_path: Path, cache_dir: Path) -> None:
    folder = tmp_path / "mine"
    shutil.copytree(urdf_dir() / "config" / "default", folder)
    before = configured(folder)
    kin = folder / "kinematics.yaml"
    kin.write_text(kin.read_text().replace("l1: 0.200", "l1: 0.230"))
    after = configured(folder)
    assert after[0]["l1"] == 0.23 and before[0]["l1"] == 0.2
    assert after[1] == generate_urdf(load_parameters(folder)) != before[1]


def test_a_broken_cache_file_is_made_again(cache_dir: Path) -> None:
    params, urdf = configured("s1")
    (entry,) = cache_dir.glob("*.json")
    for junk in ("not json", json.dumps({"kind": "scara", "values": {"l1": -1.0}, "urdf": "<robot/>"}), "[]"):
        entry.write_text(junk)
        again = configured("s1")
        assert again[1] == urdf and dict(again[0].values) == dict(params.values)


def test_an_unwritable_cache_folder_is_no_error(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    blocker = tmp_path / "file"
    blocker.write_text("")
    monkeypatch.setenv("SCARA_PIN_CACHE_DIR", str(blocker / "cache"))  # below a file: cannot be created
    assert load_robot("default").tool_pose([0, 0, 0, 0]).tolist() == pytest.approx([0.4, 0.0, -0.05, 0.0])


def test_no_cache_turns_it_off(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("SCARA_PIN_CACHE_DIR", str(tmp_path / "c"))
    monkeypatch.setenv("SCARA_PIN_NO_CACHE", "1")
    assert DescriptionCache.default().folder is None
    configured("default")
    assert not (tmp_path / "c").exists()


def test_fk_on_a_hit_imports_neither_yaml_nor_xacro(cache_dir: Path) -> None:
    """The point of the cache: `scara-pin fk` starts without PyYAML and xacro once the robot is kept."""
    code = textwrap.dedent("""
        import io, contextlib, sys
        from scara_pin.cli import main
        with contextlib.redirect_stdout(io.StringIO()) as out:
            rc = main(["fk", "--json", "0.1", "0.2", "0.05", "0.3"])
        print(rc, "yaml" in sys.modules, "xacro" in sys.modules, out.getvalue().strip())
    """)
    env = {**os.environ, "SCARA_PIN_CACHE_DIR": str(cache_dir)}
    runs = [subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, timeout=60,
                           check=True).stdout.split(" ", 3) for _ in range(2)]  # fmt: skip
    assert runs[0][:3] == ["0", "True", "True"]  # made (and kept)
    assert runs[1][:3] == ["0", "False", "False"]  # from the cache
    assert json.loads(runs[0][3]) == json.loads(runs[1][3])

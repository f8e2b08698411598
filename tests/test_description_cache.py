"""The description cache (scara_pin.description.cache): what it gives back is what generation makes.

Every expected value comes from making the robot without the cache (``SCARA_PIN_NO_CACHE=1``, or the
generator called directly), never from the cache itself.
"""

from __future__ import annotations

import hashlib
import json
import logging
import math
import os
import shutil
import stat
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


# ----------------------------------------------------------------------------- issue 30 item 5: entries that lie
def _fk_xy(q1: float, q2: float) -> tuple[float, float]:
    """The default robot's tool (x, y) from its URDF numbers: l1 = l2 = 0.2 m (the test's own FK)."""
    return 0.2 * math.cos(q1) + 0.2 * math.cos(q1 + q2), 0.2 * math.sin(q1) + 0.2 * math.sin(q1 + q2)


def _tamper(entry: Path) -> None:
    """The issue's tampered entry: l1 = 0.3 in the parameters and in the URDF (valid JSON, a valid robot)."""
    text = entry.read_text()
    header, body = text.split("\n", 1)
    data = json.loads(body)
    data["values"]["l1"] = 0.3
    data["urdf"] = data["urdf"].replace('xyz="0.2 0 0.0"', 'xyz="0.3 0 0.0"', 1)  # joint2's origin: l1
    assert data["urdf"] != json.loads(body)["urdf"]
    entry.write_text(header + "\n" + json.dumps(data))


def test_a_tampered_entry_is_made_again_with_one_warning(cache_dir: Path) -> None:
    """`fk` answered 0.4896 instead of 0.3901 from a tampered entry; now the digest does not match: one warning,
    the true answer, the entry replaced (the next run is quiet)."""
    code = ("import sys; from scara_pin.cli import main; sys.exit(main(['fk', '--json', '0.1', '0.2', '0', '0']))")
    env = {**os.environ, "SCARA_PIN_CACHE_DIR": str(cache_dir)}

    def fk() -> tuple[list[float], str]:
        p = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, timeout=60)
        assert p.returncode == 0, p.stderr
        return json.loads(p.stdout)["position"], p.stderr

    x, y = _fk_xy(0.1, 0.2)
    assert fk()[0][:2] == pytest.approx([x, y], abs=1e-12) and round(x, 4) == 0.3901
    (entry,) = cache_dir.glob("*.json")
    _tamper(entry)
    position, err = fk()
    assert position[:2] == pytest.approx([x, y], abs=1e-12)
    assert err.count("\n") == 1 and err.startswith("warning: description cache entry") and "digest" in err, err
    assert fk() == (position, "")  # replaced: quiet again


def test_a_link_in_the_cache_folder_is_never_followed(cache_dir: Path, tmp_path: Path,
                                                      caplog: pytest.LogCaptureFixture) -> None:  # fmt: skip
    """Even to a file whose digest matches (written for that key, elsewhere): the link is refused and replaced."""
    params, urdf = configured("default")
    (entry,) = cache_dir.glob("*.json")
    _tamper(entry)
    text = entry.read_text()
    header, body = text.split("\n", 1)
    key = entry.stem
    digest = hashlib.sha256(key.encode() + b"\0" + body.encode()).hexdigest()  # the attacker's own digest
    outside = tmp_path / "outside.json"
    outside.write_text(header.split("=")[0] + "=" + digest + "\n" + body)
    entry.unlink()
    entry.symlink_to(outside)
    with caplog.at_level(logging.WARNING, logger="scara_pin"):
        again = configured("default")
    assert again[1] == urdf and dict(again[0].values) == dict(params.values)
    assert [r.getMessage() for r in caplog.records if "symbolic link" in r.getMessage()], caplog.text
    assert not entry.is_symlink() and outside.read_text().endswith(body)  # replaced; the target never written


def test_entries_are_the_users_alone(cache_dir: Path) -> None:
    cache_dir.mkdir(mode=0o755)
    os.chmod(cache_dir, 0o755)
    configured("s1")
    (entry,) = cache_dir.glob("*.json")
    assert stat.S_IMODE(os.stat(cache_dir).st_mode) == 0o700 and stat.S_IMODE(os.stat(entry).st_mode) == 0o600
    assert not [p for p in cache_dir.iterdir() if p != entry]  # written atomically: no temporary file left


def test_an_entry_renamed_to_another_key_does_not_match(cache_dir: Path, caplog: pytest.LogCaptureFixture) -> None:
    configured("s1")
    configured("default")
    s1, default = (DescriptionCache(cache_dir).key(name, folder, texts, {}, urdf_dir())
                   for name, folder, texts in _keys(("s1", "default")))  # fmt: skip
    (cache_dir / f"{s1}.json").replace(cache_dir / f"{default}.json")  # s1's entry under default's key
    with caplog.at_level(logging.WARNING, logger="scara_pin"):
        params, urdf = configured("default")
    assert params.name == "default" and urdf == generate_urdf(load_parameters("default"))
    assert "does not match its digest" in caplog.text


def _keys(names: tuple[str, ...]) -> list[tuple[str, Path, dict[str, str]]]:
    folder = urdf_dir() / "config"
    files = ("kinematics.yaml", "joint_limits.yaml", "physical_parameters.yaml")
    return [(n, folder / n, {f: (folder / n / f).read_text(encoding="utf-8") for f in files}) for n in names]


@pytest.mark.skipif(not hasattr(os, "getuid") or os.getuid() != 0, reason="giving the folder away needs root")
def test_a_folder_of_another_user_is_not_used(cache_dir: Path, caplog: pytest.LogCaptureFixture) -> None:
    cache_dir.mkdir(mode=0o700)
    os.chown(cache_dir, 12345, -1)
    with caplog.at_level(logging.WARNING, logger="scara_pin"):
        configured("s1")
    assert not list(cache_dir.iterdir()) and "not the user's" in caplog.text

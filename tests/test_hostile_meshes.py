"""The hostile-input matrix of issue 24 for meshes (and issue 21's mesh units): files a package names are input.

One ``view --html`` runs over a robot carrying every hostile mesh at once (each on its own visual), in a
subprocess under the address-space limit of ``test_hostile.py`` and a timeout, its peak memory measured;
each row is a test of what that run did with its mesh. The fixtures are made by the tests: FIFOs, a
sparse 2 GiB material file, a 2 GiB zip bomb built in memory (2 MB on disk), a gzip bomb, Latin-1 STL and
OBJ text, millimetre COLLADA files, 200 visuals naming one STL.

Expected values come from the fixtures' own numbers (the boxes written in millimetres, the robot's link
lengths from its yaml), read back from the page's embedded float32 vertices.
"""

from __future__ import annotations

import base64
import importlib.metadata
import io
import itertools
import os
import re
import struct
import subprocess
import sys
import time
import zipfile
import zlib
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from test_hostile import _env, _limited

from scara_pin import load_robot
from scara_pin.cell import meshes
from scara_pin.cell.meshes import visual_meshes
from scara_pin.cli import main
from scara_pin.description import generate_urdf
from scara_pin.limits import MAX_MESH_BYTES, MAX_VISUALS
from scara_pin.robots import Robot

PKG = "hostile_meshes"
TIMEOUT = 60.0
GIB = 1 << 30
MIB = 1 << 20
RSS_CAP_KB = 1_000_000
"""Peak resident memory of one ``view`` [KiB]: the page, the robot and one decompressed mesh (200 MiB) fit;
inflating the 2 GiB bomb would not (before issue 24: 3.3 GB)."""

# The child writes its peak memory (ru_maxrss, KiB) to $HOSTILE_RSS after main() returns; $HOSTILE_PRELUDE is
# Python run first (the signal tests replace a trimesh reader with one that blocks and swallows).
RUN_MEASURED = (
    "import os, resource, sys\n"
    "exec(os.environ.get('HOSTILE_PRELUDE', ''))\n"
    "from scara_pin.cli import main\n"
    "code = main(sys.argv[1:])\n"
    "open(os.environ['HOSTILE_RSS'], 'w').write(str(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss))\n"
    "sys.exit(code)\n"
)


@dataclass
class Run:
    code: int
    out: str
    err: str
    seconds: float
    rss_kb: int


def run_measured(args: list[str], cwd: Path, timeout: float = TIMEOUT) -> Run:
    """``scara-pin ARGS`` in a subprocess under test_hostile's limits, with its peak memory."""
    rss = cwd / ".rss"
    env = {**_env(), "HOSTILE_RSS": str(rss)}
    start = time.monotonic()
    p = subprocess.run([sys.executable, "-c", RUN_MEASURED, *args], cwd=cwd, capture_output=True, text=True,
                       timeout=timeout, preexec_fn=_limited, env=env, stdin=subprocess.DEVNULL)  # fmt: skip
    seconds = time.monotonic() - start
    kb = int(rss.read_text()) if rss.exists() else -1
    rss.unlink(missing_ok=True)
    return Run(p.returncode, p.stdout, p.stderr, seconds, kb)


# --------------------------------------------------------------------------------------------- fixtures
BOX_FACES = ((0, 1, 3), (0, 3, 2), (4, 6, 7), (4, 7, 5), (0, 4, 5), (0, 5, 1),
             (2, 3, 7), (2, 7, 6), (0, 2, 6), (0, 6, 4), (1, 5, 7), (1, 7, 3))  # fmt: skip
"""The 12 triangles of the box whose corners are itertools.product((0, x), (0, y), (0, z)), outward."""


def box_corners(size: tuple[float, float, float]) -> list[tuple[float, ...]]:
    return list(itertools.product(*[(0.0, float(s)) for s in size]))


def collada_box(size: tuple[float, float, float], unit: float | None = None) -> bytes:
    """A COLLADA 1.4.1 document of a box of ``size`` (in the file's units), written by hand."""
    unit_xml = f'<unit meter="{unit!r}" name="u"/>' if unit is not None else ""
    values = " ".join(f"{v!r}" for corner in box_corners(size) for v in corner)
    indices = " ".join(str(i) for face in BOX_FACES for i in face)
    return f"""<?xml version="1.0" encoding="utf-8"?>
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
  <asset>{unit_xml}<up_axis>Z_UP</up_axis></asset>
  <library_geometries><geometry id="box"><mesh>
    <source id="p"><float_array id="pa" count="24">{values}</float_array>
      <technique_common><accessor source="#pa" count="8" stride="3"><param name="X" type="float"/>
      <param name="Y" type="float"/><param name="Z" type="float"/></accessor></technique_common></source>
    <vertices id="v"><input semantic="POSITION" source="#p"/></vertices>
    <triangles count="12"><input semantic="VERTEX" source="#v" offset="0"/><p>{indices}</p></triangles>
  </mesh></geometry></library_geometries>
  <library_visual_scenes><visual_scene id="s"><node id="n"><instance_geometry url="#box"/></node></visual_scene>
  </library_visual_scenes>
  <scene><instance_visual_scene url="#s"/></scene>
</COLLADA>
""".encode()


def ascii_stl(size: tuple[float, float, float], name: bytes) -> bytes:
    corners = box_corners(size)
    facets = b"".join(b"facet normal 0 0 0\nouter loop\n"
                      + b"".join(b"vertex %r %r %r\n" % tuple(corners[i]) for i in face)
                      + b"endloop\nendfacet\n" for face in BOX_FACES)  # fmt: skip
    return b"solid " + name + b"\n" + facets + b"endsolid " + name + b"\n"


def obj_box(size: tuple[float, float, float], head: bytes = b"") -> bytes:
    corners = box_corners(size)
    return (head + b"".join(b"v %r %r %r\n" % tuple(c) for c in corners)
            + b"".join(b"f %d %d %d\n" % tuple(i + 1 for i in face) for face in BOX_FACES))  # fmt: skip


def zip_bomb(total: int) -> bytes:
    """A zip archive holding ``bomb.dae``: ``total`` zero bytes, deflated (about 1 KB per MiB).

    Built in memory from one deflated MiB repeated: a full flush makes each copy independent of the last.
    """
    mib = bytes(MIB)
    packer = zlib.compressobj(9, zlib.DEFLATED, -15)
    chunk = packer.compress(mib) + packer.flush(zlib.Z_FULL_FLUSH)
    data = chunk * (total // MIB) + b"\x03\x00"  # the final empty fixed block
    crc = 0
    for _ in range(total // MIB):
        crc = zlib.crc32(mib, crc)
    name = b"bomb.dae"
    local = struct.pack("<IHHHHHIIIHH", 0x04034B50, 20, 0, 8, 0, 0, crc, len(data), total, len(name), 0) + name
    central = struct.pack("<IHHHHHHIIIHHHHHII", 0x02014B50, 20, 20, 0, 8, 0, 0, crc, len(data), total, len(name),
                          0, 0, 0, 0, 0, 0) + name  # fmt: skip
    end = struct.pack("<IHHHHIIH", 0x06054B50, 0, 0, 1, 1, len(central), len(local) + len(data), 0)
    return local + data + central + end


def gzip_bomb(total: int) -> bytes:
    """A gzip stream of ``total`` zero bytes (deflated as :func:`zip_bomb`)."""
    mib = bytes(MIB)
    packer = zlib.compressobj(9, zlib.DEFLATED, -15)
    chunk = packer.compress(mib) + packer.flush(zlib.Z_FULL_FLUSH)
    crc = 0
    for _ in range(total // MIB):
        crc = zlib.crc32(mib, crc)
    header = b"\x1f\x8b\x08\x00\x00\x00\x00\x00\x00\xff"
    return header + chunk * (total // MIB) + b"\x03\x00" + struct.pack("<II", crc, total & 0xFFFFFFFF)


def write_package(folder: Path, visuals: dict[str, str]) -> Path:
    """A package ``hostile_meshes`` at ``folder`` whose urdf/robot.urdf is the default robot with ``visuals``
    (link -> <visual> XML) put first in those links; returns the URDF's path."""
    (folder / "urdf").mkdir(parents=True, exist_ok=True)
    (folder / "package.xml").write_text(f"<package><name>{PKG}</name></package>")
    text = generate_urdf("default")
    for link, xml in visuals.items():
        if f'<link name="{link}"/>' in text:
            text = text.replace(f'<link name="{link}"/>', f'<link name="{link}">{xml}</link>', 1)
        else:
            assert f'<link name="{link}">' in text, link
            text = text.replace(f'<link name="{link}">', f'<link name="{link}">{xml}', 1)
    path = folder / "urdf" / "robot.urdf"
    path.write_text(text)
    return path


def visual(name: str, scale: str | None = None) -> str:
    scaled = f' scale="{scale}"' if scale is not None else ""
    return f'<visual><geometry><mesh filename="package://{PKG}/meshes/{name}"{scaled}/></geometry></visual>'


def page_commands(text: str) -> list[dict[str, Any]]:
    """The commands a page replays (base64 msgpack strings, one per line), decoded."""
    import umsgpack

    return [umsgpack.unpackb(base64.b64decode(c)) for c in re.findall(r'^"([A-Za-z0-9+/=]+)",?$', text, re.M)]


def embedded(commands: list[dict[str, Any]], name: str) -> tuple[np.ndarray, np.ndarray] | None:
    """(float32 vertices as float64, the object's 4 x 4 matrix) of the mesh drawn for visual ``name`` (None:
    a placeholder box, or a shared stand-in)."""
    objects = [c for c in commands if c["type"] == "set_object" and c["path"].endswith(f"/visuals/{name}")]
    assert len(objects) == 1, (name, len(objects))
    lowered = objects[0]["object"]
    geometry = lowered["geometries"][0]
    if geometry["type"] != "BufferGeometry":
        return None
    position = geometry["data"]["attributes"]["position"]
    vertices = np.frombuffer(position["array"].data, dtype=np.float32).reshape(-1, 3).astype(float)
    matrix = np.array(lowered["object"]["matrix"]).reshape(4, 4).T  # column-major
    return vertices, matrix


def extent(vertices: np.ndarray, matrix: np.ndarray) -> np.ndarray:
    """(3,) extent of the vertices under the object's matrix [m]."""
    placed = vertices @ matrix[:3, :3].T + matrix[:3, 3]
    return placed.max(axis=0) - placed.min(axis=0)


# --------------------------------------------------------------------------------------------- the one run
L1 = load_robot("default").parameters["l1"]
LINK1_MM = (1000 * L1, 40.0, 30.0)
"""[mm] the millimetre COLLADA box on link1: as long as the link (l1 from the robot's yaml), 40 x 30 mm."""
ROWS = {  # visual name (link tool0, in this order) -> file
    "tool0_0": "fifo_mtl.obj",  # item 3: its mtllib is a FIFO
    "tool0_1": "fifo_texture.obj",  # item 3: its .mtl names a FIFO texture
    "tool0_2": "sparse_mtl.obj",  # item 5: its .mtl is a sparse 2 GiB file
    "tool0_3": "zip_bomb.dae",  # item 5: a 2 MB zip holding 2 GiB
    "tool0_4": "gzip_bomb.dae",  # item 5: a gzip stream of 256 MiB
    "tool0_5": "box.stl",  # item 10: scale 1e300
    "tool0_6": "latin1.stl",  # item 11: ASCII STL, Latin-1 name
    "tool0_7": "latin1.obj",  # item 11: OBJ with a Latin-1 comment and object name
    "tool0_8": "mm_no_unit.dae",  # issue 21 item 3: millimetres without a <unit>: implausible, warned
    "tool0_9": "mm.zae",  # a zipped COLLADA (.zae) named .dae: read
}


@dataclass
class Page:
    run: Run
    folder: Path
    commands: list[dict[str, Any]]
    size: int


@pytest.fixture(scope="module")
def hostile_page(tmp_path_factory: pytest.TempPathFactory) -> Page:
    folder = tmp_path_factory.mktemp("hostile_meshes")
    m = folder / "meshes"
    m.mkdir()
    os.mkfifo(m / "fifo.mtl")
    (m / "fifo_mtl.obj").write_bytes(obj_box((0.01, 0.02, 0.03), b"mtllib fifo.mtl\nusemtl red\n"))
    os.mkfifo(m / "fifo.png")
    (m / "texture.mtl").write_bytes(b"newmtl red\nKd 1 0 0\nmap_Kd fifo.png\n")
    (m / "fifo_texture.obj").write_bytes(obj_box((0.01, 0.02, 0.03), b"mtllib texture.mtl\nusemtl red\n"))
    with (m / "sparse.mtl").open("wb") as handle:
        handle.truncate(2 * GIB)
    (m / "sparse_mtl.obj").write_bytes(obj_box((0.01, 0.02, 0.03), b"mtllib sparse.mtl\nusemtl red\n"))
    (m / "zip_bomb.dae").write_bytes(zip_bomb(2 * GIB))
    (m / "gzip_bomb.dae").write_bytes(gzip_bomb(256 * MIB))
    (m / "box.stl").write_bytes(ascii_stl((0.01, 0.02, 0.03), b"box"))
    (m / "latin1.stl").write_bytes(ascii_stl((0.01, 0.02, 0.03), "pièce usinée".encode("latin-1")))
    (m / "latin1.obj").write_bytes(obj_box((0.01, 0.02, 0.03), "# pièce usinée\no pièce\n".encode("latin-1")))
    (m / "link1_mm.dae").write_bytes(collada_box(LINK1_MM, unit=0.001))
    (m / "mm_no_unit.dae").write_bytes(collada_box(LINK1_MM))
    archive = io.BytesIO()
    with zipfile.ZipFile(archive, "w", zipfile.ZIP_DEFLATED) as z:
        z.writestr("model/mm.dae", collada_box(LINK1_MM, unit=0.001))
    (m / "mm.zae").write_bytes(archive.getvalue())
    tool = "".join(visual(name, "1e300 1e300 1e300" if name == "box.stl" else None) for name in ROWS.values())
    urdf = write_package(folder, {"tool0": tool, "link1": visual("link1_mm.dae")})
    (folder / "v.html").write_text("old page")
    run = run_measured(["view", "--urdf", str(urdf), "--html", "v.html"], cwd=folder)
    text = (folder / "v.html").read_text()
    return Page(run, folder, page_commands(text) if run.code == 0 else [], len(text))


def warnings_naming(page: Page, name: str) -> list[str]:
    return [line for line in page.run.err.splitlines() if f"/meshes/{name}" in line]


def test_the_hostile_page_is_written_in_bounded_time_and_memory(hostile_page: Page) -> None:
    run = hostile_page.run
    assert run.code == 0, run.err[-2000:]
    assert "Traceback" not in run.err and "error" not in run.err
    lines = run.err.splitlines()
    assert all(line.startswith("warning: ") for line in lines), lines
    assert sorted(name for line in lines for name in ROWS.values() if f"/{name}'" in line) == sorted(
        ["zip_bomb.dae", "gzip_bomb.dae", "box.stl", "mm_no_unit.dae"]), lines  # one warning each, no more
    assert run.seconds < 30, run.seconds
    assert 0 < run.rss_kb < RSS_CAP_KB, run.rss_kb
    assert sorted(p.name for p in hostile_page.folder.iterdir()) == ["meshes", "package.xml", "urdf", "v.html"]


@pytest.mark.parametrize("name", ["tool0_0", "tool0_1", "tool0_2"])
def test_materials_and_textures_are_never_read(hostile_page: Page, name: str) -> None:
    """Items 3 and 5: a FIFO named by mtllib or map_Kd, a sparse 2 GiB .mtl: the OBJ is drawn (the URDF's
    colour), nothing blocks, nothing is read whole."""
    drawn = embedded(hostile_page.commands, name)
    assert drawn is not None
    np.testing.assert_allclose(extent(*drawn), [0.01, 0.02, 0.03], rtol=1e-6)
    assert warnings_naming(hostile_page, ROWS[name]) == []


@pytest.mark.parametrize(("name", "holds"), [("tool0_3", "2 GiB zip"), ("tool0_4", "256 MiB gzip")])
def test_an_archive_bomb_is_refused_after_the_cap_of_decompressed_bytes(hostile_page: Page, name: str,
                                                                       holds: str) -> None:  # fmt: skip
    """Item 5: at most MAX_MESH_BYTES are decompressed (the peak memory is bounded above); a placeholder."""
    assert embedded(hostile_page.commands, name) is None  # the placeholder box
    (line,) = warnings_naming(hostile_page, ROWS[name])
    assert f"more than {MAX_MESH_BYTES // MIB} MiB once decompressed" in line and "drawn as a 0.02 m box" in line


def test_a_scale_of_1e300_is_refused_with_its_geometry(hostile_page: Page) -> None:
    """Item 10: 1e300 x the vertices is infinite in float32: refused, one warning, the placeholder drawn."""
    assert embedded(hostile_page.commands, "tool0_5") is None
    (line,) = warnings_naming(hostile_page, "box.stl")
    assert "scale 1e+300" in line and "beyond 1e+06 m" in line and "link tool0 is drawn as a 0.02 m box" in line
    for command in hostile_page.commands:  # no infinite number anywhere in the page
        if command["type"] == "set_object" and command["object"]["geometries"]:
            assert np.isfinite(command["object"]["object"]["matrix"]).all()


@pytest.mark.parametrize("name", ["tool0_6", "tool0_7"])
def test_latin1_stl_and_obj_are_drawn(hostile_page: Page, name: str) -> None:
    """Item 11: CAD tools write Latin-1 names in ASCII STL and OBJ; trimesh decodes them with charset_normalizer."""
    drawn = embedded(hostile_page.commands, name)
    assert drawn is not None, hostile_page.run.err
    np.testing.assert_allclose(extent(*drawn), [0.01, 0.02, 0.03], rtol=1e-6)
    assert warnings_naming(hostile_page, ROWS[name]) == []


def test_charset_normalizer_is_declared() -> None:
    """Item 11: what trimesh needs at run time for those files is a dependency of scara-pin."""
    requires = importlib.metadata.requires("scara-pin") or []
    assert any(re.match(r"charset[-_]normalizer\b", r) and "extra ==" not in r for r in requires), requires


def test_a_millimetre_collada_mesh_is_as_long_as_its_link(hostile_page: Page) -> None:
    """Issue 21 item 3: <unit meter="0.001"> honoured: the vertices embedded in the page span l1 (0.2 m)."""
    drawn = embedded(hostile_page.commands, "link1_0")
    assert drawn is not None
    np.testing.assert_allclose(extent(*drawn), np.array(LINK1_MM) / 1000, rtol=1e-6)  # float32
    np.testing.assert_allclose(extent(*drawn)[0], L1, rtol=1e-6)  # the link's length, from the robot's yaml
    assert warnings_naming(hostile_page, "link1_mm.dae") == []


def test_a_zipped_collada_file_is_read(hostile_page: Page) -> None:
    drawn = embedded(hostile_page.commands, "tool0_9")
    assert drawn is not None
    np.testing.assert_allclose(extent(*drawn), np.array(LINK1_MM) / 1000, rtol=1e-6)


def test_a_millimetre_mesh_without_unit_is_drawn_with_a_warning(hostile_page: Page) -> None:
    """Issue 21 item 3: 200 m across on a robot of about half a metre: drawn as written, and said."""
    drawn = embedded(hostile_page.commands, "tool0_8")
    assert drawn is not None
    np.testing.assert_allclose(extent(*drawn), LINK1_MM, rtol=1e-6)
    (line,) = warnings_naming(hostile_page, "mm_no_unit.dae")
    assert "times the robot's size" in line and "check its units" in line and "drawn as it is" in line


# --------------------------------------------------------------------------------------------- item 6
VISUALS = 200


@pytest.fixture(scope="module")
def shared_page(tmp_path_factory: pytest.TempPathFactory) -> Page:
    """200 visuals naming one 3 MB binary STL (60,000 triangles, no shared vertex), half of them scaled."""
    import trimesh

    folder = tmp_path_factory.mktemp("shared_mesh")
    (folder / "meshes").mkdir()
    corners = np.random.default_rng(24).uniform(-0.05, 0.05, (60_000, 3, 3))
    trimesh.Trimesh(corners.reshape(-1, 3), np.arange(180_000).reshape(-1, 3), process=False).export(
        folder / "meshes" / "part.stl")  # fmt: skip
    tool = "".join(visual("part.stl", f"{1 + i % 3} 1 1" if i % 2 else None) for i in range(VISUALS))
    urdf = write_package(folder, {"tool0": tool})
    run = run_measured(["view", "--urdf", str(urdf), "--html", "v.html"], cwd=folder)
    text = (folder / "v.html").read_text() if run.code == 0 else ""
    return Page(run, folder, page_commands(text), len(text))


def test_a_mesh_named_by_200_visuals_is_read_and_embedded_once(shared_page: Page) -> None:
    run = shared_page.run
    assert run.code == 0 and run.err == "", run.err[-2000:]
    drawn = embedded(shared_page.commands, "tool0_0")
    assert drawn is not None and len(drawn[0]) == 180_000
    shares = [c for c in shared_page.commands if c["type"] == "scara_share_geometry"]
    assert len(shares) == VISUALS - 1
    first = next(c["path"] for c in shared_page.commands if c["path"].endswith("/visuals/tool0_0"))
    assert {c["source"] for c in shares} == {first}
    for i in range(1, VISUALS):  # the others hold a stand-in triangle and their own scale
        stand_in = embedded(shared_page.commands, f"tool0_{i}")
        assert stand_in is not None and len(stand_in[0]) == 3
        np.testing.assert_array_equal(np.diag(stand_in[1]), [1 + i % 3 if i % 2 else 1, 1, 1, 1])
    one_copy = 180_000 * 12 + 60_000 * 12  # float32 vertices + uint32 indices
    assert shared_page.size < 4 / 3 * one_copy + 3 * MIB  # base64 of one copy, the viewer script, the robot
    assert run.rss_kb < RSS_CAP_KB / 2 and run.seconds < 30, (run.rss_kb, run.seconds)


def test_the_page_shows_a_shared_mesh_on_every_visual(tmp_path: Path, page: Any) -> None:
    """In the browser: every visual's object holds the first one's geometry (one buffer), at its own scale."""
    from scara_pin.viz.meshcat import export_html

    (tmp_path / "meshes").mkdir()
    (tmp_path / "meshes" / "part.stl").write_bytes(ascii_stl((0.01, 0.02, 0.03), b"part"))
    n = 20
    scales = [1 + i % 3 if i % 2 else 1 for i in range(n)]
    urdf = write_package(tmp_path, {"tool0": "".join(visual("part.stl", f"{s} 1 1") for s in scales)})
    path = export_html(Robot.from_file(urdf), tmp_path / "v.html")
    page.goto(path.as_uri())
    page.wait_for_function("() => window.scaraSceneCommands > 0")
    found = page.evaluate("""(n) => {
        const objects = [];
        (function walk(node) {
            for (const [name, child] of Object.entries(node.children)) {
                if (/^tool0_\\d+$/.test(name)) objects[Number(name.slice(6))] = child.find(["<object>"]).object;
                walk(child);
            }
        })(viewer.scene_tree);
        const first = objects[0].geometry;
        return {
            count: objects.filter((o) => o !== undefined).length,
            shared: objects.filter((o) => o.geometry === first).length,
            vertices: first.attributes.position.count,
            scales: objects.map((o) => o.matrix.elements[0]),
        };
    }""", n)
    assert found["count"] == n and found["shared"] == n and found["vertices"] == 8
    assert found["scales"] == scales
    assert page.errors == []


def test_more_visuals_than_the_cap_is_refused_before_drawing(tmp_path: Path,
                                                            capsys: pytest.CaptureFixture[str]) -> None:  # fmt: skip
    boxes = '<visual><geometry><box size="0.01 0.01 0.01"/></geometry></visual>' * (MAX_VISUALS + 1)
    urdf = write_package(tmp_path, {"tool0": boxes})
    (tmp_path / "v.html").write_text("old page")
    assert main(["view", "--urdf", str(urdf), "--html", str(tmp_path / "v.html")]) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: visuals of the robot") and f"{MAX_VISUALS:,}" in err and len(err.splitlines()) == 1
    assert (tmp_path / "v.html").read_text() == "old page"


def test_the_triangles_kept_for_one_robot_are_capped(tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
                                                    caplog: pytest.LogCaptureFixture) -> None:  # fmt: skip
    """Two distinct meshes, a cap that holds one: the second is a warning and a placeholder."""
    m = tmp_path / "meshes"
    m.mkdir()
    (m / "a.stl").write_bytes(ascii_stl((0.01, 0.02, 0.03), b"a"))
    (m / "b.stl").write_bytes(ascii_stl((0.03, 0.02, 0.01), b"b"))
    urdf = write_package(tmp_path, {"tool0": visual("a.stl") + visual("b.stl") + visual("a.stl")})
    monkeypatch.setattr(meshes, "MAX_PAGE_MESH_BYTES", 8 * 12 + 12 * 12)  # one box: 8 vertices, 12 triangles
    found = visual_meshes(Robot.from_file(urdf))
    assert [v.name for v in found] == ["tool0_0", "tool0_2"] and found[0].geometry is found[1].geometry
    (record,) = caplog.records
    assert "b.stl" in record.getMessage() and "the cap" in record.getMessage()


def test_the_live_viewer_sends_copies_counted_against_the_cap(tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
                                                             caplog: pytest.LogCaptureFixture) -> None:  # fmt: skip
    """meshcat's server has no shared geometry: each visual gets a copy, and the copies count together."""
    import scara_pin.limits
    from scara_pin.viz.scene import MeshcatScene, draw_meshes
    from scara_pin.viz.window import Window

    (tmp_path / "meshes").mkdir()
    (tmp_path / "meshes" / "a.stl").write_bytes(ascii_stl((0.01, 0.02, 0.03), b"a"))
    robot = Robot.from_file(write_package(tmp_path, {"tool0": visual("a.stl") * 5}))
    scene = MeshcatScene(robot, Window())  # a recorded page: one copy, four shares
    assert len(scene.vis.window.recorder.shares) == 4
    monkeypatch.setattr(scara_pin.limits, "MAX_PAGE_MESH_BYTES", 3 * (8 * 12 + 12 * 12))  # three copies of the box
    window = Window()  # the meshes drawn again, as for the live server (the scene's node names)
    draw_meshes(type(scene.vis)(window=window), robot, scene.viz, share=False)
    copies = [p for p in window.recorder.objects if "/visuals/tool0_" in p]
    assert len(copies) == 3 and not window.recorder.shares
    (record,) = [r for r in caplog.records if "the cap" in r.getMessage()]
    assert "2 of its copies (links tool0)" in record.getMessage()

"""The package's layers as a picture (docs/layers.png) and as data the README's architecture section is checked with.

The layers are ``LAYERS`` of tests/test_architecture.py, lowest first: a module imports its own layer and those
below, never one above (that test enforces it). Each layer holds top-level modules and subpackages of
``scara_pin``; the picture stacks the layers, the lowest at the bottom, each with its modules and packages and
their line counts, the arrows of the imports pointing down. The table it is drawn from (the layers' titles and
names, with the counts) is written into the PNG's metadata (``Description``, JSON), so that a test can read the
committed picture back and compare it with the tree (tests/test_architecture.py).

Run from anywhere: ``python tools/layers.py`` writes docs/layers.png (``--out FILE`` writes elsewhere).
"""

from __future__ import annotations

import argparse
import importlib.util
import json
import re
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = ROOT / "scara_pin"
PICTURE = ROOT / "docs" / "layers.png"

TITLES = {
    "_typing": "foundations",
    "limits": "caps, files",
    "description": "description",
    "_checks": "checks, symbolic model",
    "model": "model",
    "kinematics": "kinematics",
    "calibration": "calibration",
    "cell": "cell",
    "workspace": "workspace, lint",
    "motion": "motion",
    "job": "job",
    "sweep": "sweep",
    "viz": "pictures",
    "robots": "facade",
    "cli": "command line",
    "__init__": "public surface",
}
"""Each layer's title, keyed by the first name of its tuple in ``LAYERS``."""


def load_layers() -> tuple[tuple[str, ...], ...]:
    """``LAYERS`` of tests/test_architecture.py (read from its file: the test owns the order)."""
    spec = importlib.util.spec_from_file_location("_architecture", ROOT / "tests" / "test_architecture.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module.LAYERS  # type: ignore[no-any-return]


def _lines(path: Path) -> int:
    files = sorted(path.rglob("*.py")) if path.is_dir() else [path]
    return sum(len(f.read_text(encoding="utf-8").splitlines()) for f in files)


def table(layers: tuple[tuple[str, ...], ...], package: Path = PACKAGE) -> list[dict[str, Any]]:
    """The layers present in the tree, lowest first: ``{"title", "names": [...], "lines": [...]}`` each.

    A name is a module (``model.py``) or a package (``motion/``) of ``package``; a name of ``layers`` the tree
    does not have is left out, and so is a layer left empty.

    Raises:
        KeyError: a layer without a title in :data:`TITLES`.
        ValueError: a module or package of the tree in no layer.
    """
    known = {name for layer in layers for name in layer}
    loose = sorted(p.name for p in package.iterdir() if (p.suffix == ".py" and p.stem not in known)
                   or (p.is_dir() and (p / "__init__.py").is_file() and p.name not in known))  # fmt: skip
    if loose:
        raise ValueError(f"in no layer of LAYERS: {', '.join(loose)}")
    out = []
    for layer in layers:
        names, lines = [], []
        for name in layer:
            for path, shown in ((package / f"{name}.py", f"{name}.py"), (package / name, f"{name}/")):
                if path.is_file() or (path / "__init__.py").is_file():
                    names.append(shown)
                    lines.append(_lines(path))
        if names:
            out.append({"title": TITLES[layer[0]], "names": names, "lines": lines})
    return out


def structure(rows: list[dict[str, Any]]) -> list[tuple[str, list[str]]]:
    """The layers' titles and names, without the line counts (which change with every edit)."""
    return [(row["title"], list(row["names"])) for row in rows]


def readme_layers(text: str) -> list[tuple[str, list[str]]]:
    """The layers the README's "Architecture" section lists: its table's rows, (title, the names in backticks).

    A row reads ``| 5 model | `model.py`, `chain.py` | what lives there |``, the lowest layer first.
    """
    start = text.index("\n## Architecture")
    section = text[start : text.find("\n## ", start + 1) if "\n## " in text[start + 1 :] else len(text)]
    out = []
    for line in section.splitlines():
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        match = re.fullmatch(r"\d+ (.+)", cells[0]) if len(cells) >= 3 else None
        if match:
            out.append((match[1], re.findall(r"`([^`]+)`", cells[1])))
    return out


def draw(rows: list[dict[str, Any]], path: Path) -> None:
    """The picture: the layers stacked, the lowest at the bottom, arrows pointing down; the table in its metadata."""
    import matplotlib

    matplotlib.use("Agg")
    from matplotlib.figure import Figure
    from matplotlib.patches import FancyArrowPatch, FancyBboxPatch

    n = len(rows)
    height = 0.62
    fig = Figure(figsize=(11.0, 0.9 + height * n))
    ax = fig.add_axes((0.0, 0.0, 1.0, 1.0))
    ax.set_xlim(0.0, 11.0)
    ax.set_ylim(-0.35, height * n + 0.45)
    ax.axis("off")
    for k, row in enumerate(rows):  # k = 0: the lowest layer, at the bottom
        y = k * height
        box = FancyBboxPatch((0.25, y + 0.06), 10.5, height - 0.2, boxstyle="round,pad=0.02,rounding_size=0.08",
                             facecolor="#e8eef7" if k % 2 else "#f6f1e7", edgecolor="#5a6472", lw=0.8)
        ax.add_patch(box)
        ax.text(0.4, y + height / 2 - 0.04, f"{k + 1}  {row['title']}", fontsize=10, fontweight="bold",
                va="center", ha="left", color="#1d232b")
        items = "   ".join(f"{name} {lines:,}" for name, lines in zip(row["names"], row["lines"], strict=True))
        ax.text(3.15, y + height / 2 - 0.04, items, fontsize=8.2, family="monospace", va="center", ha="left",
                color="#1d232b")
        if k:  # imports point down: from this layer to the one below
            ax.add_patch(FancyArrowPatch((1.9, y + 0.08), (1.9, y - 0.12), arrowstyle="-|>", mutation_scale=11,
                                         color="#5a6472", lw=1.0))
    ax.text(0.25, height * n + 0.2, "scara_pin, the lowest layer first, each module or package (name/) with its "
            "lines of Python: a module imports its own layer and those below, never one above", fontsize=9,
            color="#3a4450")
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110, metadata={"Description": json.dumps(rows)})


def picture_table(path: Path) -> list[dict[str, Any]]:
    """The table written into a picture made by :func:`draw` (its PNG metadata)."""
    from PIL import Image

    with Image.open(path) as image:
        return json.loads(image.info["Description"])  # type: ignore[no-any-return]


def main() -> None:
    """Write the picture of the tree's layers (docs/layers.png, or ``--out``)."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=PICTURE, help="the PNG to write (default docs/layers.png)")
    args = parser.parse_args()
    rows = table(load_layers())
    draw(rows, args.out)
    print(f"wrote {args.out}: {len(rows)} layers")


if __name__ == "__main__":
    main()

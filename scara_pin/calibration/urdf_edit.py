"""The calibrated URDF: the input's own text with the changed ``<origin>`` attributes, nothing else touched.

The text is edited, not regenerated: comments, formatting, meshes, inertias, limits and every element not
calibrated stay byte for byte as they were. Each calibrated joint's ``<origin>`` gets its new ``xyz`` and
(when its rotation changed) ``rpy``, each value written as ``repr(float)`` (the shortest text that reads
back as the same double); a joint without ``<origin>`` gets one. The edit is then verified: the edited
document parsed again must equal the input but for those attributes (else an internal error: a bug).
"""

from __future__ import annotations

import re
import xml.etree.ElementTree as ET
from collections.abc import Mapping

import numpy as np

__all__ = ["edit_origins", "triple_text"]

_COMMENT = re.compile(r"<!--.*?-->", re.S)
_JOINT = re.compile(r"<joint\b[^>]*\stype\s*=[^>]*>")  # a joint has a type; a <transmission>'s <joint> has none
_NAME = re.compile(r"""\sname\s*=\s*(?:"([^"]*)"|'([^']*)')""")
_ORIGIN = re.compile(r"<origin\b[^>]*?(/?)>")


def triple_text(values: np.ndarray) -> str:
    """Three numbers as URDF writes them: ``repr(float)`` each, ``-0.0`` as ``0.0``."""
    return " ".join(repr(float(v) + 0.0) for v in values)


def _inside(spans: list[tuple[int, int]], pos: int) -> bool:
    return any(a <= pos < b for a, b in spans)


def _set_attribute(tag: str, attr: str, value: str) -> str:
    pattern = re.compile(rf"""(\s){attr}\s*=\s*(?:"[^"]*"|'[^']*')""")
    if pattern.search(tag):
        return pattern.sub(lambda m: f'{m.group(1)}{attr}="{value}"', tag, count=1)
    end = len(tag) - (2 if tag.endswith("/>") else 1)
    return f'{tag[:end].rstrip()} {attr}="{value}"{tag[end:]}'


def edit_origins(urdf: str, origins: Mapping[str, tuple[np.ndarray | None, np.ndarray | None]]) -> str:
    """``urdf`` with the ``<origin>`` of each named joint set to (xyz, rpy); None leaves that attribute as it is.

    Raises:
        RuntimeError: a named joint is not in the document, or the verification fails (a bug).
    """
    text = urdf
    for name, (xyz, rpy) in origins.items():
        if xyz is None and rpy is None:
            continue
        comments = [m.span() for m in _COMMENT.finditer(text)]
        start = next((m for m in _JOINT.finditer(text) if not _inside(comments, m.start())
                      and (n := _NAME.search(m.group(0))) is not None and (n.group(1) or n.group(2) or "") == name),
                     None)  # fmt: skip
        if start is None:
            raise RuntimeError(f"joint {name!r} not found in the URDF text")
        end = text.find("</joint>", start.end())
        origin = next((m for m in _ORIGIN.finditer(text, start.end(), end) if not _inside(comments, m.start())), None)
        if origin is not None:
            tag = origin.group(0)
            if xyz is not None:
                tag = _set_attribute(tag, "xyz", triple_text(xyz))
            if rpy is not None:
                tag = _set_attribute(tag, "rpy", triple_text(rpy))
            text = text[: origin.start()] + tag + text[origin.end():]
        else:
            indent = re.match(r"\s*", text[start.end():end]).group(0)  # type: ignore[union-attr]
            xyz_text = triple_text(xyz if xyz is not None else np.zeros(3))
            rpy_text = triple_text(rpy if rpy is not None else np.zeros(3))
            text = text[: start.end()] + f'{indent}<origin xyz="{xyz_text}" rpy="{rpy_text}"/>' + text[start.end():]
    _verify(urdf, text, origins)
    return text


def _verify(before: str, after: str, origins: Mapping[str, tuple[np.ndarray | None, np.ndarray | None]]) -> None:
    """The edited document equals the input but for the edited origins, which read back as asked."""
    a, b = ET.fromstring(before), ET.fromstring(after)

    def same(x: ET.Element, y: ET.Element, joint: str | None) -> bool:
        if x.tag != y.tag or (x.text or "").strip() != (y.text or "").strip():
            return False
        ax, ay = dict(x.attrib), dict(y.attrib)
        if x.tag == "origin" and joint in origins:
            for attr in ("xyz", "rpy"):
                ax.pop(attr, None)
                ay.pop(attr, None)
        if ax != ay:
            return False
        kx, ky = list(x), list(y)
        if x.tag == "joint" and x.get("name") in origins and len(ky) == len(kx) + 1 and x.find("origin") is None:
            ky = [c for c in ky if c.tag != "origin"]
        name = x.get("name") if x.tag == "joint" else joint
        return len(kx) == len(ky) and all(same(c, d, name) for c, d in zip(kx, ky))

    if not same(a, b, None):
        raise RuntimeError("the calibrated URDF differs from the input beyond the calibrated origins (a bug)")
    for el in b.findall("joint"):
        name = el.get("name", "")
        if name not in origins:
            continue
        o = el.find("origin")
        for attr, want in zip(("xyz", "rpy"), origins[name]):
            if want is None:
                continue
            got = np.array([float(v) for v in (o.get(attr, "0 0 0") if o is not None else "0 0 0").split()])
            if not np.array_equal(got, np.asarray(want, dtype=float) + 0.0):
                raise RuntimeError(f"joint {name}'s calibrated {attr} did not read back (a bug)")

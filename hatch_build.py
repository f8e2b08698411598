"""Build hook: compile the optional C module ``scara_pin._speedups`` (the per-call hot paths).

Hatchling calls :class:`SpeedupsBuildHook` for every wheel, regular or editable:

- a regular wheel gets the compiled module inside ``scara_pin/`` and a platform tag;
- an editable install compiles it in place, next to ``scara_pin/_speedups.c`` (ignored by git), because the
  package is then imported from the source tree.

Without a working C compiler the build does not fail: it warns and builds a pure-Python wheel, and
scara_pin falls back to its Python implementations of the same functions (slower per call, same results).
Set ``SCARA_PIN_REQUIRE_SPEEDUPS=1`` to make a failed compilation an error instead (CI does).
"""

from __future__ import annotations

import os
import shutil
import sys
import tempfile
from pathlib import Path
from typing import Any

from hatchling.builders.hooks.plugin.interface import BuildHookInterface

SOURCE = Path("scara_pin") / "_speedups.c"
MODULE = "scara_pin._speedups"


class SpeedupsBuildHook(BuildHookInterface):
    """Compile scara_pin._speedups into the wheel (or in place for an editable install)."""

    PLUGIN_NAME = "custom"

    def initialize(self, version: str, build_data: dict[str, Any]) -> None:
        """Before the wheel is built: compile, and mark the wheel as platform-specific."""
        if self.target_name != "wheel":
            return
        root = Path(self.root)
        self._tmp = tempfile.mkdtemp(prefix="scara_pin_build_")  # kept until the wheel is written
        try:
            built = _compile(root, inplace=version == "editable", build_dir=Path(self._tmp))
        except Exception as exc:  # a missing compiler, headers, numpy: the package still works without it
            if os.environ.get("SCARA_PIN_REQUIRE_SPEEDUPS") == "1":
                raise
            print(f"warning: scara_pin._speedups not built ({type(exc).__name__}: {exc}); "
                  "using the pure-Python fallbacks", file=sys.stderr)  # fmt: skip
            return
        build_data["pure_python"] = False
        build_data["infer_tag"] = True
        if version != "editable":
            build_data["force_include"][str(built)] = f"scara_pin/{built.name}"

    def finalize(self, version: str, build_data: dict[str, Any], artifact_path: str) -> None:
        """After the wheel is written: remove the temporary build folder."""
        tmp = getattr(self, "_tmp", None)
        if tmp is not None:
            shutil.rmtree(tmp, ignore_errors=True)


def _compile(root: Path, *, inplace: bool, build_dir: Path) -> Path:
    """Compile the extension with setuptools' build_ext; return the path of the built module."""
    import numpy
    from setuptools import Distribution, Extension
    from setuptools.command.build_ext import build_ext

    ext = Extension(
        MODULE,
        [str(SOURCE)],
        include_dirs=[numpy.get_include()],
        # the same IEEE operations as the Python code: no fused multiply-add contraction
        extra_compile_args=["-O2", "-ffp-contract=off"] if os.name != "nt" else ["/O2", "/fp:precise"],
    )
    dist = Distribution({"name": "scara-pin", "ext_modules": [ext]})
    if inplace:  # a module left by an earlier build must not survive a failed one (scara_pin._fast checks too)
        for old in (root / "scara_pin").glob("_speedups.*"):
            if old.suffix in (".so", ".pyd"):
                old.unlink()
    cmd = build_ext(dist)
    cmd.inplace = inplace
    cmd.build_lib = str(build_dir / "lib")
    cmd.build_temp = str(build_dir / "temp")
    cmd.ensure_finalized()
    old = Path.cwd()
    os.chdir(root)  # build_ext resolves the source path and the in-place target from the project root
    try:
        cmd.run()
        return (root / cmd.get_ext_fullpath(MODULE)).resolve()
    finally:
        os.chdir(old)

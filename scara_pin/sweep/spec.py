"""A sweep's file: which job, which of its keys vary and over what, read and checked before any work.

```yaml
format: scara-pin sweep 1        # optional; checked when present
job: tray.yaml                   # relative to this file
vary:                            # every key a dotted key of the job file (docs/job.md, variants), or robot
  robot: [default, s1]           # names, configuration folders or URDF files
  base.xyz: {from: [-50, -50, 0], to: [50, 50, 0], steps: [5, 5, 1]}   # in the job file's units
  frames.tray.yaw: [0, 0.1]
  speed: [70, 100]
samples: 200                     # optional: a scrambled Sobol sequence over the ranges instead of their grid
seed: 0                          # optional: the Sobol sequence's scrambling seed (default 0)
timeout: 600                     # optional: [s] one variant's planning time limit (default none)
acceleration: [..]               # optional: the joint acceleration limits of URDF robots [rad/s^2, m/s^2]
```

A value list is taken as it is (each item a number, a name, or a list of numbers); a range ``{from, to, steps}``
is ``steps`` values evenly spaced from ``from`` to ``to`` (both ends included), each component of a vector on its
own (``steps`` one number per component, or one for all). The variants are the product of every key's values, in
the file's order of keys (the last key varies fastest). With ``samples: N`` the ranges are sampled instead: N
points of a scrambled Sobol sequence (``scipy.stats.qmc``, seeded) over every range component whose ends differ,
crossed with the lists. The count is known before any variant is made and refused above
:data:`~scara_pin.limits.MAX_SWEEP_VARIANTS`.

Each variant has a content key (:attr:`Variant.key`): a digest of what its plan depends on (the job's text, the
files it names by content: its points' bytes, its cell's shapes with a mesh's triangles, a varied file's each; the
robot's description; the values; the planner: this package's version and planning sources, the solvers' versions,
as the plan cache's). A rerun skips the keys already
answered (:mod:`~scara_pin.sweep.store`).
"""

from __future__ import annotations

import hashlib
import itertools
import json
import math
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ..errors import InvalidInputError, UnknownRobotError
from ..limits import MAX_DOCUMENT_BYTES, MAX_JOB_BYTES, MAX_SWEEP_VARIANTS, check_count, read_bytes, read_text

__all__ = ["FORMAT", "KEYS", "RobotRecipe", "SweepSpec", "Variant", "load_spec"]

FORMAT = "scara-pin sweep 1"
"""The ``format:`` value of a sweep file."""
KEYS = ("format", "job", "vary", "samples", "seed", "timeout", "acceleration")
"""The top-level keys of a sweep file."""
_RANGE_KEYS = ("from", "to", "steps")
_FILE_KEYS = ("points", "cell")
"""The job's keys that name a file: a varied one keys each variant by its file's content."""
_KEY_DIGITS = 32
"""Hex digits of a variant's key (128 bits of SHA-256)."""


@dataclass(frozen=True)
class RobotRecipe:
    """How a worker makes a robot (a ``Robot`` does not pickle): a configured robot's name or folder, or URDF text.

    Attributes:
        name: the value as the sweep file spells it (a name, a folder, a URDF file).
        urdf: the URDF file's text, or None for a configured robot.
        acceleration: a URDF robot's joint acceleration limits [rad/s^2, m/s^2], or None.
        digest: SHA-256 of what the robot is made from (its configuration files, or the URDF text).
        folder: a configuration folder's absolute path (a worker in another folder finds it), or None for a name.
    """

    name: str
    urdf: str | None = None
    acceleration: tuple[float, ...] | None = None
    digest: str = ""
    folder: str | None = None


@dataclass(frozen=True)
class Variant:
    """One variant of a sweep: the values of its keys, its place in the sweep, its content key.

    Attributes:
        index: its number in the sweep's order (from 0).
        values: (key, value) of every varied key, as the sweep file spells the key; values in the job file's units.
        key: the content key (hex digest; module docstring).
    """

    index: int
    values: tuple[tuple[str, Any], ...]
    key: str

    def overrides(self) -> dict[str, Any]:
        """The job's overrides: every value but the robot's (``Job.replace``'s mapping)."""
        return {k: v for k, v in self.values if k != "robot"}

    @property
    def robot(self) -> str | None:
        """The robot's value, if the sweep varies it."""
        return dict(self.values).get("robot")


@dataclass(frozen=True, eq=False)
class SweepSpec:
    """A sweep file, read and checked (:func:`load_spec`).

    Attributes:
        path: the sweep file.
        job: the job file (resolved beside the sweep file).
        job_text: the job file's text as read once (every worker gets this text, not the file).
        vary: key -> the values of a list, or the range ``{from, to, steps}`` (module docstring), in the file's order.
        samples: N Sobol points over the ranges, or None for the grid.
        seed: the Sobol sequence's scrambling seed.
        timeout: [s] a variant's planning time limit, or None.
        robots: the robot recipes by the sweep's value (the job's own robot when ``robot`` is not varied).
        digest: SHA-256 of what every variant shares (job text, the files it names, the planner).
        files: a varied file's digest (its content, as the job reads it) by ``key=value``.
    """

    path: Path
    job: Path
    job_text: str
    vary: Mapping[str, Any]
    samples: int | None
    seed: int
    timeout: float | None
    robots: Mapping[str, RobotRecipe]
    digest: str
    files: Mapping[str, str] = field(default_factory=dict)

    @property
    def columns(self) -> tuple[str, ...]:
        """The varied keys, as spelled: a column of the results each."""
        return tuple(self.vary)

    @property
    def count(self) -> int:
        """How many variants (before any is made)."""
        lists = math.prod(len(v) for v in self.vary.values() if isinstance(v, list))
        if self.samples is not None:
            return self.samples * lists
        ranges = math.prod(math.prod(r["steps"]) for r in self.vary.values() if isinstance(r, dict))
        return lists * ranges

    def variants(self) -> Iterator[Variant]:
        """Every variant, in the sweep's order (the last key fastest; with ``samples``, the samples outermost)."""
        keys = list(self.vary)
        if self.samples is None:
            axes = [v if isinstance(v, list) else _grid(v) for v in self.vary.values()]
            combos: Iterator[tuple[Any, ...]] = itertools.product(*axes)
        else:
            combos = self._sampled()
        for index, combo in enumerate(combos):
            values = tuple(zip(keys, combo))
            yield Variant(index, values, self.key_of(values))

    def key_of(self, values: Sequence[tuple[str, Any]]) -> str:
        """The content key of a variant with these values (module docstring)."""
        robot = dict(values).get("robot") or next(iter(self.robots))  # the job's own robot when not varied
        recipe = self.robots.get(str(robot))
        files = [self.files.get(_file_key(k, v), "") for k, v in values if k in _FILE_KEYS]
        text = json.dumps([self.digest, recipe.digest if recipe else "", list(values), *files], sort_keys=True,
                          separators=(",", ":"), allow_nan=False)  # fmt: skip
        return hashlib.sha256(text.encode("utf-8")).hexdigest()[:_KEY_DIGITS]

    def _sampled(self) -> Iterator[tuple[Any, ...]]:
        import warnings

        from scipy.stats import qmc

        dims = [(k, i) for k, r in self.vary.items() if isinstance(r, dict)
                for i, (a, b) in enumerate(zip(r["from"], r["to"])) if a != b]  # fmt: skip
        assert self.samples is not None
        if dims:
            with warnings.catch_warnings():  # N not a power of two: fine for a sweep (docs/sweep.md)
                warnings.simplefilter("ignore", UserWarning)
                points = qmc.Sobol(len(dims), scramble=True, seed=self.seed).random(self.samples)
        lists = [(k, v) for k, v in self.vary.items() if isinstance(v, list)]
        for n in range(self.samples):
            sampled: dict[str, list[float]] = {k: list(r["from"]) for k, r in self.vary.items() if isinstance(r, dict)}
            for d, (k, i) in enumerate(dims):
                r = self.vary[k]
                sampled[k][i] = float(r["from"][i] + points[n, d] * (r["to"][i] - r["from"][i]))
            for combo in itertools.product(*(v for _, v in lists)):
                chosen = dict(zip((k for k, _ in lists), combo))
                yield tuple(chosen[k] if k in chosen else _shaped(sampled[k], self.vary[k]) for k in self.vary)


def _grid(r: Mapping[str, Any]) -> list[Any]:
    """The values of a range: each component's ``steps`` values, their product (the last component fastest)."""
    axes = [[a] if n == 1 else [float(a + (b - a) * k / (n - 1)) for k in range(n)]
            for a, b, n in zip(r["from"], r["to"], r["steps"])]  # fmt: skip
    return [_shaped(list(c), r) for c in itertools.product(*axes)]


def _shaped(values: list[float], r: Mapping[str, Any]) -> Any:
    """A range's value: a number for a scalar range, else the list."""
    return values[0] if r["scalar"] else values


def load_spec(path: str | Path) -> SweepSpec:
    """Read and check a sweep file (module docstring): every problem refused here, before any variant runs.

    Raises:
        InvalidInputError: the file, the key and what is wrong (exit 2): an unknown key, an empty list or range, a
            robot that is not one (unknown name, unreadable URDF), the variants over
            :data:`~scara_pin.limits.MAX_SWEEP_VARIANTS`, a first variant the job file refuses.
    """
    from ..description.yaml_units import load_yaml
    from ..errors import YamlError
    from ..job import KEYS as JOB_KEYS
    from ..job import Job
    from ..job.cache import planner_digest

    path = Path(path)
    text = read_text(path, "sweep file", MAX_JOB_BYTES)
    try:
        data = load_yaml(text, f"sweep file {path}")
    except YamlError as exc:
        raise InvalidInputError(str(exc)) from None

    def fail(why: str) -> InvalidInputError:
        return InvalidInputError(f"{path}: {why}")

    if not isinstance(data, dict):
        raise fail("a sweep file is a mapping (format, job, vary, samples, seed, timeout)")
    unknown = [k for k in data if k not in KEYS]
    if unknown:
        raise fail(f"unknown key {str(unknown[0])[:40]!r} (a sweep file has {', '.join(KEYS)})")
    if "format" in data and data["format"] != FORMAT:
        raise fail(f"format is {str(data['format'])[:40]!r}; this reads {FORMAT!r}")
    if not isinstance(data.get("job"), str) or not data["job"]:
        raise fail("job: the job file (relative to this file) is required")
    job_path = (path.parent / data["job"]) if not Path(data["job"]).is_absolute() else Path(data["job"])
    job_text = read_text(job_path, "job file", MAX_JOB_BYTES)
    vary = data.get("vary")
    if not isinstance(vary, dict) or not vary:
        raise fail("vary: at least one key of the job (or robot) and its values")
    checked: dict[str, Any] = {}
    for key, values in vary.items():
        first = str(key).split(".")[0]
        if key != "robot" and first not in JOB_KEYS:
            raise fail(f"vary {str(key)[:64]}: not a key of the job file ({', '.join(JOB_KEYS)}) nor robot")
        checked[str(key)] = _values(str(key), values, fail)
    samples = _integer(data, "samples", fail, low=1)
    if samples is not None and not any(isinstance(v, dict) for v in checked.values()):
        raise fail("samples: samples a range ({from, to, steps}); this sweep varies lists only")
    seed = _integer(data, "seed", fail, low=0)
    timeout = data.get("timeout")
    if timeout is not None and (isinstance(timeout, bool) or not isinstance(timeout, (int, float))
                                or not 0 < timeout < math.inf):  # fmt: skip
        raise fail(f"timeout is {str(timeout)[:40]}; it must be a number of seconds > 0")
    acceleration = data.get("acceleration")
    if acceleration is not None:
        if not (isinstance(acceleration, list) and all(_number(a) and a > 0 for a in acceleration)):
            raise fail("acceleration: one limit > 0 per joint [rad/s^2, m/s^2]")
        acceleration = tuple(float(a) for a in acceleration)
    job = Job.load(job_path, text=job_text)  # the job itself refused here, once
    names = checked["robot"] if "robot" in checked else [job.robot or "default"]
    if not all(isinstance(n, str) and n for n in names):
        raise fail("vary robot: robot names, configuration folders or URDF files")
    robots = {n: _recipe(n, path.parent, acceleration, fail) for n in names}
    shared = {"format": FORMAT, "planner": planner_digest(), "job": _sha(job_text.encode()),
              "files": _files(job, skip=checked)}  # a varied file is in its own variants' keys (below)
    files = {_file_key(key, value): _files(Job.load(job_path, {key: value}, text=job_text),
                                           skip=[k for k in _FILE_KEYS if k != key]).get(key, "")
             for key in checked if key in _FILE_KEYS and isinstance(checked[key], list)
             for value in checked[key]}  # fmt: skip
    spec = SweepSpec(path=path, job=job_path, job_text=job_text, vary=checked, samples=samples, seed=seed or 0,
                     timeout=None if timeout is None else float(timeout), robots=robots,
                     digest=_sha(json.dumps(shared, sort_keys=True).encode()), files=files)  # fmt: skip
    check_count(f"variants of sweep {path}", spec.count, MAX_SWEEP_VARIANTS, "vary fewer values, or sample: samples: N")
    head = next(spec.variants())
    Job.load(job_path, head.overrides(), text=job_text)  # a value the job refuses: refused now, not per variant
    return spec


def _values(key: str, values: Any, fail: Any) -> Any:
    """A key's values checked: a non-empty list (numbers, names, lists of numbers) or a range."""
    if isinstance(values, dict):
        if sorted(values) != sorted(_RANGE_KEYS):
            raise fail(f"vary {key}: a range is {{from, to, steps}}; got {sorted(map(str, values))}")
        scalar = not isinstance(values["from"], list)
        lo, hi, steps = ([v] if scalar and not isinstance(v, list) else v for v in
                         (values["from"], values["to"], values["steps"]))  # fmt: skip
        if not (isinstance(lo, list) and isinstance(hi, list) and lo and len(lo) == len(hi)
                and all(_number(v) for v in lo + hi)):  # fmt: skip
            raise fail(f"vary {key}: from and to are numbers, or lists of numbers of one length")
        if isinstance(steps, list) and len(steps) == 1 and len(lo) > 1:
            steps = steps * len(lo)
        if not (isinstance(steps, list) and len(steps) == len(lo) and all(isinstance(s, int) and not
                isinstance(s, bool) for s in steps)):  # fmt: skip
            raise fail(f"vary {key}: steps is a whole number, or one per component of from ({len(lo)})")
        if any(s < 1 for s in steps):
            raise fail(f"vary {key}: steps {steps} makes an empty range (every component needs steps >= 1)")
        return {"from": [float(v) for v in lo], "to": [float(v) for v in hi], "steps": steps, "scalar": scalar}
    if not isinstance(values, list):
        values = [values]
    if not values:
        raise fail(f"vary {key}: an empty list (a sweep over nothing)")
    for v in values:
        if not (_number(v) or isinstance(v, str) or (isinstance(v, list) and v and all(_number(x) for x in v))):
            raise fail(f"vary {key}: {str(v)[:40]} is not a number, a name or a list of numbers")
    kinds = {"text" if isinstance(v, str) else "list" if isinstance(v, list) else "number" for v in values}
    if len(kinds) > 1:
        raise fail(f"vary {key}: mixes {' and '.join(sorted(kinds))} values (one column holds one kind)")
    return [_plain(v) for v in values]


def _plain(value: Any) -> Any:
    """A yaml value as plain Python (the loader's line-knowing containers and numbers as themselves)."""
    if isinstance(value, list):
        return [_plain(v) for v in value]
    if isinstance(value, bool) or isinstance(value, str):
        return str(value) if isinstance(value, str) else value
    return int(value) if isinstance(value, int) else float(value)


def _number(v: Any) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)


def _integer(data: Mapping[str, Any], key: str, fail: Any, low: int) -> int | None:
    value = data.get(key)
    if value is None:
        return None
    if isinstance(value, bool) or not isinstance(value, int) or value < low:
        raise fail(f"{key} is {str(value)[:40]}; it must be a whole number >= {low}")
    return int(value)


def _recipe(name: str, folder: Path, acceleration: tuple[float, ...] | None, fail: Any) -> RobotRecipe:
    """The recipe of a robot the sweep names: a URDF file's text, a shipped robot's name, or a folder's path.

    URDF files (``.urdf``) and configuration folders are relative to the sweep file, as its job is.
    """
    from ..description import available_robots, config_files

    if name.endswith(".urdf"):
        file = Path(name) if Path(name).is_absolute() else folder / name
        text = read_text(file, "URDF file")
        if acceleration is None:
            raise fail(f"vary robot {name}: a URDF file has no acceleration limits: give acceleration: [...] "
                       "(one per joint)")  # fmt: skip
        return RobotRecipe(name, text, acceleration, _sha(text.encode() + repr(acceleration).encode()))
    beside = folder / name  # a configuration folder, relative to the sweep file (as its job and URDF files)
    try:
        files = config_files(name if name in available_robots() or not beside.is_dir() else beside)
    except UnknownRobotError as exc:
        raise fail(f"vary robot: {exc}") from None
    except (ValueError, OSError) as exc:
        raise fail(f"vary robot {name[:64]!r}: {exc}") from None
    body = b"".join(read_bytes(f, "robot file") for f in files)
    place = None if name in available_robots() else str(files[0].parent.resolve())  # a folder: its absolute path
    return RobotRecipe(name, None, None, _sha(body), place)


def _sha(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()


def _file_key(key: str, value: Any) -> str:
    return f"{key}={json.dumps(value, sort_keys=True)}"


def _files(job: Any, skip: Any = ()) -> dict[str, str]:
    """The digests of the files a job reads: its points' bytes, its cell's content (a mesh's triangles included)."""
    from ..cell import load_cell
    from ..errors import ScaraError
    from ..job.cache import cell_digest

    out = {}
    if job.points_file is not None and "points" not in skip:
        out["points"] = _sha(read_bytes(job.points_file, "points file", MAX_DOCUMENT_BYTES))
    if job.cell is not None and "cell" not in skip:
        try:
            out["cell"] = cell_digest(load_cell(job.cell))
        except ScaraError as exc:
            raise InvalidInputError(f"{job.path}: cell {job.cell}: {exc}") from None
    return out

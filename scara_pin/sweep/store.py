"""A sweep's results on disk: a Parquet dataset of part files, each written atomically, read back by content key.

The folder holds ``part-<UTC time>-<number>-<random>.parquet`` files (pyarrow), one per batch of finished rows:
written to a temporary name in the folder and renamed (:func:`scara_pin.files.atomic_output`), so a part is on
disk whole or not at all, whatever stops the sweep (Ctrl-C, SIGTERM, a crash). Nothing else in the folder is read
or written; ``pandas.read_parquet(folder)`` and ``pyarrow.dataset.dataset(folder)`` read it too.

A rerun (:meth:`ResultStore.answered`) skips the variants whose key has an ``ok`` or ``infeasible`` row: those are
answers; a ``failed`` or ``timeout`` variant runs again and its new row is kept (:meth:`ResultStore.rows`: the last
row of a key, answers before failures).
"""

from __future__ import annotations

import datetime
import os
import time
from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ..errors import InvalidInputError
from .task import ROW_COLUMNS

if TYPE_CHECKING:
    import pandas as pd
    import pyarrow as pa

__all__ = ["ANSWERS", "PART_GLOB", "ResultStore", "row_schema"]

ANSWERS = ("ok", "infeasible")
"""The statuses a rerun does not run again."""
PART_GLOB = "part-*.parquet"
"""The part files of a results folder."""
_TEXT = ("key", "status", "reason", "binding", "closest_pair", "worker")


def row_schema(vary: Mapping[str, Any]) -> pa.Schema:
    """The Parquet schema of a sweep's rows: a column per varied key (its values' type), then :data:`ROW_COLUMNS`."""
    import pyarrow as pa

    fields = []
    for key, values in vary.items():
        if isinstance(values, dict):  # a range: numbers, or lists of numbers
            kind = pa.float64() if values["scalar"] else pa.list_(pa.float64())
        elif all(isinstance(v, str) for v in values):
            kind = pa.string()
        elif all(isinstance(v, list) for v in values):
            kind = pa.list_(pa.float64())
        elif all(isinstance(v, int) for v in values):
            kind = pa.int64()
        else:
            kind = pa.float64()
        fields.append(pa.field(key, kind))
    for name in ROW_COLUMNS:
        kind = pa.int64() if name == "variant" else pa.string() if name in _TEXT else pa.float64()
        fields.append(pa.field(name, kind))
    return pa.schema(fields)


class ResultStore:
    """The rows of one sweep: those on disk (earlier runs) and those finished now, written a batch at a time.

    Args:
        folder: the results folder (made if missing; its parent must exist), or None to keep the rows in memory.
        schema: the rows' schema (:func:`row_schema`).
        batch: rows per part file; a part is written when this many are waiting, or ``every`` seconds after the
            oldest waiting row, and by :meth:`flush`.
        every: [s] the longest a finished row waits before it is written.
    """

    def __init__(self, folder: str | os.PathLike[str] | None, schema: pa.Schema, *, batch: int = 256,
                 every: float = 30.0) -> None:  # fmt: skip
        self.folder = None if folder is None else Path(folder)
        self.schema = schema
        self.batch = batch
        self.every = every
        self.written = 0
        self._waiting: list[dict[str, Any]] = []
        self._since = 0.0
        self._kept: list[dict[str, Any]] = []
        self._parts = 0
        if self.folder is not None:
            if self.folder.exists() and not self.folder.is_dir():
                raise InvalidInputError(f"--out {self.folder}: not a folder (a sweep writes a folder of part files)")
            if not self.folder.parent.is_dir():
                raise InvalidInputError(f"--out {self.folder}: its folder {self.folder.parent} does not exist")
            self.folder.mkdir(exist_ok=True)

    def parts(self) -> list[Path]:
        """The part files on disk, oldest first (their names begin with the time they were written)."""
        return [] if self.folder is None else sorted(self.folder.glob(PART_GLOB))

    def earlier(self) -> pd.DataFrame:
        """Every row on disk (all part files, in the order written)."""
        import pandas as pd
        import pyarrow.parquet as pq

        tables = [pq.read_table(p).to_pandas() for p in self.parts()]
        return pd.concat(tables, ignore_index=True) if tables else pd.DataFrame(columns=self.schema.names)

    def answered(self, keys: Iterable[str]) -> set[str]:
        """The keys among ``keys`` with an ``ok`` or ``infeasible`` row on disk (a rerun skips them)."""
        rows = self.earlier()
        if rows.empty:
            return set()
        done = set(rows.loc[rows["status"].isin(ANSWERS), "key"])
        return done & set(keys)

    def add(self, row: Mapping[str, Any]) -> None:
        """A finished row: kept, and written with its batch."""
        if not self._waiting:
            self._since = time.monotonic()
        self._waiting.append(dict(row))
        if self.folder is None:  # else read back from the part files (10^6 rows kept would be about a GB)
            self._kept.append(dict(row))
        if len(self._waiting) >= self.batch or time.monotonic() - self._since >= self.every:
            self.flush()

    def flush(self) -> Path | None:
        """Write the waiting rows as one part file (atomically); None when none waits or there is no folder."""
        rows, self._waiting = self._waiting, []
        if not rows or self.folder is None:
            return None
        import pyarrow as pa
        import pyarrow.parquet as pq

        from ..files import atomic_output

        table = pa.Table.from_pylist([{k: r.get(k) for k in self.schema.names} for r in rows], schema=self.schema)
        self._parts += 1
        stamp = datetime.datetime.now(datetime.UTC).strftime("%Y%m%dT%H%M%S%fZ")
        path = self.folder / f"part-{stamp}-{self._parts:05d}-{os.urandom(3).hex()}.parquet"
        with atomic_output(path) as tmp:
            pq.write_table(table, tmp)
        self.written += len(rows)
        return path

    def rows(self, keys: Sequence[str]) -> pd.DataFrame:
        """One row per key of ``keys`` that has one (on disk or finished now): the last, answers before failures.

        Sorted by ``variant``: the key's place in ``keys`` (the sweep's order, whatever run wrote the row).
        """
        import pandas as pd

        order = {k: n for n, k in enumerate(keys)}
        now = pd.DataFrame(self._kept, columns=self.schema.names) if self._kept else None
        on_disk = self.earlier() if self.folder is not None else None
        frames = [f for f in (on_disk, now) if f is not None and not f.empty]
        if not frames:
            return pd.DataFrame(columns=self.schema.names)
        rows = pd.concat(frames, ignore_index=True)
        rows = rows[rows["key"].isin(order)].copy()
        rows["_answer"] = rows["status"].isin(ANSWERS)
        rows["_seen"] = range(len(rows))
        rows = rows.sort_values(["_answer", "_seen"]).drop_duplicates("key", keep="last")
        rows["variant"] = rows["key"].map(order).astype("int64")
        return rows.drop(columns=["_answer", "_seen"]).sort_values("variant").reset_index(drop=True)

"""The results of a campaign: a Parquet dataset partitioned by run status (Hive layout), one row per run.

    DIR/runs/status=done/part-<time>-<n>.parquet     finished runs: inputs and summary numbers
    DIR/runs/status=failed/part-<time>-<n>.parquet   runs that raised: inputs, error and traceback

Rows are written in small files as runs finish (`Writer`), each file written under a hidden name and renamed when
complete, so a reader never sees half a file and a crash loses at most the rows not yet flushed. Any Parquet reader
takes the folder:

    pyarrow.dataset.dataset("DIR/runs", partitioning="hive").to_table()
    pandas.read_parquet("DIR/runs")
    polars.scan_parquet("DIR/runs/**/*.parquet", hive_partitioning=True)
    duckdb.sql("SELECT * FROM read_parquet('DIR/runs/**/*.parquet', hive_partitioning=true, union_by_name=true)")

Columns: `run_key` (hash of the run's inputs), `run_index`, `seed`, `inputs` (JSON of kind, scenario and seed: the
key is its hash, which is how a damaged row is recognised), `param.<path>` (the varied parameters), the kind's
summary numbers, `wall_s`, `worker`, `attempts`, and for failed runs `error`, `error_type`, `traceback`.
"""

from __future__ import annotations

import itertools
import json
import os
import time
from dataclasses import dataclass, field
from pathlib import Path

import pyarrow as pa
import pyarrow.parquet as pq

from .._core import InputError
from .spec import _hash

STATUSES = ("done", "failed")
INT_COLUMNS = ("run_index", "seed", "attempts")
#: always strings (also when empty), and present in every file of both partitions: a reader that takes the
#: schema from the first file it finds (pyarrow.dataset's default) still sees the errors of failed runs
STRING_COLUMNS = ("run_key", "inputs", "worker", "warnings", "error_type", "error", "traceback")


class CorruptDataset(InputError):
    """A file or row of an existing dataset cannot be trusted (unreadable, or a key that is not its inputs')."""


def _type_of(name: str, value) -> pa.DataType:
    if name in INT_COLUMNS:
        return pa.int64()
    if name in STRING_COLUMNS:
        return pa.string()
    if isinstance(value, bool):
        return pa.bool_()
    if isinstance(value, str):
        return pa.string()
    if isinstance(value, (list, dict, tuple)):
        return pa.string()
    return pa.float64()  # numbers and None (a missing number)


def _cell(name: str, value):
    if isinstance(value, (list, dict, tuple)):
        return json.dumps(value, sort_keys=True)
    if name in INT_COLUMNS:
        return None if value is None else int(value)
    if name in STRING_COLUMNS:
        return None if value is None else str(value)
    if value is None or isinstance(value, (bool, str)):
        return value
    return float(value)


def to_table(rows: list[dict]) -> pa.Table:
    """Rows (mappings) to an Arrow table with the dataset's column types: integers for index/seed/attempts,
    float64 for numbers and missing numbers, bool, string, JSON strings for lists and mappings."""
    names: list[str] = []
    types: dict[str, pa.DataType] = {}
    for r in rows:
        for k, v in r.items():
            if k not in types:
                names.append(k)
                types[k] = _type_of(k, v)
            elif v is not None and types[k] == pa.float64() and not isinstance(v, (int, float)):
                types[k] = _type_of(k, v)  # a None seen first, then a string
    cols = {k: [_cell(k, r.get(k)) for r in rows] for k in names}
    return pa.table({k: pa.array(cols[k], type=types[k]) for k in names})


@dataclass
class Writer:
    """Buffers finished rows and writes them as one file per flush (every `flush_rows` rows or `flush_seconds`)."""

    root: Path
    flush_rows: int = 32
    flush_seconds: float = 5.0
    _buffer: dict = field(default_factory=lambda: {s: [] for s in STATUSES})
    _last: float = field(default_factory=time.monotonic)
    _seq: itertools.count = field(default_factory=itertools.count)
    written: int = 0

    def add(self, row: dict) -> None:
        for k in STRING_COLUMNS:
            row.setdefault(k, None)
        self._buffer[row.pop("status")].append(row)
        pending = sum(len(b) for b in self._buffer.values())
        if pending >= self.flush_rows or time.monotonic() - self._last >= self.flush_seconds:
            self.flush()

    def flush(self) -> None:
        for status, rows in self._buffer.items():
            if not rows:
                continue
            folder = self.root / f"status={status}"
            folder.mkdir(parents=True, exist_ok=True)
            name = f"part-{time.strftime('%Y%m%dT%H%M%S')}-{os.getpid()}-{next(self._seq):05d}.parquet"
            tmp = folder / f".{name}.tmp"  # hidden: dataset readers skip names starting with '.'
            pq.write_table(to_table(rows), tmp)
            os.replace(tmp, folder / name)
            self.written += len(rows)
            rows.clear()
        self._last = time.monotonic()


def warm_up() -> None:
    """Do pyarrow's one-time set-up of the Parquet writer now, into memory: the first `write_table` of a process
    takes about 0.2 s (more with a cold disk cache, as on a fresh install), the next ones under 1 ms. The campaign
    runner calls this before its runs start, so that the flush a Ctrl-C makes stays well within its one second: that
    first write was 0.23-0.27 s of a 0.3-s stop here, and a stop once took 1.07 s in a CI run on a fresh install."""
    pq.write_table(to_table([{"run_key": "", "run_index": 0, "inputs": "{}"}]), pa.BufferOutputStream())


def files(root: Path) -> list[tuple[str, Path]]:
    """(status, file) of every data file of the dataset, in name order."""
    out = []
    for status in STATUSES:
        folder = Path(root) / f"status={status}"
        if folder.is_dir():
            out += [(status, p) for p in sorted(folder.glob("*.parquet")) if not p.name.startswith((".", "_"))]
    return out


@dataclass
class Scan:
    """What an existing dataset holds: keys of finished and failed runs, and what could not be trusted."""

    done: dict = field(default_factory=dict)  # run_key -> run_index
    failed: dict = field(default_factory=dict)  # run_key -> error text
    problems: list = field(default_factory=list)  # (file, description)


def scan(root: Path) -> Scan:
    """Read the keys of every row and check each against the hash of its stored inputs."""
    s = Scan()
    for status, f in files(root):
        try:
            cols = ["run_key", "inputs", "run_index"] + (["error"] if status == "failed" else [])
            t = pq.read_table(f, columns=cols)
        except Exception as e:  # noqa: BLE001  (any reader error means the file cannot be trusted)
            s.problems.append((f, f"not a readable Parquet file with run_key/inputs columns ({type(e).__name__}: {e})"))
            continue
        keys, inputs, idx = (t.column(c).to_pylist() for c in ("run_key", "inputs", "run_index"))
        errs = t.column("error").to_pylist() if status == "failed" else [None] * len(keys)
        bad = []
        for i, (k, js) in enumerate(zip(keys, inputs)):
            try:
                ok = k is not None and js is not None and _hash(json.loads(js)) == k
            except (TypeError, ValueError):
                ok = False
            if not ok:
                bad.append(i)
                continue
            if status == "done":
                s.done[k] = idx[i]
            else:
                s.failed[k] = errs[i]
        if bad:
            s.problems.append((f, f"row(s) {bad[:10]} have a run_key that is not the hash of their inputs"))
    for k in list(s.failed):
        if k in s.done:
            del s.failed[k]  # failed once, finished on a later attempt
    return s


def read(root: Path, status: str | None = None) -> pa.Table:
    """The whole dataset as one Arrow table (a `status` column added; schemas of the files unified)."""
    tables = []
    for st, f in files(root):
        if status is not None and st != status:
            continue
        t = pq.read_table(f)
        tables.append(t.append_column("status", pa.array([st] * t.num_rows, pa.string())))
    if not tables:
        return pa.table({"run_key": pa.array([], pa.string()), "status": pa.array([], pa.string())})
    try:
        return pa.concat_tables(tables, promote_options="permissive")
    except TypeError:  # pyarrow < 14 spelling
        return pa.concat_tables(tables, promote=True)


def remove_rows(root: Path, status: str, keys: set) -> int:
    """Rewrite the files of one partition without the rows whose key is in `keys` (used to retry failed runs)."""
    n = 0
    for st, f in files(root):
        if st != status:
            continue
        t = pq.read_table(f)
        k = t.column("run_key").to_pylist()
        keep = [i for i, x in enumerate(k) if x not in keys]
        if len(keep) == len(k):
            continue
        n += len(k) - len(keep)
        if keep:
            tmp = f.with_name(f".{f.name}.tmp")
            pq.write_table(t.take(keep), tmp)
            os.replace(tmp, f)
        else:
            f.unlink()
    return n

"""Running a campaign on Dask: a `LocalCluster` on this machine (one single-threaded worker process per core) or an
existing cluster (`scheduler="tcp://host:8786"`), with the same code.

Runs are submitted in a bounded window (a few per worker thread, so a campaign of any size needs little memory),
their rows go to the dataset as they finish (`dataset.Writer`), runs already in the dataset are skipped (their key
is a hash of their inputs), a run that raises becomes a row with its error, and a run whose worker died is
submitted again (up to `max_retries` times; the scheduler itself also reschedules the tasks of a lost worker).
Ctrl-C stops cleanly: finished rows are written, `results.json` says the campaign was interrupted, and the same
command continues where it stopped.
"""

from __future__ import annotations

import contextlib
import json
import os
import signal
import socket
import sys
import threading
import time
import traceback
import warnings
from collections.abc import Callable
from pathlib import Path

from .._core import InputError
from . import dataset, registry
from .spec import CampaignSpec, Run, _canonical

#: seconds to wait for a scheduler given by address before giving up (the issue asks for an error within 10 s)
CONNECT_TIMEOUT = 6.0


def execute(payload: dict) -> dict:
    """Run one campaign run (on a worker) and return its row. Never raises for an error of the run itself: the
    error and its traceback go in the row."""
    kind = registry.get(payload["kind"])
    inputs = {"kind": payload["kind"], "scenario": payload["scenario"], "seed": payload["seed"]}
    row = {
        "run_key": payload["key"],
        "run_index": payload["index"],
        "seed": payload["seed"],
        "attempts": payload.get("attempt", 1),
        "inputs": _canonical(inputs),
    }
    row.update({f"param.{k}": v for k, v in payload["params"].items()})
    t0 = time.perf_counter()
    row["started_at"] = time.time()
    caught: list = []
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            summary = kind.run(payload["scenario"], payload["seed"])
        if not isinstance(summary, dict):
            raise TypeError(f"kind {kind.name}: run returned {type(summary).__name__}, not a mapping of numbers")
        row["status"] = "done"
        row.update(summary)
    except Exception as e:  # noqa: BLE001  (recorded in the row: one bad run must not stop the campaign)
        row["status"] = "failed"
        row["error_type"] = type(e).__name__
        row["error"] = str(e) or type(e).__name__
        row["traceback"] = traceback.format_exc(limit=20)
    row["run_wall_s"] = time.perf_counter() - t0
    row["finished_at"] = time.time()
    row["warnings"] = "; ".join(dict.fromkeys(str(w.message) for w in caught or []))
    row["worker"] = f"{socket.gethostname()}:{os.getpid()}"
    return row


def _check_out(out: Path, spec: CampaignSpec) -> dict | None:
    """The existing campaign.json of `out` (None for a new folder); InputError if `out` holds something else."""
    meta_p = out / "campaign.json"
    if meta_p.is_file():
        try:
            meta = json.loads(meta_p.read_text())
        except ValueError as e:
            raise InputError(f"--out {out}: campaign.json is not valid JSON ({e})") from None
        if meta.get("fingerprint") != spec.fingerprint():
            what = (
                f"campaign '{meta.get('name')}'"
                if meta.get("name") != spec.name
                else f"an earlier version of '{spec.name}' (its runs or base scenario differ)"
            )
            raise InputError(
                f"--out {out} holds {what}, not this spec's runs: choose another --out folder "
                "(or delete that one to start again)"
            )
        return meta
    if out.is_dir() and any(out.iterdir()):
        raise InputError(
            f"--out {out} is not empty and holds no campaign (no campaign.json): choose a new or empty folder"
        )
    return None


def _connect(scheduler: str | None, workers: int | None):
    from dask.distributed import Client, LocalCluster

    if scheduler:
        t0 = time.monotonic()
        try:
            client = Client(scheduler, timeout=CONNECT_TIMEOUT)
        except (OSError, TimeoutError) as e:
            raise InputError(
                f"--scheduler {scheduler}: could not reach a Dask scheduler there within "
                f"{time.monotonic() - t0:.0f} s ({type(e).__name__}: {e}); start one with `dask scheduler` "
                "and workers with `dask worker ADDRESS`, or leave --scheduler out to use this machine"
            ) from None
        except ValueError as e:
            raise InputError(f"--scheduler {scheduler}: not a scheduler address ({e}); e.g. tcp://host:8786") from None
        return client, None, f"{scheduler}"
    n = workers or os.cpu_count() or 1
    if n < 1:
        raise InputError(f"--workers must be at least 1, got {n}")
    import logging

    cluster = LocalCluster(
        n_workers=n,
        threads_per_worker=1,
        processes=True,
        dashboard_address=":0",  # any free port: the scheduler's HTTP server starts anyway, never clash on 8787
        silence_logs=logging.ERROR,
    )
    return Client(cluster), cluster, f"LocalCluster({n} workers)"


def run_campaign(
    spec: CampaignSpec,
    out,
    runs: int | None = None,
    workers: int | None = None,
    scheduler: str | None = None,
    progress: bool = True,
    retry_failed: bool = False,
    repair: bool = False,
    max_retries: int = 3,
    flush_rows: int = 32,
    flush_seconds: float = 5.0,
    on_row: Callable | None = None,
    echo: Callable = print,
) -> dict:
    """Run the campaign `spec` into the folder `out` and return what `out/results.json` holds.

    runs: only the first N runs of the spec. workers: size of the local cluster (default: the number of cores).
    scheduler: address of an existing Dask scheduler instead. retry_failed: run again the runs recorded as failed.
    repair: move unreadable or damaged dataset files to `out/quarantine/` and run their runs again (without it
    they are an error). on_row(client, row): called in this process for each finished row (tests use it)."""
    out = Path(out)
    if runs is not None and runs < 1:
        raise InputError(f"--runs must be at least 1, got {runs}")
    meta = _check_out(out, spec)
    root = out / "runs"
    s = dataset.scan(root)
    if s.problems:
        if not repair:
            lines = "; ".join(f"{f}: {why}" for f, why in s.problems)
            raise dataset.CorruptDataset(
                f"the dataset in {root} has damaged data: {lines}. Nothing was run; move the file(s) away or "
                "re-run with --repair (moves them to quarantine/ and runs their runs again)"
            )
        q = out / "quarantine"
        q.mkdir(exist_ok=True)
        for f, why in s.problems:
            os.replace(f, q / f"{f.parent.name}-{f.name}")
            echo(f"moved damaged {f} to {q} ({why})")
        s = dataset.scan(root)
    out.mkdir(parents=True, exist_ok=True)
    all_runs = spec.runs()
    selected = all_runs[:runs] if runs is not None else all_runs
    if retry_failed and s.failed:
        retry = {r.key for r in selected if r.key in s.failed}
        dataset.remove_rows(root, "failed", retry)
        for k in retry:
            del s.failed[k]
    todo: list[Run] = [r for r in selected if r.key not in s.done and r.key not in s.failed]
    meta = meta or {
        "name": spec.name,
        "kind": spec.kind,
        "description": spec.description,
        "source": spec.source,
        "fingerprint": spec.fingerprint(),
        "created": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()),
    }
    meta["spec"] = spec.raw
    meta["base_scenario"] = spec.base
    meta["runs_total"] = len(all_runs)
    (out / "campaign.json").write_text(json.dumps(meta, indent=1, default=str))

    state = {"new_done": 0, "new_failed": 0, "interrupted": False, "scheduler": None, "workers": None}
    t_start = time.perf_counter()
    writer = dataset.Writer(root, flush_rows=flush_rows, flush_seconds=flush_seconds)
    keys = {r.key for r in all_runs}
    done0 = sum(1 for k in s.done if k in keys)
    failed0 = sum(1 for k in s.failed if k in keys)
    try:
        if todo:
            dataset.warm_up()
            _execute_all(spec, todo, writer, state, workers, scheduler, progress, max_retries, on_row, done0, failed0)
    except KeyboardInterrupt:
        state["interrupted"] = True
    finally:
        with _sigint_deferred(state):  # a second Ctrl-C must not lose the bookkeeping of what finished
            res = _finish(spec, out, root, writer, state, all_runs, selected, todo, keys, t_start)
    if state["interrupted"]:
        raise KeyboardInterrupt
    return res


@contextlib.contextmanager
def _sigint_deferred(state: dict):
    """Hold Ctrl-C while the finished rows and results.json are written (main thread only; a Ctrl-C held here
    marks the campaign interrupted once the writing is done)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return

    def held(signum, frame):
        state["interrupted"] = True

    previous = signal.signal(signal.SIGINT, held)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)


def _finish(spec, out, root, writer, state, all_runs, selected, todo, keys, t_start) -> dict:
    """Flush the rows still in memory and write `out/results.json` from what the dataset holds."""
    writer.flush()
    final = dataset.scan(root)
    res = {
        "campaign": spec.name,
        "kind": spec.kind,
        "description": spec.description,
        "spec": spec.source,
        "runs_total": len(all_runs),
        "runs_selected": len(selected),
        "runs_done": sum(1 for k in final.done if k in keys),
        "runs_failed": sum(1 for k in final.failed if k in keys),
        "runs_new": state["new_done"] + state["new_failed"],
        "runs_new_failed": state["new_failed"],
        "runs_skipped": len(selected) - len(todo),
        "dataset": str(root.resolve()),
        "dataset_format": "parquet, hive-partitioned by status",
        "scheduler": state["scheduler"],
        "workers": state["workers"],
        "wall_s": time.perf_counter() - t_start,
        "interrupted": state["interrupted"],
        "failures": [{"run_key": k, "error": e} for k, e in list(final.failed.items())[:20] if k in keys],
    }
    res["runs_remaining"] = res["runs_total"] - res["runs_done"] - res["runs_failed"]
    (out / "results.json").write_text(json.dumps(res, indent=1))
    return res


def _kill_local_workers(cluster) -> None:
    """Kill the worker processes of a LocalCluster this process started (its nannies run here; each holds one
    worker process). Used only when a campaign on a local cluster is stopped by Ctrl-C."""
    for nanny in list(getattr(cluster, "workers", {}).values()):
        with contextlib.suppress(Exception):  # a worker that already exited (or never started) has nothing to kill
            os.kill(nanny.process.process.pid, signal.SIGKILL)


def _execute_all(spec, todo, writer, state, workers, scheduler, progress, max_retries, on_row, done0, failed0):
    from dask.distributed import as_completed
    from tqdm import tqdm

    client, cluster, where = _connect(scheduler, workers)
    state["scheduler"] = where
    try:
        nthreads = sum(client.nthreads().values()) or 1
        state["workers"] = len(client.nthreads())
        window = max(2 * nthreads, 4)
        pending = list(reversed(todo))  # pop() takes the next run in order
        attempts: dict[str, int] = {}
        byname: dict[str, Run] = {}

        def submit(run: Run):
            attempts[run.key] = attempts.get(run.key, 0) + 1
            p = run.payload() | {"attempt": attempts[run.key]}
            f = client.submit(execute, p, key=f"freefloat-run-{run.key}-{attempts[run.key]}", pure=False)
            byname[f.key] = run
            return f

        ac = as_completed([submit(pending.pop()) for _ in range(min(window, len(pending)))])
        total = len(todo) + done0 + failed0
        bar = tqdm(
            total=total, initial=done0 + failed0, unit="run", desc=spec.name, disable=not progress, dynamic_ncols=True
        )

        def postfix():
            d = done0 + state["new_done"]
            fl = failed0 + state["new_failed"]
            bar.set_postfix_str(f"done {d}, failed {fl}, remaining {total - d - fl}")

        postfix()
        for fut in ac:
            run = byname.pop(fut.key)
            try:
                row = fut.result()
            except Exception as e:  # noqa: BLE001  (the worker died or the task was lost, not the run's own error)
                fut.release()
                if attempts[run.key] <= max_retries:
                    ac.add(submit(run))
                    continue
                row = {
                    "status": "failed",
                    "run_key": run.key,
                    "run_index": run.index,
                    "seed": run.seed,
                    "attempts": attempts[run.key],
                    "inputs": _canonical({"kind": run.kind, "scenario": run.scenario, "seed": run.seed}),
                    **{f"param.{k}": v for k, v in run.params.items()},
                    "error_type": type(e).__name__,
                    "error": f"lost {attempts[run.key]} times (worker died or task failed outside the run): {e}",
                    "traceback": "",
                }
            fut.release()
            if on_row is not None:
                on_row(client, dict(row))
            state["new_done" if row["status"] == "done" else "new_failed"] += 1
            writer.add(row)
            bar.update(1)
            postfix()
            if pending:
                ac.add(submit(pending.pop()))
        bar.close()
    finally:
        # On Ctrl-C the runs still in flight are abandoned (the finished ones are already in the writer), so the
        # local workers are killed rather than asked to finish: a graceful LocalCluster shutdown waits for its
        # worker processes and took about 5 s, against the one second a stop may take.
        stopping = isinstance(sys.exc_info()[1], KeyboardInterrupt)
        try:
            if stopping and cluster is not None:
                _kill_local_workers(cluster)
            client.close(timeout=1 if stopping else 10)
        finally:
            if cluster is not None:
                cluster.close(timeout=1 if stopping else 10)

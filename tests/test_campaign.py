"""Campaigns (issue 15): the spec format and its expansion into keyed runs, the dataset (streamed, resumable,
damage reported), runs on a 2-worker LocalCluster (re-run does nothing new, a killed worker loses nothing), on a
separately started `dask scheduler` + `dask worker`, and the bad inputs the issue lists."""

from __future__ import annotations

import json
import os
import shutil
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pyarrow.dataset as pads
import pyarrow.parquet as pq
import pytest
import yaml

from freefloat import campaign as cp
from freefloat._core import InputError
from freefloat.campaign import dataset, runner
from freefloat.campaign.spec import get_path, run_key, set_path

from _helpers import sigint_when, start_cli

#: the medium post-capture scenario, shortened so one run takes about a second, with measurement noise so the
#: Monte Carlo seeds matter; 2 grid points x 8 noise draws (the issue's 2 x 8)
MEDIUM_2X8 = {
    "name": "medium_2x8",
    "kind": "postcapture",
    "scenario": "zhang2020_2d_medium",
    "set": {"duration": 3.0, "noise": {"velocity": 1.0e-4, "acceleration": 1.0e-4, "force": 0.01}},
    "grid": {"initial.base_velocity.0": [1.0, 2.0]},
    "monte_carlo": {"runs": 8, "seed": 7},
}


def _spec(d=MEDIUM_2X8, **changes):
    d = json.loads(json.dumps(d)) | changes
    return cp.spec.parse(d, "test spec")


# -- the spec and its runs (no cluster) -------------------------------------------------------------------
def test_expansion_order_keys_and_seeds():
    s = _spec()
    runs = s.runs()
    assert s.runs_total == 16 and len(runs) == 16
    assert [r.index for r in runs] == list(range(16))
    # grid outer, draws inner; the same 8 seeds at both grid points (common random numbers), all different
    assert [r.params["initial.base_velocity.0"] for r in runs] == [1.0] * 8 + [2.0] * 8
    seeds = [r.seed for r in runs]
    assert seeds[:8] == seeds[8:] and len(set(seeds[:8])) == 8
    assert len({r.key for r in runs}) == 16
    # the overrides reached the scenario each run executes
    for r in runs:
        assert r.scenario["duration"] == 3.0
        assert r.scenario["initial"]["base_velocity"][0] == r.params["initial.base_velocity.0"]
        assert r.scenario["initial"]["base_velocity"][1] == 2.0  # untouched Vy of zhang2020_2d_medium
        assert r.key == run_key("postcapture", r.scenario, r.seed)
    # a prefix (--runs N) has the same runs, and the key changes with any input
    assert [r.key for r in s.runs(5)] == [r.key for r in runs[:5]]
    other = _spec(set={"duration": 3.5, "noise": MEDIUM_2X8["set"]["noise"]}).runs()
    assert not {r.key for r in other} & {r.key for r in runs}


def test_monte_carlo_draws_follow_their_distribution():
    s = _spec(
        grid={},
        monte_carlo={
            "runs": 400,
            "seed": 3,
            "parameters": {"control.K_P": {"distribution": "uniform", "low": 0.2, "high": 0.3}},
        },
    )
    x = np.array([r.params["control.K_P"] for r in s.runs()])
    assert 0.2 <= x.min() and x.max() <= 0.3
    # mean and variance of U(0.2, 0.3): 0.25 and 0.01/12; 400 draws: standard error of the mean 1.4e-3
    assert abs(x.mean() - 0.25) < 6e-3 and abs(x.var() - 0.01 / 12) < 2.5e-4
    assert x.tolist() == [r.params["control.K_P"] for r in s.runs()]  # reproducible


def test_dotted_paths():
    d = {"a": {"b": [1, 2, 3]}, "c": None}
    set_path(d, "a.b.1", 9)
    set_path(d, "c.d", 4)  # a missing optional section is created
    assert d == {"a": {"b": [1, 9, 3]}, "c": {"d": 4}} and get_path(d, "a.b.1") == 9
    with pytest.raises(InputError, match="index 5"):
        set_path(d, "a.b.5", 0)
    with pytest.raises(InputError, match="dotted"):
        set_path(d, "a..b", 0)


def test_builtin_specs_load_and_list():
    names = cp.builtin_names()
    assert {"zhang2020_velocity_sweep", "naveen_noise_monte_carlo"} <= set(names)
    z = cp.load_spec("zhang2020_velocity_sweep")
    assert z.kind == "postcapture" and z.runs_total == 81
    assert {r.scenario["duration"] for r in z.runs()} == {60.0}
    vel = {tuple(r.scenario["initial"]["base_velocity"]) for r in z.runs()}
    assert (0.0, 0.0) in vel and (200.0, 200.0) in vel and len(vel) == 81
    n = cp.load_spec("naveen_noise_monte_carlo")
    assert n.kind == "identify_minimal" and n.runs_total == 48


# -- bad input ----------------------------------------------------------------------------------------------
@pytest.mark.parametrize(
    "change, match",
    [
        ({"kind": "postcapure"}, "unknown scenario kind 'postcapure'.*did you mean postcapture"),
        ({"scenario": "zhang2020_2d_medum"}, "not found"),
        ({"grid": {"initial.base_velocty.0": [1.0]}}, "unknown parameter 'initial.base_velocty.0'.*closest: initial"),
        ({"set": {"controll.K_P": 1.0}}, "unknown parameter 'controll.K_P'.*closest: control.K_P"),
        ({"grid": {"initial.base_velocity.0": []}}, "has no values"),
        ({"grid": {}, "monte_carlo": None}, "no runs"),
        ({"monte_carlo": {"runs": 0}}, "positive integer"),
        ({"monte_carlo": {"runs": 2, "parameters": {"duration": {"distribution": "gauss"}}}}, "distribution"),
        (
            {"monte_carlo": {"runs": 2, "parameters": {"duration": {"distribution": "uniform", "low": 2, "high": 1}}}},
            "low must be below high",
        ),
    ],
)
def test_bad_spec(change, match):
    with pytest.raises(InputError, match=match):
        _spec(**change)


def test_unknown_spec_name_suggests_builtin():
    with pytest.raises(InputError, match="did you mean zhang2020_velocity_sweep"):
        cp.load_spec("zhang2020_velocity_swep")


def test_spec_yaml_error_names_line(tmp_path):
    p = tmp_path / "bad.yaml"
    p.write_text("name: x\nkind: postcapture\ngrid: [1, 2\n")
    with pytest.raises(InputError, match=r"bad.yaml: line \d+"):
        cp.load_spec(p)


def test_a_run_that_raises_is_a_row_with_its_error():
    r = _spec(set={"duration": -1.0}).runs(1)[0]
    row = runner.execute(r.payload())
    assert row["status"] == "failed" and row["run_key"] == r.key
    assert "t_final" in row["error"] and "Traceback" in row["traceback"]


def test_out_folder_of_another_campaign_or_command(tmp_path):
    s = _spec()
    (tmp_path / "a").mkdir()
    (tmp_path / "a" / "campaign.json").write_text(json.dumps({"name": "other", "fingerprint": "123"}))
    with pytest.raises(InputError, match="holds campaign 'other'"):
        cp.run_campaign(s, tmp_path / "a", progress=False)
    (tmp_path / "b").mkdir()
    (tmp_path / "b" / "results.json").write_text("{}")
    with pytest.raises(InputError, match="not empty and holds no campaign"):
        cp.run_campaign(s, tmp_path / "b", progress=False)


def _fake_done_rows(s, out: Path, n: int):
    """Rows for the first n runs, written as the campaign would (summary numbers made up: only keys matter)."""
    w = dataset.Writer(out / "runs", flush_rows=1000)
    for r in s.runs(n):
        row = runner.execute(r.payload() | {"scenario": r.scenario | {"duration": -1.0}})  # fast: fails at once
        row.update(status="done", error=None)
        row["inputs"] = runner._canonical({"kind": r.kind, "scenario": r.scenario, "seed": r.seed})
        w.add(row)
    w.flush()
    (out / "campaign.json").write_text(json.dumps({"name": s.name, "fingerprint": s.fingerprint()}))


def test_damaged_dataset_is_reported_not_dropped(tmp_path):
    s = _spec()
    _fake_done_rows(s, tmp_path, 3)
    assert len(dataset.scan(tmp_path / "runs").done) == 3
    # a row whose key is not the hash of its inputs
    f = dataset.files(tmp_path / "runs")[0][1]
    t = pq.read_table(f).to_pylist()
    t[1]["run_key"] = "0" * 20
    pq.write_table(dataset.to_table(t), f)
    with pytest.raises(dataset.CorruptDataset, match=r"row\(s\) \[1\].*not the hash"):
        cp.run_campaign(s, tmp_path, progress=False)
    # an unreadable file
    (tmp_path / "runs" / "status=done" / "part-junk.parquet").write_bytes(b"not parquet at all")
    with pytest.raises(dataset.CorruptDataset, match="part-junk.parquet: not a readable Parquet"):
        cp.run_campaign(s, tmp_path, progress=False)
    # nothing was run or changed by the refused calls
    assert len(dataset.files(tmp_path / "runs")) == 2


@pytest.mark.parametrize("reader", ["pyarrow", "pandas", "polars", "duckdb"])
def test_the_dataset_is_read_by_the_usual_readers(tmp_path, reader):
    s = _spec()
    _fake_done_rows(s, tmp_path, 3)
    w = dataset.Writer(tmp_path / "runs")
    w.add(runner.execute(_spec(set={"duration": -1.0}).runs(1)[0].payload()))  # one failed run
    w.flush()
    root = tmp_path / "runs"
    if reader == "pyarrow":
        rows = pads.dataset(root, partitioning="hive").to_table().to_pylist()
    elif reader == "pandas":
        rows = pytest.importorskip("pandas").read_parquet(root).to_dict("records")
    elif reader == "polars":
        pl = pytest.importorskip("polars")
        rows = pl.scan_parquet(f"{root}/**/*.parquet", hive_partitioning=True, missing_columns="insert").collect()
        rows = rows.to_dicts()
    else:
        duckdb = pytest.importorskip("duckdb")
        rel = duckdb.sql(
            f"SELECT * FROM read_parquet('{root}/**/*.parquet', hive_partitioning=true, union_by_name=true)"
        )
        rows = [dict(zip(rel.columns, r)) for r in rel.fetchall()]
    assert sorted(str(r["status"]) for r in rows) == ["done"] * 3 + ["failed"]
    bad = next(r for r in rows if str(r["status"]) == "failed")
    assert "t_final" in bad["error"]


@pytest.mark.slow
def test_unreachable_scheduler_is_a_clear_error_within_10_s(tmp_path):
    with socket.socket() as sk:
        sk.bind(("127.0.0.1", 0))
        port = sk.getsockname()[1]  # free now, nobody listens there
    t0 = time.monotonic()
    with pytest.raises(InputError, match=f"--scheduler tcp://127.0.0.1:{port}: could not reach"):
        cp.run_campaign(_spec(), tmp_path / "o", scheduler=f"tcp://127.0.0.1:{port}", progress=False)
    assert time.monotonic() - t0 < 10


# -- on a cluster -------------------------------------------------------------------------------------------
def _rows(out: Path):
    return pads.dataset(out / "runs", partitioning="hive").to_table().to_pylist()


@pytest.mark.slow
def test_2x8_on_a_2_worker_local_cluster_then_rerun_does_nothing(tmp_path):
    s = _spec()
    res = cp.run_campaign(s, tmp_path, workers=2, progress=False, flush_rows=4)
    assert res["runs_total"] == res["runs_done"] == res["runs_new"] == 16 and res["runs_failed"] == 0
    assert json.loads((tmp_path / "results.json").read_text()) == res
    assert Path(res["dataset"]) == (tmp_path / "runs").resolve()
    rows = _rows(tmp_path)
    assert len(rows) == 16 and {r["run_key"] for r in rows} == {r.key for r in s.runs()}
    assert len({r["worker"] for r in rows}) == 2  # both workers ran
    assert len(dataset.files(tmp_path / "runs")) >= 4  # streamed in several files, not gathered at the end
    # each row is what a direct run of the same inputs gives (independent of Dask): compare one row
    run = s.runs()[5]
    direct = cp.registry.KINDS["postcapture"].run(run.scenario, run.seed)
    row = next(r for r in rows if r["run_key"] == run.key)
    assert row["error.momentum.modified_rls.In"] == pytest.approx(direct["error.momentum.modified_rls.In"], rel=1e-12)
    # noise draws differ: the 8 runs of a grid point do not give the same estimate
    est = [r["estimate.force.standard_rls.mn"] for r in rows if r["param.initial.base_velocity.0"] == 1.0]
    assert len(set(est)) == 8
    again = cp.run_campaign(s, tmp_path, workers=2, progress=False)
    assert again["runs_new"] == 0 and again["runs_done"] == 16 and again["scheduler"] is None
    assert len(_rows(tmp_path)) == 16


@pytest.mark.slow
def test_killing_a_worker_mid_campaign_still_gives_16_rows(tmp_path):
    s = _spec()
    killed = []

    def kill_one(client, row):
        if killed:
            return
        pids = client.run(os.getpid)  # worker address -> pid; processes this test started (LocalCluster)
        victim = next(p for p in pids.values() if str(p) != row["worker"].split(":")[-1])
        os.kill(victim, signal.SIGKILL)
        killed.append(victim)

    res = cp.run_campaign(s, tmp_path, workers=2, progress=False, flush_rows=2, on_row=kill_one)
    assert killed, "no worker was killed: the test did not test anything"
    with pytest.raises(ProcessLookupError):
        os.kill(killed[0], 0)
    rows = _rows(tmp_path)
    assert res["runs_done"] == 16 and res["runs_failed"] == 0
    assert len(rows) == 16 and {r["run_key"] for r in rows} == {r.key for r in s.runs()}
    assert all(r["status"] == "done" for r in rows)


@pytest.mark.slow
def test_runs_that_raise_are_recorded_and_retried_on_request(tmp_path):
    s = _spec(grid={"duration": [1.0, -1.0]}, monte_carlo=None)
    res = cp.run_campaign(s, tmp_path, workers=1, progress=False)
    assert res["runs_done"] == 1 and res["runs_failed"] == 1 and res["runs_new"] == 2
    failed = [r for r in dataset.read(tmp_path / "runs", None).to_pylist() if r["status"] == "failed"]
    assert len(failed) == 1 and failed[0]["param.duration"] == -1.0 and "t_final" in failed[0]["error"]
    # a reader that takes its schema from the first file (the done partition) still sees the error
    plain = [r for r in _rows(tmp_path) if r["status"] == "failed"]
    assert plain[0]["error"] == failed[0]["error"]
    assert res["failures"][0]["run_key"] == failed[0]["run_key"]
    # a plain re-run skips the failed run too (it would fail again); --retry-failed runs it again
    assert cp.run_campaign(s, tmp_path, workers=1, progress=False)["runs_new"] == 0
    again = cp.run_campaign(s, tmp_path, workers=1, progress=False, retry_failed=True)
    assert again["runs_new"] == 1 and again["runs_failed"] == 1
    assert sum(r["status"] == "failed" for r in dataset.read(tmp_path / "runs", None).to_pylist()) == 1


def _free_port() -> int:
    with socket.socket() as sk:
        sk.bind(("127.0.0.1", 0))
        return sk.getsockname()[1]


@pytest.mark.slow
def test_the_same_spec_on_a_separately_started_dask_scheduler_and_worker(tmp_path):
    dask_cli = shutil.which("dask", path=str(Path(sys.executable).parent)) or shutil.which("dask")
    assert dask_cli, "the `dask` command of dask[distributed] is not installed"
    port = _free_port()
    addr = f"tcp://127.0.0.1:{port}"
    env = os.environ | {"PYTHONUNBUFFERED": "1"}
    sched = subprocess.Popen(
        [dask_cli, "scheduler", "--host", "127.0.0.1", "--port", str(port), "--no-dashboard"],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
        env=env,
    )
    worker = subprocess.Popen(
        [dask_cli, "worker", addr, "--nworkers", "1", "--nthreads", "1", "--no-dashboard", "--no-nanny"],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
        env=env,
    )
    try:
        spec_file = tmp_path / "spec.yaml"
        spec_file.write_text(yaml.safe_dump(MEDIUM_2X8 | {"monte_carlo": {"runs": 2, "seed": 7}}))
        deadline = time.monotonic() + 60
        from dask.distributed import Client

        while True:  # wait for the worker to register
            try:
                with Client(addr, timeout=5) as c:
                    if c.nthreads():
                        break
            except OSError:
                pass
            assert time.monotonic() < deadline, "the dask scheduler/worker did not come up"
            time.sleep(0.5)
        r = subprocess.run(
            [
                sys.executable,
                "-m",
                "freefloat",
                "campaign",
                str(spec_file),
                "--out",
                str(tmp_path / "o"),
                "--scheduler",
                addr,
            ],
            capture_output=True,
            text=True,
            timeout=300,
        )
        assert r.returncode == 0, r.stderr[-2000:]
        res = json.loads((tmp_path / "o" / "results.json").read_text())
        assert res["scheduler"] == addr and res["runs_done"] == 4 and res["runs_new"] == 4
        rows = _rows(tmp_path / "o")
        assert len(rows) == 4 and {r["worker"].split(":")[-1] for r in rows} == {str(worker.pid)}
    finally:
        for p in (worker, sched):
            p.terminate()
        for p in (worker, sched):
            try:
                p.wait(timeout=20)
            except subprocess.TimeoutExpired:
                p.kill()


@pytest.mark.slow
def test_repair_quarantines_damaged_files_and_runs_their_runs_again(tmp_path):
    s = _spec(grid={"initial.base_velocity.0": [1.0, 2.0]}, monte_carlo=None)
    _fake_done_rows(s, tmp_path, 2)
    f = dataset.files(tmp_path / "runs")[0][1]
    f.write_bytes(f.read_bytes()[:100])  # truncated, as by a full disk
    res = cp.run_campaign(s, tmp_path, workers=1, progress=False, repair=True, echo=lambda *_: None)
    assert (tmp_path / "quarantine" / f"status=done-{f.name}").is_file()
    assert res["runs_new"] == 2 and res["runs_done"] == 2
    assert len(_rows(tmp_path)) == 2


def test_cli_bad_input_is_one_clear_line(tmp_path):
    from click.testing import CliRunner

    from freefloat.cli import main

    r = CliRunner().invoke(main, ["campaign", "zhang2020_velocity_swep", "--out", str(tmp_path / "o")])
    assert r.exit_code == 2 and "did you mean zhang2020_velocity_sweep" in r.output
    r = CliRunner().invoke(main, ["campaign", "zhang2020_velocity_sweep"])
    assert r.exit_code == 2 and "--out DIR is required" in r.output
    r = CliRunner().invoke(main, ["campaign", "zhang2020_velocity_sweep", "--out", str(tmp_path), "--runs", "0"])
    assert r.exit_code == 2 and "--runs" in r.output
    r = CliRunner().invoke(main, ["campaign", "--list"])
    assert r.exit_code == 0 and "zhang2020_velocity_sweep" in r.output and "naveen_noise_monte_carlo" in r.output


@pytest.mark.slow
def test_ctrl_c_keeps_the_finished_runs_and_the_same_command_continues(tmp_path):
    # Ctrl-C as soon as the progress line reports a finished run, with runs long enough (about 0.5 s each on a fast
    # machine, 16 in all) that the campaign is surely still running then. Waiting for rows on disk instead raced:
    # the writer flushes every 5 s, a fast machine finished all 16 runs first, and the signal hit the exiting process
    spec = json.loads(json.dumps(MEDIUM_2X8))
    spec["set"]["duration"] = 40.0
    spec_file = tmp_path / "spec.yaml"
    spec_file.write_text(yaml.safe_dump(spec))
    args = ["campaign", str(spec_file), "--out", str(tmp_path / "o"), "--workers", "1"]
    # once a run is done (the progress bar's postfix: "done 1, failed 0")
    r = sigint_when(start_cli(args), r"done [1-9]", regex=True)
    assert r.code == 130 and "run the same command again to continue" in r.err, (r.code, r.err[-2000:])
    # within a second: the local worker is killed, not waited for (a graceful shutdown took about 5 s)
    assert r.took < 1.0, f"the campaign exited {r.took:.2f} s after Ctrl-C"
    res = json.loads((tmp_path / "o" / "results.json").read_text())
    assert res["interrupted"] is True and 1 <= res["runs_done"] < 16
    kept = res["runs_done"]
    r = subprocess.run([sys.executable, "-m", "freefloat.cli", *args], capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr[-2000:]
    res = json.loads((tmp_path / "o" / "results.json").read_text())
    assert res["runs_done"] == 16 and res["runs_new"] == 16 - kept and len(_rows(tmp_path / "o")) == 16

"""The command line, run as a user would."""

import json
import subprocess
import sys

import numpy as np
import pytest

import freefloat as ff


def run(*args, ok=True):
    r = subprocess.run([sys.executable, "-m", "freefloat.cli", *args], capture_output=True, text=True, timeout=600)
    if ok:
        assert r.returncode == 0, r.stderr
    return r


@pytest.mark.parametrize(
    "cmd",
    [
        [],
        ["models"],
        ["simulate"],
        ["demo"],
        ["identify"],
        ["identify", "minimal"],
        ["params"],
        ["params", "minimal"],
        ["excite"],
        ["reactions"],
        ["scenarios"],
        ["identify", "postcapture"],
    ],
)
def test_every_command_has_help(cmd):
    r = run(*cmd, "--help")
    assert "Usage:" in r.stdout and len(r.stdout) > 200


def test_models_lists_builtins():
    r = run("models")
    assert "naveen_dual_arm" in r.stdout and "valverde_ch7_two_arm" in r.stdout
    assert "name: zhang2020_3d" in run("models", "--show", "zhang2020_3d").stdout


@pytest.mark.slow
def test_simulate_writes_parquet_json_and_figure(tmp_path):
    out = tmp_path / "run.parquet"
    r = run("simulate", "valverde_ch5_single_arm", "--t-final", "1", "--out", str(out))
    assert "momentum drift" in r.stdout
    res = json.loads(out.with_suffix(".results.json").read_text())
    assert res["samples"] == 101 and res["momentum_drift_angular_rel"] < 1e-9
    assert out.exists() and out.with_suffix(".png").stat().st_size > 10_000


@pytest.mark.slow
def test_demo_runs(demo_run):
    _, out, r = demo_run
    res = json.loads((out / "results.json").read_text())
    assert res["momentum_drift_linear_rel"] < 1e-10 and res["energy_minus_work_rel"] < 1e-9
    assert "peak joint torques" in r.stdout and (out / "demo.png").exists()


def test_bad_model_gives_one_clear_line(tmp_path):
    r = run("simulate", "no_such_robot", ok=False)
    assert r.returncode == 2 and "built-in robot" in r.stderr and "Traceback" not in r.stderr
    bad = tmp_path / "bad.yaml"
    bad.write_text("name: x\nbodies:\n  - name: b\n    inertial: {mass: -1}\n")
    r = run("simulate", str(bad), ok=False)
    assert r.returncode == 2 and "negative" in r.stderr and "Traceback" not in r.stderr


@pytest.mark.slow
def test_params_minimal_prints_and_writes_table4(tmp_path):
    r = run("params", "minimal", "naveen_dual_arm", "--method", "closed-form", "--out", str(tmp_path))
    assert "52 minimal parameters" in r.stdout and "0.09*L4.m" in r.stdout
    res = json.loads((tmp_path / "results.json").read_text())
    assert res["rank"] == 52 and len(res["names"]) == len(res["expressions"]) == len(res["values"]) == 52
    assert abs(res["values"][3] - (-96.63)) < 1e-9 and res["known_bodies"] == ["wheel_x", "wheel_y", "wheel_z"]
    r = run("params", "minimal", "naveen_dual_arm", "--known", "")
    assert "73 minimal parameters" in r.stdout


def test_params_minimal_closed_form_refuses_prismatic():
    r = run("params", "minimal", "valverde_ch7_two_arm", "--method", "closed-form", ok=False)
    assert r.returncode == 2 and 'method="numeric"' in r.stderr and "Traceback" not in r.stderr


@pytest.mark.slow
def test_identify_minimal_from_a_simulation_and_from_a_file(tmp_path):
    r = run("identify", "minimal", "naveen_dual_arm", "--simulate", "16", "--out", str(tmp_path))
    assert "eqs. 38-39" in r.stdout
    res = json.loads((tmp_path / "results.json").read_text())
    assert len(res["estimate"]) == 52 and res["median_rel_error_pct"] < 1.0
    r2 = run("identify", "minimal", "naveen_dual_arm", "--data", str(tmp_path / "telemetry.parquet"))
    assert "52 minimal parameters" in r2.stdout
    bad = run("identify", "minimal", "naveen_dual_arm", ok=False)
    assert bad.returncode == 2 and "exactly one of --data" in bad.stderr


@pytest.mark.slow
def test_identify_minimal_full_urdf_and_weights(tmp_path):
    r = run(
        "identify",
        "minimal",
        "naveen_dual_arm_consistent",
        "--simulate",
        "16",
        "--weights",
        "auto",
        "--full",
        "--prior",
        "naveen_dual_arm_offset",
        "--out",
        str(tmp_path),
    )
    assert "physically consistent" in r.stdout
    res = json.loads((tmp_path / "results.json").read_text())
    assert res["consistent"]["max_rel_deviation"] < 1e-5
    # The URDF written back loads without allow_nonphysical and has the identified momentum model.
    m = ff.Model.from_urdf(tmp_path / "identified.urdf")
    truth = ff.models.load("naveen_dual_arm_consistent")
    mp = ff.minimal_parameters(truth, "closed-form")
    np.testing.assert_allclose(mp.from_standard(m.parameters()), res["estimate"], rtol=1e-4)
    bad = run("identify", "minimal", "naveen_dual_arm", "--simulate", "16", "--weights", "1,2", ok=False)
    assert bad.returncode == 2 and "--weights" in bad.stderr


@pytest.mark.slow
def test_identify_minimal_case1_like_for_like(tmp_path):
    """`identify minimal --case1`: Naveen, Shah, Misra's Case 1 under the paper's conditions, then one improvement a
    row. The paper's figures (Table 5: median 2.08 %, max 174.02 %; κ(G_m) = 248.8, Sec. VI.B) are printed beside
    ours. Our rows are held to figures measured by other paths: the 67 spread intervals at 1 kHz in
    docs/identification.md ("Cases 1-3": κ 1931, LS median 0.036-0.052 % over seeds 0-3 through
    `excitation_data(m, 67)` with its own noise, bias removal 0.0015-0.0083 %, max 0.06-0.30 %) and the designed
    trajectory in docs/excitation.md (κ 1405 on the true robot); `demo --case1` gives the same rows."""
    r = run("identify", "minimal", "naveen_dual_arm", "--case1", "--out", str(tmp_path))
    for printed in ("2.08 %", "174 %", "248.8"):
        assert printed in r.stdout, (printed, r.stdout)
    res = json.loads((tmp_path / "results.json").read_text())
    assert (tmp_path / "table.txt").read_text().count("\n") == 6 and "248.8" in (tmp_path / "table.txt").read_text()
    assert res["paper"] == {"median_pct": 2.08, "max_pct": 174.02, "condition_number": 248.8}
    paper, cond, more, eiv, designed = res["rows"]
    assert (paper["median_pct"], paper["max_pct"], paper["condition_number"]) == (2.08, 174.02, 248.8)
    # the paper's conditions: 67 s at 20 Hz, both ends included; a median of the paper's order (its 2.08 %)
    assert cond["samples"] == 67 * 20 + 1 and res["sample_rate_hz"] == 20.0
    assert 2.08 / 3 < cond["median_pct"] < 2.08 * 3, cond
    assert cond["max_pct"] > 5 * cond["median_pct"]  # a few poorly seen parameters, as in the paper
    # 1 kHz, plain LS: docs/identification.md's 67 spread intervals
    assert more["samples"] == 67 * 1000 + 1
    assert more["condition_number"] == pytest.approx(1931, rel=0.01)
    assert 0.02 < more["median_pct"] < 0.06 and more["max_pct"] < 0.5, more
    assert more["median_pct"] < cond["median_pct"] / 10
    # bias removal: the median falls several times, the maximum (variance, not bias) stays of the same size
    assert eiv["median_pct"] < 0.3 * more["median_pct"] and eiv["max_pct"] < 0.5, eiv
    assert designed["condition_number"] == pytest.approx(1405, rel=0.01)
    assert designed["median_pct"] < 0.3 * more["median_pct"] and designed["max_pct"] < 1.0, designed
    # the same function behind `freefloat demo --case1`
    d = run("demo", "--case1", "--out", str(tmp_path / "demo"))
    assert "2.08 %" in d.stdout and "174 %" in d.stdout
    rows = json.loads((tmp_path / "demo" / "case1.json").read_text())["rows"]
    assert [x["median_pct"] for x in rows] == [x["median_pct"] for x in res["rows"]]


@pytest.mark.parametrize(
    "args, expect",
    [
        (["--case1", "--simulate", "16"], "drop --data, --simulate and --trajectory"),
        (["--case1", "--full"], "do not apply to it: --full"),
        (["--case1", "--rate-noise", "none"], "--rate-noise"),
        (["--simulate", "16", "--case1-rate", "10"], "--case1-rate only go with --case1"),
        (["--case1", "--case1-rate", "0"], "sampling rate must be above 0 and at most 1000 Hz"),
        (["--case1", "--case1-rate", "5000"], "at most 1000 Hz"),
        (["--case1", "--case1-draws", "0"], "--case1-draws"),
    ],
)
def test_identify_minimal_case1_bad_input(args, expect):
    r = run("identify", "minimal", "naveen_dual_arm", *args, ok=False)
    assert r.returncode != 0 and expect in r.stderr and "Traceback" not in r.stderr, r.stderr


def test_identify_minimal_case1_needs_the_naveen_robot():
    r = run("identify", "minimal", "valverde_ch5_single_arm", "--case1", ok=False)
    assert r.returncode != 0 and "Naveen, Shah, Misra robot" in r.stderr and "Traceback" not in r.stderr, r.stderr


@pytest.mark.slow
def test_excite_writes_a_trajectory_that_identify_consumes(tmp_path):
    r = run("excite", "naveen_dual_arm", "--guess", "naveen_dual_arm_offset", "--maxiter", "3", "--out", str(tmp_path))
    assert "pruning kept" in r.stdout and "Table 3" in r.stdout
    res = json.loads((tmp_path / "results.json").read_text())
    assert 0 < res["n_kept"] < 256 and len(res["kept_intervals"]) == res["n_kept"]
    assert (tmp_path / "fig4.png").stat().st_size > 10_000
    r2 = run(
        "identify",
        "minimal",
        "naveen_dual_arm",
        "--trajectory",
        str(tmp_path / "trajectory.json"),
        "--out",
        str(tmp_path / "id"),
    )
    assert "simulating naveen_dual_arm along" in r2.stdout
    ident = json.loads((tmp_path / "id" / "results.json").read_text())
    assert ident["median_rel_error_pct"] < 1.0 and "bias compensation" in ident["solver"]
    bad = run("excite", "naveen_dual_arm", "--out", str(tmp_path / "bad"), ok=False)  # Table 2 is non-physical
    assert bad.returncode != 0 and "non-physical" in bad.stderr and "Traceback" not in bad.stderr


def test_scenarios_lists_postcapture_scenarios_and_shipped_trajectories():
    out = run("scenarios").stdout.splitlines()
    names = [ln.split()[0] for ln in out if ln.strip() and not ln.startswith("#")]
    assert {
        "zhang2020_2d_small",
        "zhang2020_2d_medium",
        "zhang2020_2d_large",
        "zhang2020_2d_sweep",
        "zhang2020_3d",
    } <= set(names)
    assert "naveen_exciting_trajectory" in names and len(names) >= 6
    line = next(ln for ln in out if ln.startswith("naveen_exciting_trajectory"))
    assert "63 intervals" in line and "naveen_dual_arm_offset" in line


def test_identify_minimal_trajectory_by_unknown_name_is_a_clear_error():
    r = run("identify", "minimal", "naveen_dual_arm", "--trajectory", "no_such_trajectory", ok=False)
    assert r.returncode == 2 and "Traceback" not in r.stderr
    assert "neither a file nor a built-in trajectory" in r.stderr and "naveen_exciting_trajectory" in r.stderr

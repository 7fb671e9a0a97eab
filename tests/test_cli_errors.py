"""No Python traceback reaches a command-line user, whatever the input: every command is run (as a user runs it,
a subprocess) on bad inputs — the issue's list of scenario mistakes, the fuzzing findings (non-UTF-8 telemetry,
a CSV with a byte-order mark, a string column), wrongly typed values, missing and unreadable files — and each
must end with a non-zero exit code and one `error:` line that says where (file, key, line), never "Traceback".
`--debug` shows the traceback."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import freefloat as ff
from freefloat.io import data as ffdata

PC = ffdata.read_text("scenarios", "zhang2020_2d_medium")
CL = ffdata.read_text("scenarios", "valverde_ch9_two_arm")
AD = ffdata.read_text("scenarios", "valverde_ch4_example_a")


def run(*args, cwd=None, timeout=120):
    env = {k: v for k, v in os.environ.items() if k != "FREEFLOAT_DEBUG"}
    return subprocess.run(
        [sys.executable, "-m", "freefloat.cli", *args],
        capture_output=True,
        text=True,
        timeout=timeout,
        cwd=cwd,
        env=env,
        stdin=subprocess.DEVNULL,
    )


def refused(r, *expect):
    assert r.returncode != 0, f"accepted:\n{r.stdout[-2000:]}\n{r.stderr[-2000:]}"
    assert "Traceback" not in r.stderr and "Traceback" not in r.stdout, r.stderr[-3000:]
    lines = [ln for ln in r.stderr.splitlines() if ln.startswith("error:") or ln.startswith("Error:")]
    assert lines, f"no error line: {r.stderr[-2000:]}"
    for e in expect:
        assert e in r.stderr, f"{e!r} not in {r.stderr[-2000:]!r}"
    return r.stderr


# -- scenario files: the list ----------------------------------------------------------------------------
SCENARIO_CASES = [
    ("sample_period: 0.1 ", "sample_period: 0.0001 ", ["line 6", "'sample_period'", "even multiple"]),
    ("sample_period: 0.1 ", "sample_period: -0.1 ", ["line 6", "'sample_period'", "> 0"]),
    ("sample_period: 0.1 ", "sample_period: 1.0e9 ", ["'sample_period'", "fewer than 3 samples"]),
    ("sample_period: 0.1 ", "sample_perod: 0.1 ", ["line 6", "did you mean 'sample_period'?"]),
    ("  forgetting: 1.0", "  forgeting: 1.0", ["did you mean 'forgetting'?", "identification"]),
    ("duration: 60.0", "duration: ten", ["line 4", "'duration'", "expected a number", "'ten'"]),
    ("duration: 60.0", "duration: 1.0e7", ["'duration'", "steps"]),
    ("transit_tolerance: 0.001", "transit_tolerance: -0.001", ["'identification.transit_tolerance'", "> 0"]),
    ("F_max: 10.0", "F_max: .nan", ["'control.F_max'", "finite"]),
    ("K_F: -1.0", "K_F: [1, 2", ["not valid YAML", "line"]),
    ("mass: 600.0", "mass: '600 kg'", ["'identification.guess.base.mass'"]),
]


@pytest.mark.parametrize("old,new,expect", SCENARIO_CASES, ids=[c[1].strip() for c in SCENARIO_CASES])
def test_bad_postcapture_scenario_gets_one_line_with_file_key_and_line(tmp_path, old, new, expect):
    assert old in PC
    f = tmp_path / "my.yaml"
    f.write_text(PC.replace(old, new, 1))
    err = refused(run("identify", "postcapture", str(f)), *expect)
    assert str(f) in err  # the file is named


@pytest.mark.parametrize(
    "content,expect",
    [
        (b"", "empty"),
        (b"   \n# only a comment\n", "empty"),
        (b"- a\n- b\n", "mapping"),
        (b"\xff\xfe not utf-8", "UTF-8"),
        (b"model: [unclosed\n", "not valid YAML"),
        (b"kind: postcapure\n", "did you mean 'postcapture'?"),
    ],
)
def test_unreadable_scenario_files(tmp_path, content, expect):
    f = tmp_path / "s.yaml"
    f.write_bytes(content)
    refused(run("identify", "postcapture", str(f)), expect)


def test_identify_cl_and_adaptive_scenarios_are_schema_checked(tmp_path):
    f = tmp_path / "cl.yaml"
    f.write_text(CL.replace("  sigma_th: 0.001", "  sigma_tht: 0.001"))
    refused(run("identify", "cl", str(f)), "did you mean 'sigma_th'?", "line")
    f.write_text(CL.replace("duration: 10.0", "duration: -1"))
    refused(run("identify", "cl", str(f)), "'duration'", "> 0")
    g = tmp_path / "ad.yaml"
    g.write_text(AD.replace("  rtol: 1.0e-10", "  rtol: 2"))
    refused(run("control", "adaptive", str(g)), "'simulation.rtol'", "< 1")
    g.write_text(AD.replace("  mode: continuous", "  mdoe: continuous"))
    refused(run("control", "adaptive", str(g)), "did you mean 'mode'?")


# -- telemetry files (fuzz findings) ----------------------------------------------------------------------------
@pytest.fixture(scope="module")
def telemetry_csv(tmp_path_factory):
    m = ff.models.load("zhang2020_2d_medium")
    tr = ff.simulate(m, m.neutral(), np.full(m.nv, 0.01), 2.0, 0.01)
    d = tmp_path_factory.mktemp("tel")
    tr.to_parquet(d / "t.parquet")
    import pyarrow.csv as pacsv
    import pyarrow.parquet as pq

    pacsv.write_csv(pq.read_table(d / "t.parquet"), d / "t.csv")
    return d / "t.csv"


def test_bad_telemetry_files(tmp_path, telemetry_csv):
    text = telemetry_csv.read_bytes()
    cases = {
        "latin1.csv": text[:200] + b"\xe9\xff" + text[200:],
        "string_column.csv": text.replace(b"\n0.5", b"\nhalf", 1) if b"\n0.5" in text else text + b"x,y\n",
        "empty.csv": b"",
        "header_only.csv": text.split(b"\n")[0] + b"\n",
    }
    for name, content in cases.items():
        f = tmp_path / name
        f.write_bytes(content)
        refused(run("identify", "minimal", "zhang2020_2d_medium", "--data", str(f)))


def test_csv_with_a_byte_order_mark_is_read(tmp_path, telemetry_csv):
    f = tmp_path / "bom.csv"
    f.write_bytes(b"\xef\xbb\xbf" + telemetry_csv.read_bytes())
    m = ff.models.load("zhang2020_2d_medium")
    a = ff.io.Telemetry.from_file(telemetry_csv, m)
    b = ff.io.Telemetry.from_file(f, m)
    np.testing.assert_array_equal(np.asarray(a.t), np.asarray(b.t))


# -- every command, bad arguments and files ---------------------------------------------------------------------
def test_every_command_refuses_bad_input_without_a_traceback(tmp_path):
    bad_yaml = tmp_path / "bad_model.yaml"
    bad_yaml.write_text("name: x\nbodies:\n  - name: base\n    inertial: {mas: 1}\n")
    bad_urdf = tmp_path / "bad.urdf"
    bad_urdf.write_text("<robot name='r'><link name='a'/><joint name='j' type='revolute'><parent link='a'/></joint>")
    binary = tmp_path / "bin.yaml"
    binary.write_bytes(b"\x00\xff\xfe\x80" * 20)
    missing = str(tmp_path / "nope.yaml")
    cases = [
        ("simulate", str(bad_yaml)),
        ("simulate", str(bad_urdf)),
        ("simulate", str(binary)),
        ("simulate", missing),
        ("simulate", "zhang2020_2d_medium", "--t-final", "-1"),
        ("simulate", "zhang2020_2d_medium", "--dt", "0"),
        ("simulate", "zhang2020_2d_medium", "--q0", "1,2"),
        ("simulate", "zhang2020_2d_medium", "--torques", str(tmp_path / "none.csv")),
        ("reactions", str(bad_yaml)),
        ("reactions", "zhang2020_2d_medium", "--dt", "-1"),
        ("excite", str(bad_yaml)),
        ("export", str(bad_urdf), "--urdf", str(tmp_path / "o.urdf")),
        ("params", "minimal", str(binary)),
        ("identify", "minimal", "zhang2020_2d_medium", "--data", missing),
        ("identify", "minimal", "zhang2020_2d_medium", "--data", str(bad_yaml)),
        ("identify", "postcapture", missing),
        ("identify", "postcapture", "no_such_scenario"),
        ("identify", "cl", str(binary)),
        ("control", "adaptive", str(binary)),
        ("control", "ddp", str(binary)),
        ("control", "ddp", "no_such_scenario"),
        ("campaign", str(binary), "--out", str(tmp_path / "c1")),
        ("campaign", missing, "--out", str(tmp_path / "c2")),
        ("convert", missing, "--from", "mujoco", "--model", "zhang2020_2d_medium"),
        ("report", str(tmp_path)),
    ]
    for args in cases:
        refused(run(*args))


def test_bad_model_file_names_key_and_closest(tmp_path):
    f = tmp_path / "m.yaml"
    f.write_text("name: x\nbodies:\n  - name: base\n    inertial: {mas: 1}\n")
    refused(run("simulate", str(f)), "did you mean `mass`?", str(f))
    f.write_text("name: x\nbodies:\n  - name: base\n    inertial: {mass: 1, inertia: [1, 2]}\n")
    err = refused(run("simulate", str(f)), "inertia", "[Ixx, Iyy, Izz]")
    assert "untagged" not in err


def test_campaign_spec_unknown_key(tmp_path):
    f = tmp_path / "c.yaml"
    f.write_text("name: c\nkind: postcapture\nscenario: zhang2020_2d_medium\ngird:\n  duration: [1.0]\n")
    refused(run("campaign", str(f), "--out", str(tmp_path / "o")), "did you mean 'grid'?", "line 4")
    f.write_text("name: c\nkind: postcapture\nscenario: zhang2020_2d_medium\ngrid:\n  duration: [60.0, ten]\n")
    refused(run("campaign", str(f), "--out", str(tmp_path / "o")), "grid 'duration' = 'ten'", "expected a number")


def test_debug_shows_the_traceback(tmp_path):
    f = tmp_path / "s.yaml"
    f.write_text(PC.replace("duration: 60.0", "duration: ten"))
    r = run("--debug", "identify", "postcapture", str(f))
    assert r.returncode != 0 and "Traceback" in r.stderr, r.stderr[-2000:]


def test_an_unexpected_exception_is_one_line_marked_as_a_bug():
    from freefloat.cli import _common

    try:
        raise ZeroDivisionError("float division by zero")
    except ZeroDivisionError as e:
        import io
        from contextlib import redirect_stderr

        buf = io.StringIO()
        with redirect_stderr(buf):
            code = _common.report_error(e)
    out = buf.getvalue()
    assert code == 3 and out.count("\n") == 1 and "internal error" in out and "--debug" in out, out


def test_the_test_can_fail(tmp_path):
    # the helper itself must flag a traceback (a test that could not fail proves nothing)
    fake = subprocess.CompletedProcess([], 1, "", "Traceback (most recent call last):\nerror: x\n")
    with pytest.raises(AssertionError):
        refused(fake)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(pytest.main([str(Path(__file__))]))

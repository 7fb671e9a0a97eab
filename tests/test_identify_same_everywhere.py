"""Identification behaves the same however it is called: declared rate noise, one minimal-set default, zero true
values, truth only when asked, the unobservable scale explained, tags kept in URDF."""

from __future__ import annotations

import json

import numpy as np
import pytest
from click.testing import CliRunner

import freefloat as ff
from freefloat._core import InputError
from freefloat.cli import main
from freefloat.constants import SIGMA_ANG, SIGMA_JOINT, SIGMA_LIN
from freefloat.identification import identify as idf
from freefloat.io.telemetry import Telemetry

ROBOT = "naveen_dual_arm_consistent"


@pytest.fixture(scope="module")
def noisy(tmp_path_factory):
    m = ff.models.load(ROBOT)
    telem, traj = idf.excitation_data(m, n_intervals=12)
    d = tmp_path_factory.mktemp("tel")
    telem.to_parquet(d / "t.parquet")
    telem.to_csv(d / "t.csv")
    return m, telem, traj, d


@pytest.mark.slow
def test_telemetry_declares_its_rate_noise_in_every_file(noisy):
    m, telem, _, d = noisy
    assert telem.rate_noise == [SIGMA_LIN, SIGMA_ANG, SIGMA_JOINT]
    for f in ("t.parquet", "t.csv"):
        assert Telemetry.from_file(d / f, m).rate_noise == telem.rate_noise
    assert Telemetry.from_trajectory(noisy[2]).rate_noise is None  # noise-free: nothing declared


@pytest.mark.slow
def test_same_estimate_from_memory_file_and_explicit_noise(noisy):
    m, telem, _, d = noisy
    a = ff.identify_minimal(m, telem, rate_noise="data")
    b = ff.identify_minimal(m, d / "t.parquet", rate_noise="data")
    c = ff.identify_minimal(m, telem, rate_noise=(SIGMA_LIN, SIGMA_ANG, SIGMA_JOINT))
    np.testing.assert_allclose(a.estimate, b.estimate, rtol=1e-12)
    np.testing.assert_allclose(a.estimate, c.estimate, rtol=1e-12)
    assert "errors-in-variables bias removal" in a.estimator and "declared by the data" in a.estimator
    with pytest.warns(UserWarning, match="declare rate noise.*no errors-in-variables bias removal"):
        plain = ff.identify_minimal(m, telem)
    assert "no rate-noise removal" in plain.estimator
    # removal matters: plain least squares is biased, the removal brings the median error down
    assert a.errors(m)["median_rel_error_pct"] < plain.errors(m)["median_rel_error_pct"]


@pytest.mark.slow
def test_cli_simulated_and_file_give_the_same_estimate(noisy, tmp_path):
    m, telem, _, d = noisy
    r = CliRunner()
    out = r.invoke(main, ["identify", "minimal", ROBOT, "--data", str(d / "t.parquet"), "--out", str(tmp_path)])
    assert out.exit_code == 0, out.output
    assert "estimator: least squares + errors-in-variables bias removal" in out.output
    res = json.loads((tmp_path / "results.json").read_text())
    np.testing.assert_allclose(res["estimate"], ff.identify_minimal(m, telem, rate_noise="data").estimate, rtol=1e-12)
    # real telemetry: no truth column unless asked for
    assert "true" not in out.output.splitlines()[2] and "truth" not in res
    out = r.invoke(main, ["identify", "minimal", ROBOT, "--data", str(d / "t.parquet"), "--truth-model", ROBOT])
    assert out.exit_code == 0 and "rel. error" in out.output and "eqs. 38-39" in out.output


@pytest.mark.slow
def test_one_minimal_set_default_for_params_and_identify(tmp_path):
    m = ff.models.load(ROBOT)
    r = CliRunner()
    out = r.invoke(main, ["params", "minimal", ROBOT, "--out", str(tmp_path)])
    assert out.exit_code == 0, out.output
    names = json.loads((tmp_path / "results.json").read_text())["names"]
    assert names == ff.minimal_parameters(m, "closed-form").names  # auto = the closed form here
    tel, _ = idf.excitation_data(m, n_intervals=12, noise=False)
    assert ff.identify_minimal(m, tel).names == names
    # a model outside the closed form: auto falls back to numeric, in both
    v = ff.models.load("valverde_ch7_two_arm")
    assert ff.minimal_parameters(v, "auto").names == ff.minimal_parameters(v, "numeric").names


@pytest.mark.slow
def test_zero_true_values_are_reported_by_absolute_error(noisy, tmp_path):
    m, *_ = noisy
    mp = ff.minimal_parameters(m, "closed-form")
    P = m.parameters()
    j = m.body_index("L6")
    mass, c = P[j, 0], P[j, 1:4] / P[j, 0]
    Io = np.array([[P[j, 4], P[j, 5], P[j, 7]], [P[j, 5], P[j, 6], P[j, 8]], [P[j, 7], P[j, 8], P[j, 9]]])
    Ic = Io - mass * (c @ c * np.eye(3) - np.outer(c, c))
    c[1] = 0.0  # L6's CoM moved onto its x-z plane, same CoM inertia: L6.mcy = 0, a zero true minimal parameter
    Io = Ic + mass * (c @ c * np.eye(3) - np.outer(c, c))
    P[j] = [mass, *(mass * c), Io[0, 0], Io[0, 1], Io[1, 1], Io[0, 2], Io[1, 2], Io[2, 2]]
    truth = m.with_parameters(P)
    zero = [n for n, x in zip(mp.names, mp.from_standard(truth.parameters())) if x == 0]
    assert zero, "the test needs a zero true minimal parameter"
    tel, _ = idf.excitation_data(truth, n_intervals=12, noise=False)
    res = ff.identify_minimal(truth, tel)
    e = res.errors(truth)
    assert e["zero_truth"]["names"] == zero and max(e["zero_truth"]["abs_error"]) < 1e-6
    assert e["median_rel_error_pct"] < 1e-6
    assert "abs" in res.table(truth=truth) and "exactly 0" in res.table(truth=truth)
    res.save(tmp_path, truth=truth)  # writes, instead of aborting
    assert json.loads((tmp_path / "results.json").read_text())["zero_truth"]["names"] == zero


@pytest.mark.slow
def test_no_known_body_explains_the_unobservable_scale(noisy, tmp_path):
    m, telem, *_ = noisy
    with pytest.raises(InputError, match="overall scale.*unobservable.*--known"):
        ff.identify_minimal(m, telem, known=[], rate_noise="data")
    urdf = ff.models.load(ROBOT).to_urdf()  # as a URDF from elsewhere: no freefloat tags, so no known body
    r = CliRunner()
    (tmp_path / "robot.urdf").write_text(urdf.replace("<freefloat tags", "<ignored tags"))
    out = r.invoke(main, ["params", "minimal", str(tmp_path / "robot.urdf")])
    assert out.exit_code == 0, out.output
    assert "overall scale" in out.output and "--known" in out.output


def test_urdf_keeps_tags_for_every_command():
    m = ff.models.load(ROBOT)
    r = ff.Model.from_urdf_string(m.to_urdf())
    assert r.tags == m.tags
    assert ff.minimal_parameters(r, "auto").known == ff.minimal_parameters(m, "auto").known
    pin = pytest.importorskip("pinocchio")
    assert pin.buildModelFromXML(m.to_urdf()).nbodies == m.nbodies  # other URDF readers skip the element

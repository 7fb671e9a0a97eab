"""Earlier names of the built-in robots, scenarios and trajectories still load (listings show the new names)."""

import pytest
from click.testing import CliRunner

import freefloat as ff
import freefloat.postcapture as pc
from freefloat import data
from freefloat.cli import main

MODEL_ALIASES = {
    "seed000_2d_large": "zhang2020_2d_large",
    "seed000_2d_medium": "zhang2020_2d_medium",
    "seed000_2d_small": "zhang2020_2d_small",
    "seed000_3d": "zhang2020_3d",
    "seed001_dual_arm": "naveen_dual_arm",
    "seed001_dual_arm_consistent": "naveen_dual_arm_consistent",
    "seed001_dual_arm_offset": "naveen_dual_arm_offset",
    "thesis_ch5_single_arm": "valverde_ch5_single_arm",
    "thesis_ch7_two_arm": "valverde_ch7_two_arm",
}


@pytest.mark.parametrize("old,new", sorted(MODEL_ALIASES.items()))
def test_model_alias_loads_the_renamed_robot(old, new):
    assert new in ff.models.names() and old not in ff.models.names()
    assert ff.models.is_builtin(old) and ff.models.is_builtin(new)
    a, b = ff.models.load(old), ff.models.load(new)
    assert a.name == b.name == new
    assert (a.parameters() == b.parameters()).all()
    assert ff.models.source(old) == ff.models.source(new)


def test_unknown_model_names_the_current_ones():
    assert not ff.models.is_builtin("no_such_robot")
    with pytest.raises(ff.InputError, match="naveen_dual_arm"):
        ff.models.load("no_such_robot")


@pytest.mark.parametrize("old,new", sorted(data.ALIASES["scenarios"].items()))
def test_scenario_alias_loads(old, new):
    assert new in data.names("scenarios") and old not in data.names("scenarios")
    assert pc.load_scenario(old).name == pc.load_scenario(new).name == new


def test_trajectory_alias_loads():
    with data.path("trajectories", "seed001_exciting_trajectory") as p:
        assert p.name == "naveen_exciting_trajectory.json"


def test_cli_accepts_an_alias_and_lists_new_names():
    r = CliRunner().invoke(main, ["models"])
    assert r.exit_code == 0 and "naveen_dual_arm" in r.output and "seed001_dual_arm " not in r.output
    assert "aliases" in r.output
    r = CliRunner().invoke(main, ["params", "minimal", "seed001_dual_arm"])
    assert r.exit_code == 0, r.output
    assert r.output.startswith("naveen_dual_arm: 52 minimal parameters")
    r = CliRunner().invoke(main, ["scenarios"])
    assert r.exit_code == 0 and "zhang2020_2d_medium" in r.output and "seed000" not in r.output


def test_controller_modules_are_attributes_of_the_control_package_without_an_import_line():
    import importlib

    import freefloat as ff

    assert ff.control.ddp is importlib.import_module("freefloat.control.ddp")
    assert ff.control.ddp_closed_loop is importlib.import_module("freefloat.control.ddp_closed_loop")
    assert not hasattr(ff.control, "no_such_controller")
    with pytest.raises(AttributeError, match="no_such_controller"):
        ff.control.no_such_controller  # noqa: B018

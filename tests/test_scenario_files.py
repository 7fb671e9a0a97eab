"""Scenario files of every kind: found by name or path, parsed with the file and line of a YAML error, and run
only by the command of their kind."""

import pytest

from freefloat import InputError
from freefloat.io import scenario_files


def test_every_builtin_scenario_has_a_known_kind_and_a_description():
    entries = scenario_files.listing()
    assert len(entries) >= 5
    for s in entries:
        assert s.kind in scenario_files.KINDS and s.description, s
        assert s.command.endswith(s.name)


def test_a_postcapture_scenario_is_read_as_its_kind_and_refused_as_another(tmp_path):
    d, source = scenario_files.read("zhang2020_2d_medium", kind="postcapture")
    assert d["model"] == "zhang2020_2d_medium" and "zhang2020_2d_medium" in source
    with pytest.raises(InputError, match="is a 'postcapture' scenario.*freefloat identify postcapture"):
        scenario_files.read("zhang2020_2d_medium", kind="control_ddp")


def test_yaml_error_names_file_and_line(tmp_path):
    f = tmp_path / "broken.yaml"
    f.write_text("kind: control_adaptive\nduration: 10\n  bad: [1, 2\n")
    with pytest.raises(InputError, match=r"broken.yaml: line \d+, column \d+: not valid YAML"):
        scenario_files.read(f, kind="control_adaptive")


def test_unknown_kind_and_missing_file_are_named(tmp_path):
    f = tmp_path / "odd.yaml"
    f.write_text("kind: juggling\n")
    with pytest.raises(InputError, match="key 'kind': unknown scenario kind 'juggling'"):
        scenario_files.read(f, kind="postcapture")
    with pytest.raises(InputError, match="scenario 'no_such' not found"):
        scenario_files.read("no_such", kind="postcapture")
    g = tmp_path / "list.yaml"
    g.write_text("- 1\n- 2\n")
    with pytest.raises(InputError, match="must be a YAML mapping"):
        scenario_files.read(g, kind="postcapture")

"""The declared schemas of scenario and campaign files (freefloat/io/scenario_schemas.py): every built-in file
passes; a mistake is refused with the file, the line, the key as the file writes it and, for a typo, the closest
valid key; a block shared by several kinds is one declaration."""

from __future__ import annotations

import numpy as np
import pytest
import yaml

from freefloat import InputError
from freefloat.campaign import spec as campaign_spec
from freefloat.io import data, scenario_files, schema
from freefloat.postcapture import scenario as pc

PC = data.read_text("scenarios", "zhang2020_2d_medium")


def check_text(text: str, kind: str = "postcapture", source: str = "my.yaml") -> None:
    schema.check(kind, yaml.safe_load(text), source, text)


def line_of(text: str, needle: str) -> int:
    return next(i + 1 for i, ln in enumerate(text.splitlines()) if needle in ln)


def test_every_built_in_scenario_and_campaign_passes_its_schema():
    for s in scenario_files.listing():
        scenario_files.read(s.name, s.kind)
    for name in campaign_spec.builtin_names():
        campaign_spec.load(name)


@pytest.mark.parametrize(
    "old,new,key,words",
    [
        ("sample_period: 0.1 ", "sample_perod: 0.1 ", "sample_perod", ["did you mean 'sample_period'?"]),
        ("  forgetting: 1.0", "  forgeting: 1.0", "forgeting", ["identification.forgeting", "'forgetting'?"]),
        ("sample_period: 0.1 ", "sample_period: 0.0001 ", "sample_period", ["even multiple"]),
        ("sample_period: 0.1 ", "sample_period: -5 ", "sample_period", ["must be > 0, got -5"]),
        ("sample_period: 0.1 ", "sample_period: 1e12 ", "sample_period", ["fewer than 3 samples"]),
        ("duration: 60.0", "duration: ten", "duration", ["expected a number, got 'ten'"]),
        ("duration: 60.0", "duration: 1.0e7", "duration", ["1e+10 steps"]),
        ("transit_tolerance: 0.001", "transit_tolerance: -0.001", "transit_tolerance", ["> 0, got -0.001"]),
        ("  forgetting: 1.0", "  forgetting: 1.5", "forgetting", ["<= 1"]),
        ("K_P: 0.25", "K_P: [0.25, x]", "K_P", ["a number or a list of numbers"]),
        ("base_rate: 0.1", "base_rate: .inf", "base_rate", ["finite"]),
        ("  project: false", "  project: 1", "project", ["bool"]),
    ],
)
def test_postcapture_mistakes_name_file_line_and_key(old, new, key, words):
    text = PC.replace(old, new, 1) if old in PC else PC.replace("  forgetting: 1.0", "  forgetting: 1.0\n" + new)
    assert text != PC
    with pytest.raises(InputError) as e:
        check_text(text)
    msg = str(e.value)
    assert msg.startswith(f"my.yaml: line {line_of(text, key + ':')}:"), msg
    assert key in msg, msg
    for w in words:
        assert w in msg, msg


def test_numbers_written_without_a_dot_are_numbers():
    # PyYAML (YAML 1.1) reads `1e6` as text; the schema takes it as the number it spells, as YAML 1.2 does
    check_text(PC.replace("P0: 1.0e6", "P0: 1e6"))
    with pytest.raises(InputError, match="'identification.P0': expected a number, got '1e6x'"):
        check_text(PC.replace("P0: 1.0e6", "P0: 1e6x"))


def test_errors_name_the_files_keys_not_internal_arguments(tmp_path):
    f = tmp_path / "s.yaml"
    f.write_text(PC.replace("  P0: 1.0e6", "  P0: -1"))
    with pytest.raises(InputError) as e:
        pc.load_scenario(f)
    assert "identification.P0" in str(e.value) and "p_mu0" not in str(e.value)
    f.write_text(PC.replace("  F_max: 10.0", "  F_max: 0"))
    with pytest.raises(InputError, match=r"control\.F_max.*> 0") as e:
        pc.load_scenario(f)
    assert "f_max" not in str(e.value)


def test_empty_and_non_mapping_files(tmp_path):
    f = tmp_path / "e.yaml"
    for content, words in [("", "empty"), ("# nothing\n", "empty"), ("[1, 2]\n", "mapping"), ("a: [1\n", "YAML")]:
        f.write_text(content)
        with pytest.raises(InputError, match=words):
            pc.load_scenario(f)


def test_a_block_shared_by_kinds_is_one_declaration():
    class Gyro(schema.Block):
        noise: schema.NonNegative = 0.0
        bias: schema.Number = 0.0

    class Sensors(schema.Block):
        gyro: Gyro | None = None

    try:
        schema.register_block("test_sensors", Sensors, kinds=("postcapture", "identify_cl"))
        check_text(PC + "test_sensors:\n  gyro: {noise: 0.01}\n")
        with pytest.raises(InputError, match=r"line \d+: unknown key 'test_sensors.gyro.nosie' \(did you mean 'noise'"):
            check_text(PC + "test_sensors:\n  gyro: {nosie: 0.01}\n")
        with pytest.raises(InputError, match=r"'test_sensors.gyro.noise': must be >= 0"):
            check_text(PC + "test_sensors:\n  gyro: {noise: -1}\n")
        assert "test_sensors" in schema.fields_of("identify_cl")
        assert "test_sensors" not in schema.fields_of("control_adaptive")
    finally:
        schema._BLOCKS.pop("test_sensors", None)
        schema._BUILT.clear()
    with pytest.raises(InputError, match="unknown key 'test_sensors'"):
        check_text(PC + "test_sensors:\n  gyro: {noise: 0.01}\n")


def test_other_kinds_have_schemas_too():
    ad = data.read_text("scenarios", "valverde_ch4_example_a")
    with pytest.raises(InputError, match=r"unknown key 'gains.K_x'"):
        check_text(ad.replace("  K_i: 10.0", "  K_i: 10.0\n  K_x: 1"), "control_adaptive")
    ddp = data.read_text("scenarios", "valverde_ch8_tracking")
    with pytest.raises(InputError, match=r"unknown key 'horizn' \(did you mean 'horizon'"):
        check_text(ddp.replace("horizon: 640", "horizn: 640"), "control_ddp")
    with pytest.raises(InputError, match=r"'horizon': expected an integer"):
        check_text(ddp.replace("horizon: 640", "horizon: 6.5"), "control_ddp")


def test_campaign_files_are_checked_with_lines(tmp_path):
    f = tmp_path / "c.yaml"
    head = "name: c\nkind: postcapture\nscenario: zhang2020_2d_medium\n"
    f.write_text(head + "grid:\n  duration: [1.0]\nmonte_carlo:\n  rnus: 3\n")
    with pytest.raises(InputError, match=r"c.yaml: line 7: unknown key 'monte_carlo.rnus' \(did you mean 'runs'"):
        campaign_spec.load(f)
    f.write_text("name: c\nkind: postcapture\nscenario: zhang2020_2d_medium\ngrid:\n  duration: [1.0, ten]\n")
    with pytest.raises(InputError, match=r"grid 'duration' = 'ten'.*expected a number"):
        campaign_spec.load(f)
    # a value out of range is left to its run (recorded as that run's error), not refused up front
    f.write_text("name: c\nkind: postcapture\nscenario: zhang2020_2d_medium\ngrid:\n  duration: [1.0, -1.0]\n")
    assert campaign_spec.load(f).runs_total == 2


# -- one declaration: the schema's blocks are made from the classes that run them (issue 35) -------------------
def test_actuator_blocks_are_the_actuator_classes():
    """Each list of an `actuators:` block has exactly the fields of its class (freefloat.Wheel, ...), in the
    engine's key order, with the class's defaults: the schema is made from the class, so a field exists once."""
    import dataclasses

    from freefloat.io import scenario_schemas as ss
    from freefloat.simulation import actuators as act

    for lst, cls, block in (
        ("limits", act.JointLimit, ss.ActLimit),
        ("wheels", act.Wheel, ss.ActWheel),
        ("thrusters", act.Thruster, ss.ActThruster),
        ("tanks", act.Tank, ss.ActTank),
    ):
        fields = {f.name: f for f in dataclasses.fields(cls)}
        assert list(block.model_fields) == act.FIELDS[lst]["keys"], lst
        assert set(block.model_fields) == set(fields), lst
        for name, f in fields.items():
            mf = block.model_fields[name]
            if f.default is dataclasses.MISSING and f.default_factory is dataclasses.MISSING:
                assert mf.is_required(), (lst, name)
            else:
                want = f.default if f.default is not dataclasses.MISSING else f.default_factory()
                assert mf.default == want, (lst, name)


def test_a_field_added_to_the_declaration_shows_up_in_the_schema():
    import dataclasses

    from freefloat.io import schema
    from freefloat.simulation import actuators as act

    @dataclasses.dataclass
    class Tank2(act.Tank):
        pressure: float = schema.key(schema.Positive, 2e6)

    block = schema.block_of(Tank2)
    assert "pressure" in block.model_fields and block.model_fields["pressure"].default == 2e6
    with pytest.raises(ValueError):
        block.model_validate({"name": "t", "mass": 1.0, "pressure": -1.0})


def test_environment_blocks_are_the_environment_reader_keys():
    from freefloat import _core
    from freefloat.io import scenario_schemas as ss
    from freefloat.simulation import environment as env

    assert list(ss.EnvCentralBody.model_fields) == list(env.CENTRAL_BODY_KEYS)
    assert list(ss.EnvOrbit.model_fields) == list(env.ORBIT_KEYS)
    assert list(ss.EnvDisturbance.model_fields) == list(env.DISTURBANCE_KEYS)
    assert list(ss.EnvironmentBlock.model_fields) == list(env.TOP_KEYS)
    cb = ss.EnvCentralBody.model_fields
    assert {k: cb[k].default for k in cb} == env.EARTH
    # the Earth of the one Python declaration is the engine's (μ and the radius are observable)
    e = _core.Environment(altitude=500e3)
    assert e.mu == env.EARTH["mu"]
    assert np.linalg.norm(e.orbit_state[0]) == pytest.approx(env.EARTH["radius"] + 500e3, rel=1e-15)


def test_one_registry_of_scenario_kinds():
    """The readers (`scenario_files.KINDS`), `freefloat scenarios` and the schemas use the kinds declared with
    `schema.register_kind`."""
    from freefloat.io import scenario_files, schema

    assert scenario_files.KINDS == schema.commands()
    assert list(scenario_files.KINDS) == [k for k in schema.kinds() if k != "campaign"]
    for s in scenario_files.listing():
        assert s.kind in scenario_files.KINDS


def test_sensor_blocks_are_the_sensor_classes_and_the_engine_reads_the_same_keys_and_defaults():
    """Each entry type of a `sensors:` block has exactly the fields of its class (freefloat.sensors.Gyro, ...) plus
    the `type` key, with the class's defaults (made from the class: a field exists once). The engine, which runs
    the sensors, reads every one of those keys (a wrong value is refused naming it) and has the same defaults (a
    sensor with every default written out measures exactly what the bare sensor measures)."""
    import dataclasses
    import json

    from freefloat import _core, models
    from freefloat import sensors as sn
    from freefloat.io import scenario_schemas as ss

    assert set(ss.SENSOR_TYPES) == set(sn.TYPES) == {"gyro", "star_tracker", "encoder", "tachometer",
                                                      "base_velocity", "base_position", "force_torque"}  # fmt: skip
    m = models.load("naveen_dual_arm")
    n, dt = 200, 1e-3
    rng = np.random.default_rng(0)
    q = np.zeros((n, m.nq))
    q[:, 6] = 1.0
    q[:, 7:] = 0.1 * rng.standard_normal(m.nq - 7)
    v = 0.05 * rng.standard_normal((n, m.nv))
    run = {"t": np.arange(n) * dt, "q": q, "v": v, "ddq": np.zeros((n, m.nv))}
    joint = m.joint_names[1]
    for t, cls in sn.TYPES.items():
        block = ss.SENSOR_TYPES[t]
        fields = {f.name: f for f in dataclasses.fields(cls)}
        assert set(block.model_fields) == set(fields) | {"type"}, t
        assert block.model_fields["type"].is_required()
        for name, f in fields.items():
            mf = block.model_fields[name]
            if f.default is dataclasses.MISSING and f.default_factory is dataclasses.MISSING:
                assert mf.is_required(), (t, name)
            else:
                assert mf.default == f.default, (t, name)
        required = {"joint": joint} if t == "force_torque" else {}
        bare = {"type": t, **required}
        explicit = cls(**required).to_dict()  # every default that is a value, written out
        assert set(explicit) - {"type"} <= set(fields)
        assert json.loads(sn.SensorSet([explicit]).to_json()) == [explicit]
        a = sn.measure(m, run, [bare], seed=5).streams[t].values
        b = sn.measure(m, run, [explicit], seed=5).streams[t].values
        np.testing.assert_array_equal(a, b, err_msg=t)
        for name in fields:
            with pytest.raises(InputError, match=name):
                _core.check_sensors(json.dumps([{**bare, name: {"not": "a value"}}]))

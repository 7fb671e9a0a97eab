"""Identify a free-floating robot from MuJoCo telemetry, end to end (needs `pip install freefloat[mujoco]`).

    python examples/mujoco_identification.py [OUT_DIR]

1. export a built-in robot to MJCF (free joint on the base, zero gravity, RK4 with a 1 ms step);
2. simulate it in MuJoCo with smooth motor torques, recording MjData's time, qpos and qvel;
3. convert the states to freefloat's conventions (by joint name) and identify the minimal parameters.
The same from the command line:
    freefloat export naveen_dual_arm_consistent --mjcf OUT/robot.xml
    freefloat convert --from mujoco OUT/states.npz --model OUT/robot.xml --out OUT/telemetry.parquet
    freefloat identify minimal OUT/robot.xml --data OUT/telemetry.parquet
"""

from __future__ import annotations

import sys
from pathlib import Path

import mujoco
import numpy as np

import freefloat as ff
from freefloat.io.mujoco import telemetry_from_states_file

out = Path(sys.argv[1] if len(sys.argv) > 1 else "mujoco_run")
out.mkdir(parents=True, exist_ok=True)
truth = ff.models.load("naveen_dual_arm_consistent")
truth.to_mjcf(out / "robot.xml")

mj = mujoco.MjModel.from_xml_path(str(out / "robot.xml"))
d = mujoco.MjData(mj)
rng = np.random.default_rng(1)
f, ph = rng.uniform(0.1, 0.6, (mj.nu, 3)), rng.uniform(0, 2 * np.pi, (mj.nu, 3))
amp = np.array([60, 40, 20, 60, 40, 20, 2, 2, 2.0])  # N m: six arm joints, three reaction wheels
t, qpos, qvel = [], [], []
for _ in range(20000):  # 20 s at 1 ms
    t.append(d.time), qpos.append(d.qpos.copy()), qvel.append(d.qvel.copy())
    d.ctrl[:] = amp * np.sin(2 * np.pi * f * d.time + ph).sum(1)
    mujoco.mj_step(mj, d)
np.savez(out / "states.npz", t=np.array(t), qpos=np.array(qpos), qvel=np.array(qvel))

robot = ff.Model.from_mjcf(out / "robot.xml")
telem = telemetry_from_states_file(robot, out / "states.npz", out / "robot.xml")
telem.to_parquet(out / "telemetry.parquet")
res = ff.identify_minimal(robot, telem)
print(res.conventions.message())
print(res.table(truth=truth))
res.save(out, truth=truth)
print(
    f"wrote {out / 'robot.xml'}, {out / 'states.npz'}, {out / 'telemetry.parquet'}, {out / 'results.json'}, "
    f"{out / 'minimal_parameters.png'}"
)

"""The chapter 8 problems rebuilt in Pinocchio + Crocoddyl, as an independent oracle for freefloat's DDP (tests and
benches only; needs `pin` and `crocoddyl`, installed by the `test` extra: pin 4.0.0 with crocoddyl 3.2.1 —
pin 4.1.0 breaks crocoddyl 3.2.1's frame residuals).

The robot is built here by hand from its description (not from freefloat's model file), the costs are
Crocoddyl's own residuals: frame placement log6(M_ref⁻¹ M), state, control, each with a weighted-quadratic
activation. Crocoddyl's cost is dt·Σ½ w r² (running) + ½ w r² (terminal); the weights are scaled by 2/dt and 2
so that its cost equals the thesis-style sum Σ w r² that freefloat minimises.
"""

from __future__ import annotations

import numpy as np


def build_pinocchio_model():
    """valverde_ch8_arm in Pinocchio: free-flyer base 50 kg / 10 I, RRR arm (waist z, shoulder and elbow about the
    local z of frames rotated +90° about x), 5 kg / I links, a Z-Y-X wrist of 0.1 kg / 0.01 I bodies, frame `ee`."""
    import pinocchio as pin

    m = pin.Model()
    m.gravity = pin.Motion.Zero()
    eye = np.eye(3)

    def body(jid, mass, com, inertia):
        m.appendBodyToJoint(jid, pin.Inertia(mass, np.asarray(com, float), inertia * eye), pin.SE3.Identity())

    rx90 = pin.utils.rotate("x", np.pi / 2)
    base = m.addJoint(0, pin.JointModelFreeFlyer(), pin.SE3.Identity(), "root_joint")
    body(base, 50.0, [0, 0, 0], 10.0)
    waist = m.addJoint(base, pin.JointModelRZ(), pin.SE3(eye, np.array([0.0, 0, 1])), "waist")
    body(waist, 5.0, [0, 0, 1], 1.0)
    shoulder = m.addJoint(waist, pin.JointModelRZ(), pin.SE3(rx90, np.array([0.75, 0, 4])), "shoulder")
    body(shoulder, 5.0, [1.5, 0, 0], 1.0)
    elbow = m.addJoint(shoulder, pin.JointModelRZ(), pin.SE3(eye, np.array([3.0, 0, 0])), "elbow")
    body(elbow, 5.0, [1.5, 0, 0], 1.0)
    wz = m.addJoint(elbow, pin.JointModelRZ(), pin.SE3(eye, np.array([3.0, 0, 0])), "wrist_z")
    body(wz, 0.1, [0, 0, 0], 0.01)
    wy = m.addJoint(wz, pin.JointModelRY(), pin.SE3.Identity(), "wrist_y")
    body(wy, 0.1, [0, 0, 0], 0.01)
    wx = m.addJoint(wy, pin.JointModelRX(), pin.SE3.Identity(), "wrist_x")
    body(wx, 0.1, [0, 0, 0], 0.01)
    m.addFrame(pin.Frame("ee", wx, pin.SE3.Identity(), pin.FrameType.OP_FRAME))
    return m


def _se3(pose7):
    import pinocchio as pin

    p = np.asarray(pose7, float)
    quat = pin.Quaternion(p[6], p[3], p[4], p[5])  # (w, x, y, z)
    quat.normalize()
    return pin.SE3(quat.matrix(), p[:3].copy())


def build_crocoddyl_problem(problem):
    """Crocoddyl's ShootingProblem for a freefloat `Problem` whose costs are frame_placement (log), state and
    control terms with constant weights (e.g. `load_scenario(..., cost="log", schedule=False, keep_out=False)`)."""
    import crocoddyl

    if problem.keep_out:
        raise ValueError("Crocoddyl has no keep-out activation: build the problem with keep_out=False")
    model = build_pinocchio_model()
    state = crocoddyl.StateMultibody(model)
    act = crocoddyl.ActuationModelFull(state)
    nu = act.nu
    fid = model.getFrameId(problem.frame)
    dt, n = problem.dt, problem.horizon

    def costs_for(terms, k, scale):
        cs = crocoddyl.CostModelSum(state, nu)
        for t in terms:
            if "weights" not in t:
                raise ValueError(f"cost {t['name']!r}: scheduled weights cannot be mirrored in Crocoddyl")
            w = np.asarray(t["weights"], float) * scale
            act_w = crocoddyl.ActivationModelWeightedQuad(w)
            ref = t.get("reference")
            if t["kind"] == "frame_placement":
                r = ref[min(k, len(ref) - 1)]
                res = crocoddyl.ResidualModelFramePlacement(state, fid, _se3(r), nu)
            elif t["kind"] == "state":
                xr = state.zero() if ref is None else np.asarray(ref[min(k, len(ref) - 1)], float)
                res = crocoddyl.ResidualModelState(state, xr, nu)
            elif t["kind"] == "control":
                res = crocoddyl.ResidualModelControl(state, nu)
            else:
                raise ValueError(f"cost kind {t['kind']!r} has no Crocoddyl counterpart here")
            cs.addCost(t["name"], crocoddyl.CostModelResidual(state, act_w, res), 1.0)
        return cs

    running = []
    for k in range(n):
        dam = crocoddyl.DifferentialActionModelFreeFwdDynamics(state, act, costs_for(problem.running, k, 2.0 / dt))
        running.append(crocoddyl.IntegratedActionModelEuler(dam, dt))
    dam = crocoddyl.DifferentialActionModelFreeFwdDynamics(state, act, costs_for(problem.terminal, n, 2.0))
    terminal = crocoddyl.IntegratedActionModelEuler(dam, 0.0)
    x0 = np.asarray(problem.x0, float)
    shooting = crocoddyl.ShootingProblem(x0, running, terminal)
    try:
        shooting.nthreads = 1
    except AttributeError:
        pass
    return shooting


def solve_crocoddyl(shooting, us0, max_iter: int = 150, solver: str = "fddp"):
    """Solve with Crocoddyl's FDDP (or DDP) from the rollout of `us0`. Returns (solver, iterations, cost), with
    iterations counted as derivative evaluations (callbacks), as freefloat counts them."""
    import crocoddyl

    s = crocoddyl.SolverFDDP(shooting) if solver == "fddp" else crocoddyl.SolverDDP(shooting)
    count = []

    class _Count(crocoddyl.CallbackAbstract):
        def __init__(self):
            crocoddyl.CallbackAbstract.__init__(self)

        def __call__(self, solver):
            count.append(solver.cost)

    s.setCallbacks([_Count()])
    us = [np.asarray(u, float) for u in us0]
    xs = shooting.rollout(us)
    s.solve(xs, us, max_iter, True)
    return s, len(count), float(s.cost)

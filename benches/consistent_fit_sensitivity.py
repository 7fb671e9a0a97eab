"""The demo's consistent fit (cvxpy, SCS status `optimal_inaccurate`) is not continuous at round-off level:
the reported misfit of the same identification moves by tens of percent when the identified minimal
parameters are perturbed by 1e-14 relative. Run: python benches/consistent_fit_sensitivity.py"""
import numpy as np, freefloat as ff
from freefloat import identify as idf, data, models
from freefloat.excitation import load_trajectory
from freefloat.telemetry import SIGMA_ANG, SIGMA_JOINT, SIGMA_LIN
from freefloat.consistent import consistent_parameters
m = models.load("seed001_dual_arm")
with data.path("trajectories", "seed001_exciting_trajectory") as p:
    designed, joints = load_trajectory(p)
telem, _ = idf.trajectory_data(m, designed, joints)
res = idf.identify_minimal(m, telem, rate_noise=(SIGMA_LIN, SIGMA_ANG, SIGMA_JOINT))
prior = models.load("seed001_dual_arm_offset")
rng = np.random.default_rng(1)
for eps in (0.0, 1e-14, 1e-13, 1e-12):
    phi = res.estimate * (1 + eps * rng.normal(size=res.estimate.shape))
    c = consistent_parameters(res.mp, phi, covariance=res.fit.covariance, prior=prior)
    print(f"phi perturbed by {eps:g} relative: misfit {c.misfit:.4g} std devs, solver {c.solver}")

"""Numbers printed in the published works, kept in one place so every module uses the same values.

Naveen, Shah, Misra (momentum-model minimal inertial parameters of a tree-type space robot):
- Table 3, the cycloid seeds of the six arm joints: start angles printed in degrees, ranges read as radians
  (the table prints no unit for them; read as radians they satisfy the paper's own rate and acceleration limits);
- Sec. VI.A.2, the reaction-wheel seeds: start 0 rad, range 3π rad per 1-s interval, i.e. a peak rate of
  2·3π/1 = 6π rad/s (18.8496 kg·m²/s for the 1 kg·m² wheel);
- Sec. VI.C, the measurement noise: zero-mean white Gaussian noise of standard deviation 50 µm/s on the base
  linear velocity, 80 µrad/s on the base angular velocity and 50 µrad/s on the joint rates;
- Sec. VI.B, the settings of Algorithm 1 (pruning): u_max = 5 free acceptances, δ = 1/300 for "significant"
  singular values;
- Sec. VI.D, the torque-sensor noise of its reference [33] (0.3808 N·m), used to judge Table 6.
"""

from __future__ import annotations

import numpy as np

#: Table 3: start angles of the arm-joint cycloids [deg]
TABLE3_START_DEG = (40.661, -109.403, -78.782, 125.089, -110.0, 51.228)
#: Table 3: ranges of the arm-joint cycloids [rad]
TABLE3_RANGE_RAD = (0.524, 2.51, 2.51, 2.513, 2.036, 2.5)

#: reaction-wheel seeds (Sec. VI.A.2): start [rad] and range [rad] per interval
WHEEL_START = 0.0
WHEEL_RANGE = 3.0 * np.pi

#: rate noise (Sec. VI.C): base linear [m/s], base angular [rad/s], joint rates [rad/s]
SIGMA_LIN, SIGMA_ANG, SIGMA_JOINT = 50e-6, 80e-6, 50e-6
PAPER_RATE_NOISE = (SIGMA_LIN, SIGMA_ANG, SIGMA_JOINT)

#: Algorithm 1 settings (Sec. VI.B)
U_MAX, DELTA = 5, 1.0 / 300.0

#: Sec. VI.B results printed beside ours: κ of the designed trajectory and the number of intervals kept
PAPER_KAPPA, PAPER_KEPT = 248.8, 67

#: torque-sensor noise of the paper's reference [33] [N·m], the yardstick of Table 6
SIGMA_TORQUE = 0.3808

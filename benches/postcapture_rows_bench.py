"""Speed of Zhang, Yue, Yuan 2020's identification rows: the engine (`_core.postcapture_rows`, one call per record)
against the former numpy equations (tests/postcapture_numpy_oracle.py: vectorised numpy over the record, with the
engine's stacked kinematics and regressors), on the same simulated record. Best of N repetitions each.

    python benches/postcapture_rows_bench.py [SCENARIO] [N]
"""

import sys
import time
from pathlib import Path

import freefloat as ff
from freefloat import postcapture as pc
from freefloat.postcapture import equations as eq

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
import postcapture_numpy_oracle as oracle  # noqa: E402

name = sys.argv[1] if len(sys.argv) > 1 else "zhang2020_3d"
reps = int(sys.argv[2]) if len(sys.argv) > 2 else 5
sc = pc.load_scenario(name)
m = ff.models.load(sc.model)
meas = pc.measure(m, pc.simulate(sc, m), sc)
base, target = 0, pc.target_index(m)


def best(f):
    ts = []
    for _ in range(reps):
        t0 = time.perf_counter()
        f(m, meas, base, target)
        ts.append(time.perf_counter() - t0)
    return min(ts)


print(f"{name}: {len(meas.t)} samples, best of {reps}")
for kind in ("paper", "standard"):
    for form in ("momentum", "force"):
        fn = f"{kind}_{form}_rows"
        tn, to = best(getattr(eq, fn)), best(getattr(oracle, fn))
        print(f"  {fn:24s} engine {1e3 * tn:8.2f} ms   numpy {1e3 * to:8.2f} ms   ratio {to / tn:5.1f}x")

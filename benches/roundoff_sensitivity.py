"""Round-off sensitivity of a Zhang, Yue, Yuan 2020 identification: the same pipeline on the same simulated record, once
as is and once with every measured number perturbed by relative noise of size EPS (default 1e-16, about
one ulp); the differences in the final estimates are the size round-off alone produces. Also prints how far
the engine's rows are from the former numpy equations (tests/postcapture_numpy_oracle.py) on this record.

    python benches/roundoff_sensitivity.py [SCENARIO] [EPS]
"""

import sys
from dataclasses import replace

import numpy as np

import freefloat as ff
from freefloat import postcapture as pc

name = sys.argv[1] if len(sys.argv) > 1 else "zhang2020_3d"
eps = float(sys.argv[2]) if len(sys.argv) > 2 else 1e-16
sc = pc.load_scenario(name)
m = ff.models.load(sc.model)
sim = pc.simulate(sc, m)
meas = pc.measure(m, sim, sc)
rng = np.random.default_rng(0)


def ulp(x):
    return x * (1 + eps * rng.normal(size=x.shape))


meas2 = replace(
    meas,
    v=ulp(meas.v),
    ddq=ulp(meas.ddq),
    base_wrench=ulp(meas.base_wrench),
    impulse_F=ulp(meas.impulse_F),
    impulse_M=ulp(meas.impulse_M),
)
r1, r2 = pc.identify(m, meas, sc), pc.identify(m, meas2, sc)
for key in r1.histories:
    a, b = r1.final(*key), r2.final(*key)
    d = np.abs(a - b)
    i = int(np.argmax(d))
    rel = d / np.maximum(np.abs(a), 1e-300)
    print(
        key,
        f"max abs diff {d.max():.2e} ({r1.names[i]}), max rel diff {rel.max():.2e} ({r1.names[int(np.argmax(rel))]})",
    )

sys.path.insert(0, str(__import__("pathlib").Path(__file__).resolve().parents[1] / "tests"))
try:
    import postcapture_numpy_oracle as oracle

    from freefloat.postcapture import equations as eq

    base, target = 0, pc.target_index(m)
    for form in ("momentum", "force"):
        for kind in ("paper", "standard"):
            new = getattr(eq, f"{kind}_{form}_rows")(m, meas, base, target)
            old = getattr(oracle, f"{kind}_{form}_rows")(m, meas, base, target)
            worst = max(
                float(np.abs(getattr(new, k) - getattr(old, k)).max() / max(np.abs(getattr(old, k)).max(), 1e-300))
                for k in ("Phi", "y")
            )
            print(f"{kind} {form} rows: engine vs former numpy, largest difference / largest entry {worst:.2e}")
except ImportError:
    pass

"""Pinocchio's C++ kernels as a timing peer, with no Python in the timed loop (driver of pinocchio_peer.cpp).

`CppPeer.start()` compiles benches/pinocchio_peer.cpp against the headers the pip `pin` wheel ships (Eigen from
`cmeel-eigen`) with g++ -O3 -march=native, header-only (so Pinocchio's templates are compiled for this machine, its
strongest build), caches the binary under ~/.cache/freefloat-bench keyed by the source, the Pinocchio version and
the flags, and runs it as a child process. A model is handed over as text written from the very Pinocchio model the
benchmark checks against freefloat; states as a binary file in Pinocchio's layout. Nothing here is committed as a
binary; without g++ or the headers `start()` returns the reason instead of a peer.
"""

from __future__ import annotations

import hashlib
import os
import shutil
import subprocess
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
SOURCE = HERE / "pinocchio_peer.cpp"
FLAGS = [
    "-O3",
    "-march=native",
    "-DNDEBUG",
    "-std=c++17",
    # the definitions Pinocchio's CMake config exports to its users (lib/cmake/pinocchio): its joint variant has
    # more alternatives than Boost.MPL's preprocessed default of 20
    "-DBOOST_MPL_LIMIT_LIST_SIZE=30",
    "-DBOOST_MPL_LIMIT_VECTOR_SIZE=30",
    "-DBOOST_MPL_CFG_NO_PREPROCESSED_HEADERS",
    "-DBOOST_FUSION_INVOKE_MAX_ARITY=12",
]
# Pinocchio joints whose axis is exactly +x, +y or +z have a specialised joint type (the URDF parser picks it); the
# random trees are built with the general "unaligned" types, so the peer upgrades those (same q, v and result)
PRINCIPAL = {"JointModelRevoluteUnaligned": "JointModelR", "JointModelPrismaticUnaligned": "JointModelP"}


def cmeel_prefix() -> Path | None:
    import pinocchio

    for p in Path(pinocchio.__file__).resolve().parents:
        if p.name == "cmeel.prefix":
            return p
    return None


def build() -> tuple[Path | None, str]:
    """(binary, "") or (None, why not)."""
    import pinocchio as pin

    gxx = shutil.which("g++")
    if gxx is None:
        return None, "g++ not found"
    prefix = cmeel_prefix()
    if prefix is None:
        return None, "the pip `pin` install has no cmeel.prefix (headers) folder"
    inc = prefix / "include"
    eigen = inc / "eigen3"
    if not (inc / "pinocchio" / "multibody.hpp").is_file():
        return None, f"no Pinocchio headers under {inc}"
    if not (eigen / "Eigen" / "Core").is_file():
        return None, f"no Eigen headers under {eigen} (pip install cmeel-eigen)"
    key = hashlib.sha256(
        SOURCE.read_bytes() + pin.__version__.encode() + " ".join(FLAGS).encode() + str(prefix).encode()
    ).hexdigest()[:16]
    cache = Path(os.environ.get("XDG_CACHE_HOME", Path.home() / ".cache")) / "freefloat-bench"
    exe = cache / f"pinocchio_peer-{key}"
    if exe.is_file():
        return exe, ""
    cache.mkdir(parents=True, exist_ok=True)
    tmp = exe.with_suffix(".tmp")
    cmd = ["nice", gxx, *FLAGS, f"-I{inc}", f"-I{eigen}", str(SOURCE), "-o", str(tmp)]
    print("building the C++ Pinocchio peer (a few minutes, once): " + " ".join(cmd), flush=True)
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0:
        return None, "g++ failed: " + r.stderr.strip()[-800:]
    tmp.rename(exe)
    return exe, ""


def write_model(pm, path: Path) -> None:
    """Pinocchio model -> the peer's text format: gravity, then per joint its parent, type, axis, placement in the
    parent joint (rotation row by row, translation) and the inertia of everything it carries (mass, centre of mass,
    inertia about the centre of mass: xx xy yy xz yz zz)."""
    lines = ["gravity " + " ".join(repr(float(x)) for x in pm.gravity.linear), f"joints {pm.njoints - 1}"]
    for j in range(1, pm.njoints):
        jm = pm.joints[j]
        kind = jm.shortname()
        axis = np.zeros(3)
        if kind in PRINCIPAL:
            axis = np.asarray(jm.extract().axis, float)
            hit = [k for k in range(3) if np.array_equal(axis, np.eye(3)[k])]
            if hit:
                kind = PRINCIPAL[kind] + "XYZ"[hit[0]]
        X, inertia = pm.jointPlacements[j], pm.inertias[j]
        Ic = inertia.inertia
        nums = [
            *axis,
            *np.asarray(X.rotation).ravel(),
            *X.translation,
            inertia.mass,
            *inertia.lever,
            Ic[0, 0],
            Ic[0, 1],
            Ic[1, 1],
            Ic[0, 2],
            Ic[1, 2],
            Ic[2, 2],
        ]
        lines.append(f"joint {pm.parents[j]} {kind} " + " ".join(repr(float(x)) for x in nums))
    path.write_text("\n".join(lines) + "\n")


def write_states(path: Path, Q, V, T) -> None:
    """States in Pinocchio's layout, one per row: header (nq, nv, N), then Q, V, T, float64."""
    Q, V, T = (np.ascontiguousarray(x, dtype=float) for x in (Q, V, T))
    hdr = np.array([Q.shape[1], V.shape[1], Q.shape[0]], float)
    with open(path, "wb") as f:
        for a in (hdr, Q, V, T):
            f.write(a.tobytes())


class CppPeer:
    def __init__(self, exe: Path):
        self.proc = subprocess.Popen([str(exe)], stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True, bufsize=1)

    @classmethod
    def start(cls) -> tuple[CppPeer | None, str]:
        exe, why = build()
        return (cls(exe), "") if exe else (None, why)

    def _ask(self, line: str) -> str:
        self.proc.stdin.write(line + "\n")
        self.proc.stdin.flush()
        out = self.proc.stdout.readline().strip()
        if not out or out.startswith("error"):
            raise RuntimeError(f"C++ Pinocchio peer, command {line!r}: {out or 'no answer (it exited)'}")
        return out

    def load(self, pm, Q, V, T, folder: Path) -> int:
        """Hand over a model and its states (Pinocchio layout, one state per row); returns the peer's index."""
        k = len(list(folder.glob("peer_model_*.txt")))
        mp, sp = folder / f"peer_model_{k}.txt", folder / f"peer_states_{k}.bin"
        write_model(pm, mp)
        write_states(sp, Q, V, T)
        return int(self._ask(f"load {mp} {sp}").split()[1])

    def time(self, k: int, kernel: str, calls: int) -> tuple[float, float]:
        """(wall, CPU) seconds of `calls` calls, cycling over the states, measured inside the peer."""
        wall, cpu, _ = self._ask(f"time {k} {kernel} {calls}").split()
        return float(wall), float(cpu)

    def outputs(self, k: int, kernel: str, n: int, folder: Path, nv: int) -> np.ndarray:
        """The kernel's outputs on the first n states: (n, nv, nv) for crba (full), (n, nv) otherwise."""
        path = folder / f"peer_out_{k}_{kernel}.bin"
        self._ask(f"dump {k} {kernel} {n} {path}")
        a = np.fromfile(path, dtype=float)
        return a.reshape(n, nv, nv) if kernel == "crba" else a.reshape(n, nv)

    def close(self) -> None:
        if self.proc.poll() is None:
            try:
                self.proc.stdin.write("quit\n")
                self.proc.stdin.flush()
                self.proc.wait(timeout=10)
            except (OSError, subprocess.TimeoutExpired):
                self.proc.kill()

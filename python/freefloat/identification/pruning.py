"""Algorithm 1 of Naveen, Shah, Misra (pruning of the excitation intervals), with the fix described in
docs/excitation.md: the reference rank and condition number follow the accepted matrix, and the figure of the
paper's Fig. 4."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..constants import DELTA, U_MAX

#: relative decrease of the condition number that counts as "lowers it" in Algorithm 1 (our choice; 0 is the
#: printed test, which once every parameter is excited accepts nearly every interval: 247 of 256 in our design)
MIN_GAIN = 0.01


@dataclass
class PruneResult:
    """Algorithm 1: kept interval indices and, per interval, the single-interval and concatenated figures
    (condition number and number of significant singular values) — the data of the paper's Fig. 4."""

    kept: np.ndarray
    single_kappa: np.ndarray
    single_significant: np.ndarray
    concat_kappa: np.ndarray
    concat_significant: np.ndarray


def significant(sv, delta: float) -> int:
    """Number of singular values above delta·σ_max (Algorithm 1's numSignificantSingularVals)."""
    sv = np.asarray(sv)
    return int(np.sum(sv > delta * sv[0])) if sv.size and sv[0] > 0 else 0


def _kappa(sv, n: int | None = None) -> float:
    """σ_max/σ_min over n singular values: a wide matrix (fewer rows than n) has n − rows zero ones."""
    sv = np.asarray(sv)
    if n is not None and sv.size < n:
        return float("inf")
    return float(sv[0] / sv[-1]) if sv[-1] > 0 else float("inf")


def prune_intervals(blocks, u_max: int = U_MAX, delta: float = DELTA, min_gain: float = MIN_GAIN) -> PruneResult:
    """Algorithm 1 of Naveen, Shah, Misra on per-interval regressor blocks (K, rows, n), with the fix:
    s_prev and cn_prev follow the accepted matrix.  An interval is kept if it raises the number of significant
    singular values or lowers the condition number by more than `min_gain` (relative; 0 is the printed test);
    otherwise it may still be kept while fewer than u_max non-improving acceptances have happened in a row (the
    counter resets on an improvement).  The stacked matrix is carried as its R factor, so every test is an SVD
    of a small (2n × n) matrix."""
    K, _, n = blocks.shape
    single_k = np.empty(K)
    single_s = np.empty(K, dtype=int)
    concat_k = np.full(K, np.nan)
    concat_s = np.zeros(K, dtype=int)
    for i in range(K):
        sv = np.linalg.svd(blocks[i], compute_uv=False)
        single_k[i], single_s[i] = _kappa(sv, n), significant(sv, delta)
    kept, R, rows = [], np.zeros((0, n)), 0
    i = 0
    while i < K and rows <= n:  # "while n_r <= n_c": take intervals until G_m^o is taller than wide
        kept.append(i)
        R = _stack(R, blocks[i])
        rows += blocks.shape[1]
        sv = np.linalg.svd(R, compute_uv=False)
        concat_k[i], concat_s[i] = _kappa(sv, n), significant(sv, delta)
        i += 1
    sv = np.linalg.svd(R, compute_uv=False)
    s_prev, cn_prev, u = significant(sv, delta), _kappa(sv, n), 0
    while i < K:
        Rt = _stack(R, blocks[i])
        sv = np.linalg.svd(Rt, compute_uv=False)
        s_now, cn_now = significant(sv, delta), _kappa(sv, n)
        improved = s_now > s_prev or cn_now < cn_prev * (1.0 - min_gain)
        if improved or (s_now == s_prev and u < u_max):
            kept.append(i)
            R = Rt
            u = 0 if improved else u + 1
            s_prev, cn_prev = s_now, cn_now
        concat_k[i], concat_s[i] = cn_prev, s_prev
        i += 1
    return PruneResult(
        kept=np.array(kept),
        single_kappa=single_k,
        single_significant=single_s,
        concat_kappa=concat_k,
        concat_significant=concat_s,
    )


def _stack(R, block):
    """R factor of [R; block] (upper triangle, n × n at most)."""
    M = np.vstack([R, block])
    r = np.linalg.qr(M, mode="r")
    return r[: min(r.shape)]


def plot_fig4(pr: PruneResult, path) -> None:
    """Naveen, Shah, Misra Fig. 4: condition number and significant singular values per interval index, single intervals
    and the accepted concatenation."""
    from ..viz import pyplot

    plt = pyplot()
    k = np.arange(1, len(pr.single_kappa) + 1)
    fig, ax = plt.subplots(2, 1, figsize=(10, 7), sharex=True, constrained_layout=True)
    ax[0].semilogy(
        k, np.minimum(pr.single_kappa, 1e20), ".", ms=3, label="single interval (rank-deficient: shown at the cap)"
    )
    ax[0].semilogy(k, np.minimum(pr.concat_kappa, 1e20), "-", label="accepted concatenation")
    ax[0].set_ylabel("condition number (capped at 1e20)")
    ax[1].plot(k, pr.single_significant, ".", ms=3, label="single interval")
    ax[1].plot(k, pr.concat_significant, "-", label="accepted concatenation")
    kept = np.zeros(len(k), bool)
    kept[pr.kept] = True
    ax[1].plot(k[kept], pr.concat_significant[kept], "|", color="k", ms=8, label="kept interval")
    ax[1].set_ylabel(f"significant singular values (> σmax/{int(round(1 / DELTA))})")
    ax[1].set_xlabel("interval index")
    for a in ax:
        a.grid(alpha=0.3)
        a.legend()
    ax[0].set_title(f"pruning (Naveen, Shah, Misra Algorithm 1, Fig. 4): {len(pr.kept)} of {len(k)} intervals kept")
    fig.savefig(path, dpi=110)
    plt.close(fig)

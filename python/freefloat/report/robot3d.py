"""A 3D view of a robot's recorded motion: every body's frame origin joined to its parent's (the kinematic tree as
a stick figure) and each body's frame axes, animated over time with Plotly frames (play button and time slider).
The body poses come from the engine's forward kinematics of the recorded configurations."""

from __future__ import annotations

import numpy as np

#: frames of the animation at most (the trajectory is subsampled evenly)
MAX_FRAMES = 80


def figure(model, t, q, title: str = "", max_frames: int = MAX_FRAMES, axis_length: float | None = None):
    """A Plotly figure animating `model` along configurations `q` (T, nq) at times `t` (T,)."""
    import plotly.graph_objects as go

    from .. import algorithms as alg

    q = np.asarray(q, dtype=float)
    t = np.asarray(t, dtype=float)
    idx = np.unique(np.linspace(0, len(t) - 1, min(max_frames, len(t))).round().astype(int))
    poses = np.asarray(alg.forward_kinematics(model, q[idx]))  # (F, nbodies, 7): position, quaternion (x, y, z, w)
    if poses.ndim == 2:
        poses = poses[None]
    parents = list(model.parents)
    R = alg.quat_to_matrix(poses[..., 3:].reshape(-1, 4)).reshape(poses.shape[0], poses.shape[1], 3, 3)
    P = poses[..., :3]
    span = float(np.ptp(P.reshape(-1, 3), axis=0).max()) or 1.0
    L = axis_length or 0.08 * span

    def traces(k):
        p = P[k]
        xs, ys, zs = [], [], []
        for i, par in enumerate(parents):
            if par is None or par < 0:
                continue
            xs += [p[par, 0], p[i, 0], None]
            ys += [p[par, 1], p[i, 1], None]
            zs += [p[par, 2], p[i, 2], None]
        out = [
            go.Scatter3d(x=xs, y=ys, z=zs, mode="lines", line=dict(color="#444", width=6), name="links"),
            go.Scatter3d(
                x=p[:, 0],
                y=p[:, 1],
                z=p[:, 2],
                mode="markers",
                marker=dict(size=4, color="#ff7f0e"),
                text=list(model.body_names),
                hovertemplate="%{text}<extra></extra>",
                name="bodies",
            ),
        ]
        for a, colour in enumerate(("#d62728", "#2ca02c", "#1f77b4")):
            ax, ay, az = [], [], []
            for i in range(len(parents)):
                e = p[i] + L * R[k, i][:, a]
                ax += [p[i, 0], e[0], None]
                ay += [p[i, 1], e[1], None]
                az += [p[i, 2], e[2], None]
            out.append(
                go.Scatter3d(x=ax, y=ay, z=az, mode="lines", line=dict(color=colour, width=3), name="xyz"[a] + " axes")
            )
        return out

    lo, hi = P.reshape(-1, 3).min(0) - L, P.reshape(-1, 3).max(0) + L
    fig = go.Figure(
        data=traces(0),
        frames=[go.Frame(data=traces(k), name=f"{t[i]:.2f}") for k, i in enumerate(idx)],
    )
    fig.update_layout(
        title=title or f"{model.name}: motion (bodies and frames)",
        scene=dict(
            xaxis=dict(range=[lo[0], hi[0]], title="x [m]"),
            yaxis=dict(range=[lo[1], hi[1]], title="y [m]"),
            zaxis=dict(range=[lo[2], hi[2]], title="z [m]"),
            aspectmode="cube",
        ),
        updatemenus=[
            dict(
                type="buttons",
                showactive=False,
                x=0.05,
                y=0.05,
                buttons=[
                    dict(
                        label="play",
                        method="animate",
                        args=[None, dict(frame=dict(duration=80, redraw=True), fromcurrent=True)],
                    ),
                    dict(label="pause", method="animate", args=[[None], dict(mode="immediate")]),
                ],
            )
        ],
        sliders=[
            dict(
                currentvalue=dict(prefix="t = ", suffix=" s"),
                steps=[
                    dict(method="animate", label=f"{t[i]:.2f}", args=[[f"{t[i]:.2f}"], dict(mode="immediate")])
                    for i in idx
                ],
            )
        ],
    )
    return fig

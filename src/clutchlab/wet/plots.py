"""Figures of the wet-clutch subsystem (matplotlib imported lazily)."""

from __future__ import annotations

import numpy as np

__all__ = ["friction_map_figure", "map_traces_figure", "engagement_figure"]


def _plt():
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    return plt


def friction_map_figure(fmap, truth=None, samples=None):
    """Surface of the identified map (Fig. 15), optionally beside the true map and the samples."""
    plt = _plt()
    v = np.linspace(fmap.speed_grid[0], fmap.speed_grid[-1], 40)
    t = np.linspace(fmap.temperature_grid[0], fmap.temperature_grid[-1], 30)
    vv, tt = np.meshgrid(v, t)
    ncol = 2 if truth is not None else 1
    fig = plt.figure(figsize=(6.0 * ncol, 4.8))
    ax = fig.add_subplot(1, ncol, 1, projection="3d")
    ax.plot_surface(vv, tt, fmap.mu(vv, tt), cmap="viridis", alpha=0.85, linewidth=0)
    gv, gt = np.meshgrid(fmap.speed_grid, fmap.temperature_grid)
    cov = fmap.covered if fmap.covered.ndim == 2 else fmap.covered[0]
    ax.scatter(gv[cov], gt[cov], fmap.values[cov] if fmap.values.ndim == 2 else fmap.values[0][cov], c="k", s=6,
               label="covered cells")
    if samples is not None and len(samples):
        sub = samples.iloc[:: max(1, len(samples) // 1500)]
        ax.scatter(sub["slip_velocity_m_s"], sub["temperature_C"], sub["mu_f"], c="tab:red", s=1, alpha=0.3,
                   label="samples")
    ax.set_xlabel("slip velocity v [m/s]")
    ax.set_ylabel("temperature T [°C]")
    ax.set_zlabel("μ_f [-]")
    ax.set_title("identified friction map")
    ax.legend(loc="upper left", fontsize=7)
    if truth is not None:
        ax2 = fig.add_subplot(1, 2, 2)
        err = fmap.mu(vv, tt) - truth.mu(vv, tt)
        im = ax2.pcolormesh(vv, tt, err * 1e3, cmap="RdBu_r", shading="auto",
                            vmin=-np.max(np.abs(err)) * 1e3, vmax=np.max(np.abs(err)) * 1e3)
        fig.colorbar(im, ax=ax2, label="identified − true μ_f [×10⁻³]")
        ax2.contour(gv, gt, cov.astype(float), levels=[0.5], colors="k", linewidths=1)
        ax2.set_xlabel("slip velocity v [m/s]")
        ax2.set_ylabel("temperature T [°C]")
        ax2.set_title("error vs the bench's true map (black: covered region)")
    fig.tight_layout()
    return fig


def map_traces_figure(record, title="friction-map experiment"):
    """Time traces of a protocol (a) record (Fig. 13)."""
    plt = _plt()
    fig, axs = plt.subplots(4, 1, figsize=(8, 8), sharex=True)
    t = record["time_s"]
    axs[0].plot(t, record["slip_speed_rad_s"] * 30 / np.pi, lw=0.8)
    axs[0].set_ylabel("slip [rpm]")
    axs[1].plot(t, record["torque_Nm"], lw=0.8)
    axs[1].set_ylabel("torque [N·m]")
    axs[2].plot(t, record["force_N"], lw=0.8, label="load cell")
    axs[2].set_ylabel("force [N]")
    ax2b = axs[2].twinx()
    ax2b.plot(t, record["piston_position_m"] * 1e3, lw=0.8, color="tab:orange", label="piston (right axis)")
    ax2b.set_ylabel("piston [mm]", color="tab:orange")
    lines = axs[2].get_lines() + ax2b.get_lines()
    axs[2].legend(lines, [ln.get_label() for ln in lines], fontsize=7, loc="lower right")
    axs[3].plot(t, record["temperature_C"], lw=0.8, label="clutch (thermistor)")
    axs[3].plot(t, record["fluid_temperature_C"], lw=0.8, label="fluid")
    axs[3].plot(t, record["housing_temperature_C"], lw=0.8, label="housing")
    axs[3].set_ylabel("T [°C]")
    axs[3].legend(fontsize=7)
    axs[3].set_xlabel("time [s]")
    axs[0].set_title(title)
    fig.tight_layout()
    return fig


def engagement_figure(bench_result, dyno_result):
    """Engagement on the speed-controlled bench vs the inertia dynamometer (Fig. 14)."""
    plt = _plt()
    fig, axs = plt.subplots(3, 1, figsize=(8, 7.5), sharex=True)
    for res, name, ls in ((bench_result, "bench (speed-controlled motor)", "-"),
                          (dyno_result, "inertia dynamometer (SAE No. 2)", "--")):
        t = res.time
        axs[0].plot(t, res.state("slip_speed_rad_s") * 30 / np.pi, ls, label=name)
        axs[1].plot(t, res.output("contact_torque_Nm"), ls, label=f"asperity τ_c, {name.split(' ')[0]}")
        axs[1].plot(t, res.output("viscous_torque_Nm"), ls, label=f"viscous τ_v, {name.split(' ')[0]}")
        axs[2].plot(t, res.output("contact_force_N"), ls, label=f"F_c, {name.split(' ')[0]}")
        axs[2].plot(t, res.output("squeeze_force_N"), ls, label=f"squeeze film, {name.split(' ')[0]}")
        for ev in res.event_list:
            if ev.kind == "lock-up":
                axs[0].axvline(ev.time, color="0.5", lw=0.8, ls=ls, label=f"lock-up, {name.split(' ')[0]}")
    axs[0].plot(bench_result.time, bench_result.output("slip_reference_rad_s") * 30 / np.pi, ":", color="k",
                label="slip reference")
    axs[2].plot(bench_result.time, bench_result.output("force_reference_N"), ":", color="k", label="force reference")
    axs[0].set_ylabel("slip [rpm]")
    axs[1].set_ylabel("torque [N·m]")
    axs[2].set_ylabel("force [N]")
    axs[2].set_xlabel("time [s]")
    for ax in axs:
        ax.legend(fontsize=7)
    axs[0].set_title("engagement: bench vs inertia dynamometer (grey: lock-up events)")
    fig.tight_layout()
    return fig

"""Wet-clutch section of ``clutchlab demo``: bench -> records -> identification -> map.

Uses the bundled synthetic records (``clutchlab/wet/data``, written by the
virtual bench, ``python -m clutchlab.wet.data.generate``) and simulates the
engagement of Fig. 14 on the bench and on an inertia dynamometer.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from ..report import Figure, Section, Table, Text

__all__ = ["demo_section"]


def demo_section(progress=lambda message: None) -> Section:
    """Build the wet-clutch report section (Figs. 13-15 and the identification tables)."""
    from ..wet.bench import EngagementProtocol, read_bench_record
    from ..wet.data import MAP_RECORDS, path
    from ..wet.engagement import simulate_engagement
    from ..wet.friction import ParametricFriction
    from ..wet.identify import friction_samples, identify_friction_map, identify_thermal
    from ..wet.params import Bench, WetClutch
    from ..wet.plots import engagement_figure, friction_map_figure, map_traces_figure

    clutch = WetClutch.paper()
    bench = Bench()
    truth = ParametricFriction.bench_truth()
    files = [path(n) for n in MAP_RECORDS]
    progress("wet: reading bundled bench records")
    records = [read_bench_record(f) for f in files]
    progress("wet: identifying the friction map and k1, k2")
    fmap = identify_friction_map(records, clutch, sensor_time_constant=bench.thermistor_time_constant)
    thermal = identify_thermal(records, clutch, sensor_time_constant=bench.thermistor_time_constant)
    samples = friction_samples(records, clutch, sensor_time_constant=bench.thermistor_time_constant)
    progress("wet: simulating the engagement on the bench and on an inertia dynamometer")
    proto = EngagementProtocol()
    res_bench = simulate_engagement(clutch, proto.scenario(clutch, "speed"), bench=bench, friction=truth)
    res_dyno = simulate_engagement(clutch, proto.scenario(clutch, "free"), bench=bench, friction=truth)

    law = fmap.law
    se = fmap.statistics["stderr"]
    law_table = pd.DataFrame({
        "parameter": ["mu0 [-] at t_ref", "mu_t [1/K]", "mu_e [-]", "v_s [m/s]"],
        "true (bench)": [truth.mu0 + truth.mu_t * (law.t_ref - truth.t_ref), truth.mu_t, truth.mu_e, truth.v_s],
        "identified": [law.mu0, law.mu_t, law.mu_e, law.v_s],
        "std. error": [se["mu0"], se["mu_t"], se["mu_e"], se["v_s"]],
    })
    vv, tt = np.meshgrid(fmap.speed_grid, fmap.temperature_grid)
    cov = fmap.covered
    err_table = fmap.values[cov] - truth.mu(vv, tt)[cov]
    vd = np.linspace(*fmap.region["slip_velocity_m_s"], 50)
    td = np.linspace(*fmap.region["temperature_C"], 40)
    dv, dt_ = np.meshgrid(vd, td)
    stats = pd.DataFrame({
        "statistic": ["samples used", "rms residual of the law fit [-]", "R^2 of the law fit",
                      "covered cells / all cells", "max |table - truth| over covered cells [-]",
                      "max |law - truth| over the covered box [-]", "covered slip velocity [m/s]",
                      "covered temperature [degC]", "covered contact force [N]"],
        "value": [f"{fmap.statistics['n_samples']}", f"{fmap.statistics['rmse']:.3g}", f"{fmap.statistics['r2']:.5f}",
                  f"{fmap.statistics['cells_covered']} / {fmap.statistics['cells_total']}",
                  f"{np.max(np.abs(err_table)):.3g}",
                  f"{np.max(np.abs(law.mu(dv, dt_) - truth.mu(dv, dt_))):.3g}",
                  "{:.3g} .. {:.3g}".format(*fmap.region["slip_velocity_m_s"]),
                  "{:.3g} .. {:.3g}".format(*fmap.region["temperature_C"]),
                  "{:.4g} .. {:.4g}".format(*fmap.region["force_N"])],
    })
    k_table = pd.DataFrame({
        "parameter": ["k1 (convection to oil) [W/K]", "k2 (conduction to housing) [W/K]"],
        "true (Table 1)": [clutch.k1, clutch.k2],
        "identified": [thermal.k1, thermal.k2],
        "std. error": [thermal.stderr["k1"], thermal.stderr["k2"]],
        "95 % low": [thermal.ci95["k1"][0], thermal.ci95["k2"][0]],
        "95 % high": [thermal.ci95["k1"][1], thermal.ci95["k2"][1]],
    })
    ev = lambda r: ", ".join(f"{e.kind} {e.time:.3f} s" for e in r.event_list)  # noqa: E731
    eng_table = pd.DataFrame({
        "run": ["bench, speed-controlled motor (b)", "inertia dynamometer, SAE No. 2 (c)"],
        "events": [ev(res_bench), ev(res_dyno)],
        "friction work [J]": [res_bench.final_state[8], res_dyno.final_state[8]],
        "peak pack temperature [degC]": [res_bench.peak_temperature_c, res_dyno.peak_temperature_c],
        "energy balance residual [-]": [res_bench.energy_balance()["residual"], res_dyno.energy_balance()["residual"]],
    })
    items = [
        Text("Wet multi-plate clutch after Shin, Kim and Choi (KAIST): Table 1 clutch on the virtual test bench of "
             "Fig. 4. Three friction-map experiments (protocol (a): constant force, 10 s constant slip, 20 s slow "
             "decrease) at different forces, slip speeds and oil temperatures were recorded with sensor noise; "
             "the friction coefficient is computed as in Sec. 4 (measured torque minus the viscous torque of Eq. 5, "
             "divided by R_eff N_c F_c), tabulated over the covered region and fitted by the parametric law. "
             "The bench's true friction law differs from the fit's starting values, which come from the data."),
        Figure("wet_fig13_traces", map_traces_figure(records[0], "protocol (a), 300 rpm, 85 °C oil (cf. Fig. 13)"),
               "Measured channels of a friction-map experiment (synthetic record, cf. Fig. 13)."),
        Figure("wet_fig15_map", friction_map_figure(fmap, truth, samples),
               "Identified friction-coefficient map (cf. Fig. 15) and its error against the bench's true map."),
        Table("wet_law", law_table, "Parametric friction law: identified vs the bench's truth "
              "(mu0 compared at the fit's reference temperature)."),
        Table("wet_map_stats", stats, "Friction-map fit statistics and covered region."),
        Table("wet_thermal", k_table, "Thermal conductances of Eq. 8: identified vs Table 1."),
        Figure("wet_fig14_engagement", engagement_figure(res_bench, res_dyno),
               "Engagement (cf. Fig. 14): force raised over 0.2 s; on the bench the motor keeps the slip on a "
               "smoothed ramp-down reference, on the inertia dynamometer the clutch can only decelerate the "
               "inertia, so slip profile, duration and heat differ."),
        Table("wet_engagement", eng_table, "Engagement events and energy (friction work = heat into pack + heat out)."),
    ]
    params = {k: f"{v:.6g}" for k, v in clutch.to_dict().items()}
    params.update({f"true {k}": f"{v:.6g}" for k, v in truth.to_dict().items()})
    return Section(
        title="Wet multi-plate clutch: friction map and thermal identification (Shin, Kim, Choi)",
        items=items,
        provenance="synthetic: bench records generated by clutchlab's virtual wet-clutch bench (fixed seed, "
                   "clutchlab/wet/data/generate.py) with a known friction law and Table 1 clutch; no measured data.",
        parameters=params,
    )

"""A toy cone clutch: the worked example of adding a component (docs/architecture.md, "Adding a component").

This file is the whole component: its declaration and its friction law.  Registering it is one line,
``register_component(CONE_CLUTCH)`` in a process, or, for an installed package, the entry point::

    [project.entry-points."clutchlab.components"]
    cone_clutch = "cone_clutch:CONE_CLUTCH"

Law (Shigley's Mechanical Engineering Design, 10th ed., Sec. 16-4, a cone clutch under uniform wear): the
axial force ``F_a`` presses the cone of half-angle ``alpha`` onto its cup, the surface's normal force is
``F_a / sin(alpha)``, and the sliding torque at the mean friction radius ``r_m`` is

    T = mu F_a r_m / sin(alpha)                                         (16-26 with r_m = (D + d) / 4)

A cone clutch holds the static limit ``peak`` times that at rest.  So it is the network's friction element
with the geometry constant ``cgeo = r_m / sin(alpha)`` and the normal force ``F_a(t)``: its friction law
is composed of the network's own friction port and its one stick/slip machine, and compiles nothing.
"""

from __future__ import annotations

import math

from clutchlab.component import Component, Field

__all__ = ["CONE_CLUTCH", "cone_torque_factor", "EXAMPLE"]

#: defaults of the fields the file may leave out: half-angle [rad] (Shigley: 10-15 deg usual), mu, peak
ALPHA, MU, PEAK = math.radians(12.0), 0.3, 1.0


def cone_torque_factor(r_mean: float, alpha: float) -> float:
    """Sliding torque per unit axial force and unit friction coefficient of a cone clutch [m].

    Shigley, Mechanical Engineering Design, Sec. 16-4, Eq. (16-26) (uniform wear), ``T / (mu F_a)``.

    Parameters
    ----------
    r_mean : float
        Mean radius of the friction surface [m].
    alpha : float
        Cone half-angle [rad], in (0, pi/2] (pi/2: a flat disc, T = mu F_a r_m).

    Returns
    -------
    float
        ``r_mean / sin(alpha)`` [m].
    """
    return r_mean / math.sin(alpha)


def _build(net, name, a, b, force, r_mean, alpha=ALPHA, mu=MU, peak=PEAK):
    # the axial force is the element's normal force: fn = 1 N x force(t) [N]
    net.clutch(name, a, b, fn_max=1.0, mu=mu, peak=peak, cgeo=cone_torque_factor(r_mean, alpha), normal=force)


CONE_CLUTCH = Component(
    "cone_clutch",
    "A cone clutch: sliding torque mu F_a r_m / sin(alpha) under the axial force F_a(t).",
    (
        Field("a", "flange", required=True, description="the cup's shaft"),
        Field("b", "flange", required=True, description="the cone's shaft"),
        Field("force", "signal", "N", required=True, description="axial force F_a(t) (free where <= 0)"),
        Field("r_mean", "quantity", "m", required=True, positive=True, maximum=2.0,
              description="mean radius of the friction surface"),
        Field("alpha", "quantity", "rad", default=ALPHA, positive=True, maximum=math.pi / 2,
              description="cone half-angle (pi/2: a flat disc)", source="Shigley Sec. 16-4: 10-15 deg usual"),
        Field("mu", "characteristic", "1", default=MU, minimum=0.0, maximum=2.0,
              description="sliding friction coefficient: a number or rows [w_rad_s, mu]"),
        Field("peak", "quantity", "1", default=PEAK, minimum=1.0, description="static limit over the sliding torque"),
    ),
    _build,
    source="Shigley, Mechanical Engineering Design, Sec. 16-4, Eq. (16-26)",
)


#: the worked example's network: J1 spinning at 100 rad/s coupled to J2 at rest through the cone clutch under a
#: constant axial force (J1 = 0.1, J2 = 0.3 kg m^2, F_a = 500 N, r_m = 50 mm, alpha = 12 deg, mu = 0.3; it
#: locks at 0.208 s)
EXAMPLE = """
[driveline]
name = "cone"

[simulation]
t_end = "0.4 s"
output_step = "1 ms"
rtol = 1e-10

[inertia.J1]
J = "0.1 kg m^2"
w0 = "100 rad/s"

[inertia.J2]
J = "0.3 kg m^2"

[cone_clutch.c]
a = "J1"
b = "J2"
force = "500 N"
r_mean = "50 mm"
alpha = "12 deg"
mu = 0.3
"""

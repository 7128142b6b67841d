"""The cross-flow finite-volume model of a clinker grate cooler, after the IIT Madras / NCL
Pune report (Mundhara, Sharma and Ranade, "Modeling of clinker coolers", 2005; reference
copy ``/work/shared/reference/clinker-grate-cooler.md``).

The bed
    The clinker moves in plug flow at the grate speed v_g (report Section 2.2.1); with the
    clinker mass flow m_s fixed the bed height follows, H = m_s / (rho_s (1 - eps) v_g W).
    Length and height are cut into n x m balance cells (120 x 90 in the report), each at
    one clinker and one air temperature, the temperature it leaves with (Eqs. 6-7, the
    upwind "fully mixed cell"). Every layer carries m_s / m (Eq. 1); every column of cells
    passes its share of the air, m_a Delta x / L for the report's uniform distribution
    (Eq. 16), or the case's compartment weights.

Clinker cell (i, j), Eqs. (8)-(15)
    F [h_s(T_W) - h_s(T_P)] + sum over faces of (1 - eps) k (T_nb - T_P) A / delta
    - a h (T_P - T_a,P) dV - q_rad = 0,
    with h_s the clinker enthalpy (the report writes F c_p (T_W - T_P); with a
    temperature-dependent c_p the enthalpy form is the one that conserves energy, and it is
    the same equation when c_p is constant). Boundary conditions of its Figure 3 / cases
    1-9: no conduction through the inlet face (the clinker brings T_in by advection only),
    none through the outlet face, none into the grate, and radiation instead of conduction
    at the top, q_rad = sigma eps_s (1 - eps) dx W (T_s^4 - T_fb^4) to the freeboard air
    above the cell (Eq. 32; the report's case 9 drops the (1 - eps) factor of cases 7, 8 and
    Eq. 32, taken here as a typo).

Air cell (i, j), Eqs. (19)-(28)
    M_i [h_a(T_S) - h_a(T_P)] + a h (T_s,P - T_P) dV = 0: plug flow upward, no conduction.

Freeboard cell (i, m+1), Eqs. (17), (32)
    The air leaving each column mixes with the air flowing along the freeboard towards the
    kiln end (i = 1), and takes up the radiation of the bed top below it; it leaves at the
    kiln end as secondary air, at the "air outlet temperature" of the report.

Convection
    The packed-bed Chilton-Colburn correlation of the report's Section 2.3 with the air
    properties at the film temperature, see :mod:`drumflow.coolers.grate.properties`.

Particle interior
    The report's cells are bed volumes: a clinker nodule is at its cell's temperature, with
    no internal resistance. For the shipped case (d_p = 20 mm, k = 1.5-1.9 W/(m K),
    h ~ 150-250 W/(m2 K)) the Biot number h d_p / (2 k) is about 1, so the internal
    resistance is not negligible; it is offered as an option (``model.interior_resistance
    = "jeschar"``: 1/h_eff = 1/h + d_p / (10 k_s), the quasi-steady resistance of a sphere
    with a parabolic profile, Jeschar 1964) instead of the project's transient shell solver
    (:mod:`drumflow.physics.particle_interior`), because the model is steady and its cells
    hold particles of every residence time along a layer; the report's choice ("none") is
    the default and the README gives the size of the effect.

Cell exchange
    The report's cell convects at its outlet temperatures (Eqs. 8, 21:
    a h dV (T_s,P - T_a,P)), a first-order form: on the report's 120 x 90 grid the outlet
    temperatures are still 2 K from their grid limit. ``numerics.exchange = "mean"`` (the
    shipped default) takes the same balance cells and fluxes but lets the convection act on
    the mean of each stream's inlet and outlet temperature in the cell (the trapezoidal
    rule in both marching directions, second order; outlets move 0.25 K from 120 x 90 to
    240 x 180). ``"outlet"`` is the report's form.

Solution
    The report solves the air column by column with TDMA, then the clinker along
    north-south lines, with under-relaxation (Section 2.5, Figure 6). Here every sweep is
    two passes of line TDMA solves (:func:`~drumflow.coolers.grate.tdma.tdma`):

    1. east-west lines (the layers, in which the clinker's advection couples the cells),
       bottom to top. In a cell the air equation involves only the cell's clinker and the
       air from the cell below, so it is eliminated exactly into the layer's equation and
       the layer is one tri-diagonal system; the layer's air follows. Conduction to the
       layer above is taken from the previous sweep, to the layer below from this one.
    2. north-south lines (the columns), from the kiln end to the discharge, with the air of
       pass 1 (the report's order); then the air is marched up again. This pass takes the
       vertical conduction implicitly, which keeps the sweep count at ~9 on every grid
       (with pass 1 alone it grows from 41 to 121 sweeps between 120 x 90 and 240 x 180).

    Properties, h and the secant heat capacities are updated every sweep; the bed-top
    radiation is Newton-linearised about the previous sweep; the freeboard is marched from
    the far end with its radiation implicit. Each line solve ends with under-relaxation
    T = T_old + alpha (T_new - T_old) (the report's Eq. 33, whose printed form drops the
    bracket; alpha = 1 converges here). The iteration stops when the summed absolute
    imbalance of every clinker, air and freeboard cell, as a fraction of the clinker's
    heat duty m_s [h_s(T_in) - h_s(T_air,in)], and the global energy imbalance are both
    below the case's tolerances (1e-9 in the shipped case).

Fan-limited air
    With ``air.supply = "fan"`` the air flow is not given but set where the fan curve meets
    the bed's Ergun pressure drop (:mod:`drumflow.coolers.grate.fans`): after every sweep the
    total air flow is moved to the operating point at the sweep's air temperatures, and the
    solve stops when, besides the two tolerances above, that flow changes by less than
    ``numerics.residual_tolerance`` relative. ``numerics.max_sweeps`` bounds the whole solve,
    the air-flow iteration included (the same sweeps, no outer loop). The solution's case
    holds the operating point as ``air.mass_flow``.

Runtime
    Measured in ``docs/grate/runtime.csv`` (written by ``studies/grate_studies.py``).
"""

from __future__ import annotations

import math
import time

import numpy as np
from numpy.typing import NDArray

from drumflow.coolers.grate.case import GrateCase
from drumflow.coolers.grate.fans import (
    bed_resistance,
    operating_point,
)
from drumflow.coolers.grate.properties import (
    ClinkerProperties,
    bed_specific_surface,
    packed_bed_h,
    radiation_conductance,
)
from drumflow.coolers.grate.solution import GrateSolution
from drumflow.coolers.grate.tdma import tdma
from drumflow.errors import GrateConvergenceError
from drumflow.physics.air import (
    AIR_T_MAX,
    AIR_T_MIN,
    air_enthalpy,
    air_enthalpy_scalar,
    air_heat_capacity,
    air_temperature_from_enthalpy,
)

__all__ = ["GrateConvergenceError", "solve_grate"]

FloatArray = NDArray[np.float64]


def _air_secant(t1: FloatArray, t2: FloatArray) -> FloatArray:
    """[h_a(t1) - h_a(t2)] / (t1 - t2), c_p at the mean where the two are within 1 mK."""
    dt = t1 - t2
    close = np.abs(dt) < 1e-3
    safe = np.where(close, 1.0, dt)
    return np.where(close, air_heat_capacity(0.5 * (t1 + t2)),
                    (air_enthalpy(t1) - air_enthalpy(t2)) / safe)


def _air_column_flow(case: GrateCase, n: int, air_flow: float | None = None) -> FloatArray:
    """Air mass flow through each column of cells, kg/s (compartment weights, kiln end first),
    for the case's total air flow or ``air_flow``."""
    weights = np.asarray(case.air.distribution, dtype=np.float64)
    x_centre = (np.arange(n) + 0.5) / n  # fraction of the grate length
    compartment = np.minimum((x_centre * weights.size).astype(int), weights.size - 1)
    w = weights[compartment]
    total = case.air.mass_flow if air_flow is None else air_flow
    return total * w / w.sum()


class _Grid:
    """Geometry, flows and fixed coefficients of one case on one grid."""

    def __init__(self, case: GrateCase) -> None:
        num, c, cooler = case.numerics, case.clinker, case.cooler
        self.case = case
        self.n, self.m = num.cells_length, num.cells_height
        self.bed_height = case.bed_height
        self.dx = cooler.length / self.n
        self.dy = self.bed_height / self.m
        self.width = cooler.width
        self.volume = self.dx * self.dy * self.width
        self.layer_flow = c.mass_flow / self.m  # Eq. (1)
        self.set_air_flow(case.air.mass_flow)
        self.surface = bed_specific_surface(c.bed_porosity, c.particle_diameter, c.sphericity)
        self.c_rad = radiation_conductance(case, self.n)
        self.theta = 0.5 if num.exchange == "mean" else 0.0
        self.props = ClinkerProperties.of(case)
        self.t_in = c.inlet_temperature
        self.t_air = case.air.inlet_temperature
        self.duty = c.mass_flow * float(self.props.enthalpy(self.t_in) - self.props.enthalpy(self.t_air))

    def set_air_flow(self, air_flow: float) -> None:
        """Set the total air flow (kg/s) and the column, flux and freeboard flows it implies."""
        self.air_flow = air_flow
        self.column_flow = _air_column_flow(self.case, self.n, air_flow)  # Eq. (16)
        self.shares = self.column_flow / self.column_flow.sum()
        self.mass_flux = self.column_flow / (self.dx * self.width)
        # Freeboard flow leaving cell i towards the kiln end: everything blown in at i..n-1.
        self.freeboard_flow = np.cumsum(self.column_flow[::-1])[::-1]

    def fan_air_flow(self, ta: FloatArray) -> float:
        """The fan's operating point at the air temperatures ``ta`` (frozen), kg/s."""
        fan = self.case.fan
        if fan is None:  # the case validator requires [fan] with air.supply = "fan"
            raise ValueError("air.supply = 'fan' without a [fan] section")
        resistance = bed_resistance(self.case, ta, self.shares, self.bed_height)
        return operating_point(fan, resistance, self.t_air)

    def h(self, ts: FloatArray, ta: FloatArray) -> FloatArray:
        """Heat-transfer coefficient of every cell at the film temperature, W/(m2 K)."""
        c = self.case.clinker
        h = packed_bed_h(self.mass_flux[None, :], 0.5 * (ts + ta), diameter=c.particle_diameter,
                         porosity=c.bed_porosity, sphericity=c.sphericity)
        if self.case.model.interior_resistance == "jeschar":
            inner = c.particle_diameter / (10.0 * self.props.conductivity(ts))
            h = np.where(h > 0.0, 1.0 / (1.0 / np.maximum(h, 1e-300) + inner), 0.0)
        return h

    def conduction(self, ts: FloatArray) -> tuple[FloatArray, FloatArray]:
        """Face conductances (1 - eps) k A / delta: east-west (m, n-1) and north-south (m-1, n)."""
        kb = (1.0 - self.case.clinker.bed_porosity) * self.props.conductivity(ts)
        dx_face = 0.5 * (kb[:, :-1] + kb[:, 1:]) * self.dy * self.width / self.dx
        dy_face = 0.5 * (kb[:-1, :] + kb[1:, :]) * self.dx * self.width / self.dy
        return dx_face, dy_face

    def freeboard(self, ts_top: FloatArray, ta_top: FloatArray, tfb_old: FloatArray) -> FloatArray:
        """Freeboard temperatures from the far end to the kiln end (Eq. 32).

        Without radiation the enthalpy of the freeboard air is a running sum. With it, each
        cell's balance M_fb h_a(T) + c_rad T^4 = gains is solved by Newton's method (both
        terms increase and are convex in T, so Newton from above converges), implicitly:
        with a small air flow the freeboard's heat capacity is tiny and a radiation term
        lagged by one sweep would make the iteration oscillate.
        """
        gain = self.column_flow * air_enthalpy(ta_top)
        if self.c_rad == 0.0:
            enthalpy = np.cumsum(gain[::-1])[::-1] / self.freeboard_flow
            return air_temperature_from_enthalpy(enthalpy)
        c_rad = self.c_rad
        emitted = c_rad * ts_top**4
        out = np.empty(self.n)
        carried = 0.0  # enthalpy flow arriving from the cell further from the kiln, W
        for i in range(self.n - 1, -1, -1):
            flow = float(self.freeboard_flow[i])
            rhs = float(gain[i] + emitted[i]) + carried
            t = max(float(tfb_old[i]), float(ts_top[i]), float(ta_top[i]))
            for _ in range(50):
                h, cp = air_enthalpy_scalar(t)
                step = (flow * h + c_rad * t**4 - rhs) / (flow * cp + 4.0 * c_rad * t**3)
                t = min(max(t - step, AIR_T_MIN), AIR_T_MAX)
                if abs(step) < 1e-10 * t:
                    break
            out[i] = t
            carried = flow * air_enthalpy_scalar(t)[0]
        return out

    def exchange_temperatures(self, ts: FloatArray,
                              ta: FloatArray) -> tuple[FloatArray, FloatArray]:
        """Clinker and air temperatures the cell's convection acts on: the outlet values
        (``exchange = "outlet"``, the report) or the means of inlet and outlet ("mean")."""
        if self.theta == 0.0:
            return ts, ta
        west = np.concatenate((np.full((self.m, 1), self.t_in), ts[:, :-1]), axis=1)
        below = np.concatenate((np.full((1, self.n), self.t_air), ta[:-1]))
        return (self.theta * west + (1.0 - self.theta) * ts,
                self.theta * below + (1.0 - self.theta) * ta)

    def residuals(self, ts: FloatArray, ta: FloatArray,
                  tfb: FloatArray) -> tuple[float, float, FloatArray]:
        """Summed absolute cell imbalance / duty, energy imbalance / duty, and h."""
        props = self.props
        ts_ex, ta_ex = self.exchange_temperatures(ts, ta)
        h = self.h(ts_ex, ta_ex)
        q = self.surface * h * self.volume * (ts_ex - ta_ex)
        hs = props.enthalpy(ts)
        hs_in = float(props.enthalpy(self.t_in))
        west = np.concatenate((np.full((self.m, 1), hs_in), hs[:, :-1]), axis=1)
        r_s = self.layer_flow * (west - hs) - q
        dxf, dyf = self.conduction(ts)
        flux_x = dxf * (ts[:, 1:] - ts[:, :-1])  # into the west cell from the east
        r_s[:, :-1] += flux_x
        r_s[:, 1:] -= flux_x
        flux_y = dyf * (ts[1:, :] - ts[:-1, :])
        r_s[:-1, :] += flux_y
        r_s[1:, :] -= flux_y
        rad = self.c_rad * (ts[-1] ** 4 - tfb**4)
        r_s[-1] -= rad
        ha = air_enthalpy(ta)
        below = np.concatenate((np.full((1, self.n), float(air_enthalpy(self.t_air))), ha[:-1]))
        r_a = self.column_flow[None, :] * (below - ha) + q
        hfb = air_enthalpy(tfb)
        downstream = np.append(hfb[1:], 0.0)
        flow_in = np.append(self.freeboard_flow[1:], 0.0)
        r_fb = self.column_flow * ha[-1] + flow_in * downstream + rad - self.freeboard_flow * hfb
        residual = (np.abs(r_s).sum() + np.abs(r_a).sum() + np.abs(r_fb).sum()) / self.duty
        q_clinker = self.case.clinker.mass_flow * hs_in - self.layer_flow * hs[:, -1].sum()
        q_air = self.air_flow * (hfb[0] - float(air_enthalpy(self.t_air)))
        return float(residual), float(abs(q_clinker - q_air) / self.duty), h

    def air_capacity(self, ta: FloatArray) -> FloatArray:
        """M_i times the secant c_p of every air cell between its inlet and outlet, W/K."""
        below = np.concatenate((np.full((1, self.n), self.t_air), ta[:-1]))
        return self.column_flow[None, :] * _air_secant(below, ta)

    def air_from_clinker(self, ts: FloatArray, ta: FloatArray, hv: FloatArray) -> None:
        """March the air up every column for the given clinker (exact for the cell
        equations with the secant c_p of the previous air field), in place."""
        th = self.theta
        caps = self.air_capacity(ta)
        below = np.full(self.n, self.t_air)
        west_in = np.full(1, self.t_in)
        for j in range(self.m):
            ts_ex = th * np.concatenate((west_in, ts[j, :-1])) + (1.0 - th) * ts[j]
            cap = caps[j]
            ta[j] = ((cap - th * hv[j]) * below + hv[j] * ts_ex) / (cap + (1.0 - th) * hv[j])
            below = ta[j]

    def sweep_layers(self, ts: FloatArray, ta: FloatArray, tfb: FloatArray, h: FloatArray,
                     alpha: float) -> None:
        """One bottom-to-top sweep of east-west line (layer) TDMA solves, in place; the air
        of each cell is eliminated exactly into its layer's equation."""
        props, n, m, th = self.props, self.n, self.m, self.theta
        hv = self.surface * h * self.volume
        dxf, dyf = self.conduction(ts)
        air_below = np.full(n, self.t_air)
        # Secant c_p of the air from the previous sweep (a lag that vanishes at convergence).
        caps = self.air_capacity(ta)
        for j in range(m):
            old = ts[j].copy()
            west = np.concatenate(([self.t_in], old[:-1]))
            adv = self.layer_flow * props.secant(west, old)
            cap = caps[j]
            # Air eliminated: heat to the air = exch * (T_s,exchange - T_air,below).
            exch = hv[j] * cap / (cap + (1.0 - th) * hv[j])
            a_w = adv - th * exch
            a_e = np.zeros(n)
            a_p = adv + (1.0 - th) * exch
            b = exch * air_below
            b[0] += a_w[0] * self.t_in
            a_w[0] = 0.0
            # East-west conduction; none through the inlet and outlet faces (Figure 3).
            a_p[:-1] += dxf[j]
            a_p[1:] += dxf[j]
            a_e[:-1] = dxf[j]
            a_w[1:] += dxf[j]
            if j > 0:  # the layer below is already this sweep's
                a_p += dyf[j - 1]
                b += dyf[j - 1] * ts[j - 1]
            if j < m - 1:  # the layer above from the previous sweep
                a_p += dyf[j]
                b += dyf[j] * ts[j + 1]
            elif self.c_rad > 0.0:
                # sigma eps (T^4 - T_fb^4) linearised about the previous sweep (Newton).
                a_p += 4.0 * self.c_rad * old**3
                b += self.c_rad * (3.0 * old**4 + tfb**4)
            new = tdma(a_w, a_p, a_e, b)
            ts[j] = old + alpha * (new - old)
            ts_ex = th * np.concatenate(([self.t_in], ts[j, :-1])) + (1.0 - th) * ts[j]
            ta[j] = ((cap - th * hv[j]) * air_below + hv[j] * ts_ex) / (cap + (1.0 - th) * hv[j])
            air_below = ta[j]
        tfb[:] = self.freeboard(ts[-1], ta[-1], tfb)

    def sweep_columns(self, ts: FloatArray, ta: FloatArray, tfb: FloatArray, h: FloatArray,
                      alpha: float) -> None:
        """One kiln-end-to-discharge sweep of north-south line (column) TDMA solves, with the
        air of the previous sweep (the report's order), then the air marched up again.

        The layer sweep leaves the slow vertical-conduction modes to Gauss-Seidel; a column
        solve takes them implicitly, which keeps the sweep count from growing with m^2.
        """
        props, n, m, th = self.props, self.n, self.m, self.theta
        hv = self.surface * h * self.volume
        dxf, dyf = self.conduction(ts)
        below = np.concatenate((np.full((1, n), self.t_air), ta[:-1]))
        ta_ex = th * below + (1.0 - th) * ta
        for i in range(n):
            old = ts[:, i].copy()
            west = np.full(m, self.t_in) if i == 0 else ts[:, i - 1]
            adv = self.layer_flow * props.secant(west, old)
            a_p = adv + (1.0 - th) * hv[:, i]
            b = (adv - th * hv[:, i]) * west + hv[:, i] * ta_ex[:, i]
            if i > 0:  # west column already this sweep's
                a_p += dxf[:, i - 1]
                b += dxf[:, i - 1] * ts[:, i - 1]
            if i < n - 1:  # east column from the previous sweep
                a_p += dxf[:, i]
                b += dxf[:, i] * ts[:, i + 1]
            a_s = np.zeros(m)
            a_n = np.zeros(m)
            a_p[:-1] += dyf[:, i]
            a_p[1:] += dyf[:, i]
            a_n[:-1] = dyf[:, i]
            a_s[1:] = dyf[:, i]
            if self.c_rad > 0.0:
                a_p[-1] += 4.0 * self.c_rad * old[-1] ** 3
                b[-1] += self.c_rad * (3.0 * old[-1] ** 4 + tfb[i] ** 4)
            new = tdma(a_s, a_p, a_n, b)
            ts[:, i] = old + alpha * (new - old)
        self.air_from_clinker(ts, ta, hv)
        tfb[:] = self.freeboard(ts[-1], ta[-1], tfb)


def solve_grate(case: GrateCase) -> GrateSolution:
    """Solve the grate-cooler model of a case to its tolerances.

    Parameters
    ----------
    case
        The validated case.

    Returns
    -------
    GrateSolution
        Fields and headline numbers.

    Raises
    ------
    GrateConvergenceError
        If ``numerics.max_sweeps`` sweeps do not bring the residual and the energy
        imbalance below their tolerances.
    """
    start = time.perf_counter()
    grid = _Grid(case)
    num = case.numerics
    ts = np.full((grid.m, grid.n), grid.t_in)
    ta = np.full((grid.m, grid.n), grid.t_air)
    tfb = np.full(grid.n, grid.t_air)
    fan_limited = case.air.supply == "fan"
    residual, imbalance, h = grid.residuals(ts, ta, tfb)
    history: list[tuple[int, float, float]] = []
    sweeps = 0
    flow_change = 0.0
    while True:
        grid.sweep_layers(ts, ta, tfb, h, num.under_relaxation)
        if grid.m > 1:
            grid.sweep_columns(ts, ta, tfb, h, num.under_relaxation)
        sweeps += 1
        if fan_limited:
            # The operating point at this sweep's air temperatures; the next sweep's fields
            # follow it, and both converge together (no outer loop, so max_sweeps bounds all).
            target = grid.fan_air_flow(ta)
            flow_change = abs(target - grid.air_flow) / grid.air_flow
            grid.set_air_flow(grid.air_flow + num.under_relaxation * (target - grid.air_flow))
        residual, imbalance, h = grid.residuals(ts, ta, tfb)
        history.append((sweeps, residual, imbalance))
        if not (math.isfinite(residual) and math.isfinite(imbalance) and math.isfinite(flow_change)):
            raise GrateConvergenceError(
                f"grate solve diverged at sweep {sweeps}; lower numerics.under_relaxation "
                f"(now {num.under_relaxation}; allowed > 0 and <= 1)")
        if (residual < num.residual_tolerance and imbalance < num.energy_tolerance
                and flow_change < num.residual_tolerance):
            break
        if sweeps >= num.max_sweeps:
            raise GrateConvergenceError(
                f"grate solve not converged after numerics.max_sweeps = {num.max_sweeps} "
                f"sweeps: residual {residual:.3g} (tolerance {num.residual_tolerance:g}), "
                f"energy imbalance {imbalance:.3g} (tolerance {num.energy_tolerance:g}), "
                f"air-flow change {flow_change:.3g} (tolerance {num.residual_tolerance:g}); "
                "raise max_sweeps (allowed <= 100000) or loosen the tolerances")
    y = np.asarray((np.arange(grid.m) + 0.5) * grid.dy, dtype=np.float64)
    x = np.asarray((np.arange(grid.n) + 0.5) * grid.dx, dtype=np.float64)
    if fan_limited:
        # The solution's case carries the operating point, so every number derived from
        # case.air.mass_flow (recovered heat, residence of the air) is the solved flow's.
        case = case.model_copy(update={"air": case.air.model_copy(
            update={"mass_flow": grid.air_flow})})
    return GrateSolution(
        case=case, x=x, y=y, clinker_temperature=ts, air_temperature=ta,
        freeboard_temperature=tfb, heat_transfer_coefficient=h,
        air_column_flow=grid.column_flow, bed_height=grid.bed_height, sweeps=sweeps,
        residual=residual, energy_imbalance=imbalance,
        wall_time_s=time.perf_counter() - start, history=history,
    )

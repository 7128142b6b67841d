"""Bubbling-bed hydrodynamics and gas-particle convection of the vibrating fluid-bed cooler.

Correlations, in SI units:

- humid-air properties: CoolProp's ``HAPropsSI`` (Lemmon et al. 2000 dry air, IAPWS-95
  water, Hyland and Wexler 1983 mixing);
- minimum fluidisation velocity: Wen and Yu (1966), and the voidage at minimum fluidisation
  their correlation implies in its inertial (large Archimedes number) limit,
  1 / (phi eps_mf^3) = 14;
- terminal velocity of a sphere: Haider and Levenspiel (1989);
- bed expansion (bubble fraction) of a freely bubbling bed at high excess velocity:
  Johnsson, Andersson and Leckner (1991, Powder Technol. 68, 117-123), with the dense
  (emulsion) phase at eps_mf (two-phase theory, Toomey and Johnstone 1952; Kunii and
  Levenspiel 1991, ch. 6);
- bubble equivalent diameter above a perforated plate: Darton et al. (1977), with the
  catchment area per orifice A_t / n that the source's eq. 15 names (reported, and used to
  say where the bed stands; it does not enter the voidage);
- hold-up and bed height: Picado and Martinez (2012), H = S / (v B rho_p (1 - eps));
- vibration intensity and vibration Reynolds number: the usual definitions
  (Gamma = A (2 pi f)^2 / g; Re_v = rho_g A (2 pi f) d / mu_g);
- particle Nusselt number in the bed: Gunn (1978).

Why not the source's Richardson-Zaki dense phase (issue 34). The source (after Lehmann et al.
2019) puts the suspension phase at the Richardson and Zaki (1954) voidage of the gas it
carries, eps_d = (u_d / u_t)^(1/n). That is particulate (liquid-like) expansion, which gas
beds of Geldart B and D particles do not show: their excess gas goes into bubbles and the
emulsion stays near minimum fluidisation (two-phase theory). Applied to 2.7 mm granules at
7.5 m/s (u / u_mf = 6.6) it gave a dense phase at eps_d = 0.98, a bed voidage of 0.989, a
3.63 m bed on a 1 m wide deck and 1.16 m bubbles. Johnsson et al. fitted the bubble fraction
of freely bubbling beds of coarse particles (fluidised-bed boiler conditions, excess
velocities of metres per second), where the two-phase theory with the visible bubble flow
over-predicts it; their correlation is the bed expansion used here.

Where a vibrated, shallow Geldart D bed stands. At the cooler's velocities (u / u_mf = 4.4
in section B and 6.6 in C) the gas, not the vibration, carries the bed: vibration lowers
the minimum fluidisation velocity and loosens the bed near and below u_mf, and its effect on
the bed fades as u rises well above u_mf (Gupta and Mujumdar 1980, Can. J. Chem. Eng. 58,
332; Pakowski et al. 1984), so no vibration term enters the expansion. The bed is shallow
(H ~ 0.1 m) and Darton's bubbles reach its depth (0.14-0.18 m at the surface): it is at
the end of the bubbling regime, past the onset of turbulent fluidisation of Bi and Grace
(1995), Re_c = 1.24 Ar^0.45 (u_c ~ 4 m/s here). Johnsson's correlation is extrapolated to
these conditions (2.7 mm, u - u_mf = 3.9-6.4 m/s); its particle-size factor has reached its
coarse-particle limit. The voidage it gives (0.57-0.60) is the bubbling-bed estimate; the
source's own bubble equations with the emulsion at eps_mf (Hilligardt and Werther's visible
bubble flow, psi = 0.26) give 0.74-0.79 at the same points, which bounds the uncertainty of
the bed's expansion here. Both are far from 0.99.

Why Gunn and not Pakowski et al. (1984): the source takes its Nusselt number from Pakowski,
Mujumdar and Strumillo (1984, Advances in Drying 3, pp. 245-306), a function of the gas
Reynolds number, the vibration Reynolds number and Gamma; that chapter's equation could not
be retrieved for this work, and inventing its coefficients is not an option. Gunn's
correlation is the standard gas-particle Nusselt number of fixed and fluidised beds
(0.35 <= eps <= 1, Re <= 1e5); vibration enters it only through the bed voidage. The
source multiplies the Nusselt number by a fitted efficiency f_c ("even though h is a
perfectly defined variable, in the model, it is one of the adjustable parameters"); the
source's f_c = 0.30 belongs to Pakowski's correlation and does not carry over to Gunn's.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

import CoolProp.CoolProp as CP
import numpy as np

GRAVITY = 9.81  # m/s^2

GeldartGroup = Literal["A", "B", "C", "D"]

#: Geldart groups the bubbling-bed correlations cover: Johnsson et al. (1991) fitted coarse
#: (B and D) particles; group A beds expand without bubbles first, group C do not fluidise.
BUBBLING_GROUPS: tuple[GeldartGroup, ...] = ("B", "D")

#: 1 / (phi eps_mf^3) of Wen and Yu (1966) in the inertial limit (their 1.75 / (phi eps^3)
#: = 24.5 Ergun term, 24.5 / 1.75 = 14).
WEN_YU_INERTIAL = 14.0


# -- air ---------------------------------------------------------------------------------------
@dataclass(frozen=True)
class HumidAir:
    """Humid air at one state, per kg of humid air unless stated.

    Attributes
    ----------
    temperature
        K.
    pressure
        Pa.
    humidity_ratio
        kg water / kg dry air.
    density
        kg humid air / m^3.
    heat_capacity
        J/(kg humid air K).
    viscosity
        Pa s.
    conductivity
        W/(m K).
    """

    temperature: float
    pressure: float
    humidity_ratio: float
    density: float
    heat_capacity: float
    viscosity: float
    conductivity: float

    @property
    def prandtl(self) -> float:
        return self.heat_capacity * self.viscosity / self.conductivity

    @property
    def enthalpy_per_dry_air(self) -> float:
        """Specific enthalpy, J per kg dry air (CoolProp's humid-air reference)."""
        return float(CP.HAPropsSI("H", "T", self.temperature, "P", self.pressure,
                                  "W", self.humidity_ratio))

    @property
    def dew_point(self) -> float:
        return float(CP.HAPropsSI("Tdp", "T", self.temperature, "P", self.pressure,
                                  "W", self.humidity_ratio))


def humid_air(temperature: float, pressure: float, humidity_ratio: float) -> HumidAir:
    """Properties of humid air from CoolProp's ``HAPropsSI``."""
    args = ("T", temperature, "P", pressure, "W", humidity_ratio)
    volume = CP.HAPropsSI("Vha", *args)  # m^3 per kg humid air
    return HumidAir(
        temperature=temperature,
        pressure=pressure,
        humidity_ratio=humidity_ratio,
        density=1.0 / volume,
        heat_capacity=CP.HAPropsSI("cp_ha", *args),
        viscosity=CP.HAPropsSI("mu", *args),
        conductivity=CP.HAPropsSI("k", *args),
    )


def humidity_ratio(temperature: float, pressure: float, relative_humidity: float) -> float:
    """Humidity ratio (kg water / kg dry air) of air at a relative humidity (0..1)."""
    return float(CP.HAPropsSI("W", "T", temperature, "P", pressure, "R", relative_humidity))


def saturation_humidity_ratio(temperature: float, pressure: float) -> float:
    return humidity_ratio(temperature, pressure, 1.0)


# -- single particle in a gas ------------------------------------------------------------------
def archimedes(diameter: float, particle_density: float, gas: HumidAir) -> float:
    """Ar = rho_g (rho_p - rho_g) g d^3 / mu^2."""
    return (gas.density * (particle_density - gas.density) * GRAVITY * diameter**3
            / gas.viscosity**2)


def minimum_fluidization_velocity(diameter: float, particle_density: float, gas: HumidAir) -> float:
    """Wen and Yu (1966): Re_mf = sqrt(33.7^2 + 0.0408 Ar) - 33.7, m/s."""
    ar = archimedes(diameter, particle_density, gas)
    re_mf = math.sqrt(33.7**2 + 0.0408 * ar) - 33.7
    return re_mf * gas.viscosity / (gas.density * diameter)


def terminal_velocity(diameter: float, particle_density: float, gas: HumidAir) -> float:
    """Haider and Levenspiel (1989) for spheres: u* = (18/d*^2 + 0.591/d*^0.5)^-1, m/s.

    d* = Ar^(1/3), u* = u_t (rho_g^2 / (mu (rho_p - rho_g) g))^(1/3).
    """
    d_star = archimedes(diameter, particle_density, gas) ** (1.0 / 3.0)
    u_star = 1.0 / (18.0 / d_star**2 + 0.591 / math.sqrt(d_star))
    scale = (gas.viscosity * (particle_density - gas.density) * GRAVITY / gas.density**2) ** (1.0 / 3.0)
    return u_star * scale


def min_fluidization_voidage(sphericity: float = 1.0) -> float:
    """Voidage at minimum fluidisation from Wen and Yu (1966): 1 / (phi eps_mf^3) = 14.

    Their two approximations, 1 / (phi eps_mf^3) ~ 14 and (1 - eps_mf) / (phi^2 eps_mf^3) ~ 11,
    are the two Ergun terms of their u_mf correlation; the first (the inertial term) sets u_mf
    at the cooler's Archimedes numbers (~1e6), so it is the eps_mf consistent with the u_mf
    used here: 14^(-1/3) = 0.415 for spheres.
    """
    if not 0.0 < sphericity <= 1.0:
        raise ValueError(f"sphericity = {sphericity!r}: allowed > 0 and <= 1")
    return (WEN_YU_INERTIAL * sphericity) ** (-1.0 / 3.0)


def geldart_group(diameter: float, particle_density: float, gas_density: float) -> GeldartGroup:
    """Geldart (1973) group from the boundaries of his diagram in SI units:
    C below 30 um; A/B at (rho_p - rho_g) d = 0.225 kg/m^2; B/D at (rho_p - rho_g) d^2 =
    1e-3 kg/m (Geldart 1973, Fig. 1, as read by Kunii and Levenspiel 1991, Fig. 3.8)."""
    drho = particle_density - gas_density
    if diameter < 30e-6:
        return "C"
    if drho * diameter <= 0.225:
        return "A"
    if drho * diameter**2 < 1e-3:
        return "B"
    return "D"


# -- bubbles -----------------------------------------------------------------------------------
def darton_bubble_diameter(excess_velocity: float, height: float | np.ndarray,
                           orifice_area: float) -> float | np.ndarray:
    """Bubble equivalent diameter at ``height`` above a perforated plate, m.

    Darton et al. (1977): d_v = 0.54 (u - u_mf)^0.4 (h + 4 sqrt(A_0))^0.8 / g^0.2, with
    A_0 = A_t / n the plate area per orifice (the source's eq. 15, after Karimipour and
    Pugsley 2011).
    """
    return (0.54 * excess_velocity**0.4 * (height + 4.0 * math.sqrt(orifice_area)) ** 0.8
            / GRAVITY**0.2)


def johnsson_bubble_fraction(excess_velocity: float, diameter: float) -> float:
    """Bubble volume fraction of a freely bubbling bed, Johnsson, Andersson and Leckner (1991):

    delta_b = 1 / (1 + 1.3 f^-1 (u - u_mf)^-0.8),
    f = (0.26 + 0.70 exp(-3.3 d_p)) (0.15 + (u - u_mf))^-0.33,

    with u - u_mf in m/s and d_p in mm (here converted from m). The dense phase is at eps_mf,
    so the bed voidage is delta_b + (1 - delta_b) eps_mf and H / H_mf = 1 / (1 - delta_b).

    Parameters
    ----------
    excess_velocity
        u - u_mf, m/s (> 0).
    diameter
        Particle diameter, m.
    """
    if not excess_velocity > 0.0:
        raise ValueError(f"excess velocity u - u_mf = {excess_velocity!r} m/s: must be > 0")
    d_mm = diameter * 1e3
    f = (0.26 + 0.70 * math.exp(-3.3 * d_mm)) * (0.15 + excess_velocity) ** -0.33
    return 1.0 / (1.0 + 1.3 / f * excess_velocity**-0.8)


@dataclass(frozen=True)
class BedState:
    """The hydrodynamic state of one section of the bed (averaged over its height).

    Attributes
    ----------
    geldart
        Geldart group.
    min_fluidization_velocity, terminal_velocity
        m/s.
    dense_phase_voidage
        eps_mf: the emulsion stays at minimum fluidisation (two-phase theory).
    bubble_fraction
        delta_b of Johnsson et al. (1991).
    voidage
        delta_b + (1 - delta_b) eps_mf.
    bed_height
        m, from the hold-up of the solids.
    bubble_diameter
        Darton's bubble diameter averaged over the bed height, m (reported).
    surface_bubble_diameter
        Darton's bubble diameter at the bed surface, m (reported: compared with the bed
        height it says how far the bed is from freely bubbling).
    """

    geldart: GeldartGroup
    min_fluidization_velocity: float
    terminal_velocity: float
    dense_phase_voidage: float
    bubble_fraction: float
    voidage: float
    bed_height: float
    bubble_diameter: float
    surface_bubble_diameter: float


def bed_state(velocity: float, gas: HumidAir, diameter: float, particle_density: float,
              solids_flow: float, solids_velocity: float, width: float,
              orifice_area: float, dense_phase_voidage: float | None = None) -> BedState:
    """Hydrodynamics of a bubbling section of the deck.

    Parameters
    ----------
    velocity
        Superficial gas velocity, m/s.
    gas
        The fluidising air.
    diameter, particle_density
        Particle Sauter diameter (m) and density (kg/m^3).
    solids_flow
        Product mass flow S, kg/s.
    solids_velocity
        Forward (plug-flow) velocity v of the solids, m/s.
    width
        Bed width B, m.
    orifice_area
        Distributor area per orifice A_t / n, m^2 (for the reported bubble diameters).
    dense_phase_voidage
        eps_mf; default :func:`min_fluidization_voidage` for spheres (Wen and Yu 1966).

    Notes
    -----
    Bubble fraction delta_b from Johnsson et al. (1991) (:func:`johnsson_bubble_fraction`),
    dense phase at eps_mf, bed voidage eps = delta_b + (1 - delta_b) eps_mf and bed height
    H = S / (v B rho_p (1 - eps)) (the source's eq. 20, Picado and Martinez 2012). The
    bubble fraction does not depend on H, so nothing is iterated. Darton's bubble diameter
    (source's eq. 15) is averaged over H (16-point Gauss-Legendre) and given at the surface.

    Raises
    ------
    ValueError
        Outside the correlations' range (not fluidised, elutriated, Geldart A or C, eps_mf
        outside 0.35..0.6).
    """
    group = geldart_group(diameter, particle_density, gas.density)
    if group not in BUBBLING_GROUPS:
        raise ValueError(f"Geldart group {group}: the bed-expansion correlation (Johnsson et al. "
                         "1991) covers groups B and D only")
    eps_mf = min_fluidization_voidage() if dense_phase_voidage is None else dense_phase_voidage
    if not 0.35 <= eps_mf <= 0.6:
        raise ValueError(f"minimum fluidisation voidage {eps_mf!r}: allowed 0.35 to 0.6")
    u_mf = minimum_fluidization_velocity(diameter, particle_density, gas)
    u_t = terminal_velocity(diameter, particle_density, gas)
    if velocity <= u_mf:
        raise ValueError(f"superficial velocity {velocity:.3g} m/s is not above the minimum "
                         f"fluidisation velocity {u_mf:.3g} m/s")
    if velocity >= u_t:
        raise ValueError(f"superficial velocity {velocity:.3g} m/s is not below the particles' "
                         f"terminal velocity {u_t:.3g} m/s (the bed would be blown out)")
    excess = velocity - u_mf
    delta = johnsson_bubble_fraction(excess, diameter)
    eps = delta + (1.0 - delta) * eps_mf
    height = solids_flow / (solids_velocity * width * particle_density * (1.0 - eps))
    nodes, weights = np.polynomial.legendre.leggauss(16)
    d_v = np.asarray(darton_bubble_diameter(excess, 0.5 * height * (nodes + 1.0), orifice_area))
    mean_d_v = float(0.5 * weights @ d_v)
    top_d_v = float(darton_bubble_diameter(excess, height, orifice_area))
    return BedState(group, u_mf, u_t, eps_mf, delta, eps, height, mean_d_v, top_d_v)


# -- vibration and convection ------------------------------------------------------------------
def vibration_intensity(amplitude: float, frequency: float) -> float:
    """Gamma = A (2 pi f)^2 / g: peak acceleration of the deck over gravity."""
    return amplitude * (2.0 * math.pi * frequency) ** 2 / GRAVITY


def vibration_reynolds(amplitude: float, frequency: float, diameter: float, gas: HumidAir) -> float:
    """Re_v = rho_g A (2 pi f) d / mu_g, on the deck's peak velocity."""
    return gas.density * amplitude * 2.0 * math.pi * frequency * diameter / gas.viscosity


def particle_reynolds(velocity: float, diameter: float, gas: HumidAir) -> float:
    """Re = rho_g u d / mu_g on the superficial velocity (Gunn 1978's definition)."""
    return gas.density * velocity * diameter / gas.viscosity


def gunn_nusselt(reynolds: float, prandtl: float, voidage: float) -> float:
    """Gunn (1978) gas-particle Nusselt number in fixed and fluidised beds, for one bed: the
    law lives once, in :func:`drumflow.physics.particle_air.gunn_nusselt` (0.35 <= eps <= 1,
    Re on the superficial velocity; a voidage outside raises a ``ValueError``)."""
    from drumflow.physics.particle_air import gunn_nusselt as law

    return float(law(reynolds, prandtl, voidage))

"""Bubbling-bed hydrodynamics and gas-particle convection of the vibrating fluid-bed cooler.

Every correlation here is the one named in the fluid-bed source's text (its equations were
images and are missing), taken from the cited literature, in SI units:

- humid-air properties: CoolProp's ``HAPropsSI`` (Lemmon et al. 2000 dry air, IAPWS-95
  water, Hyland and Wexler 1983 mixing);
- minimum fluidisation velocity: Wen and Yu (1966);
- terminal velocity of a sphere: Haider and Levenspiel (1989);
- Richardson and Zaki (1954) expansion, u = u_t eps^n, with the exponent fitted by Rowe (1987);
- bubble equivalent diameter above a perforated plate: Darton et al. (1977), the correlation
  Karimipour and Pugsley (2011) found best for Geldart B and D beds, with the catchment area
  per orifice A_t / n that the source's eq. 15 names;
- bubble rise velocity and visible bubble flow: Hilligardt and Werther (1986), as used by
  Lehmann et al. (2019);
- dense (suspension) phase gas velocity: the gas balance of the two-phase model
  (Clift and Grace 1985);
- hold-up and bed height: Lehmann et al. (2019) and Picado and Martinez (2012);
- vibration intensity and vibration Reynolds number: the usual definitions
  (Gamma = A (2 pi f)^2 / g; Re_v = rho_g A (2 pi f) d / mu_g);
- particle Nusselt number in the bed: Gunn (1978).

Why Gunn and not Pakowski et al. (1984): the source takes its Nusselt number from Pakowski,
Mujumdar and Strumillo (1984, Advances in Drying 3, pp. 245-306), a function of the gas
Reynolds number, the vibration Reynolds number and Gamma; that chapter's equation could not
be retrieved for this work, and inventing its coefficients is not an option. Gunn's
correlation is the standard gas-particle Nusselt number of fixed and fluidised beds
(0.35 <= eps <= 1, Re <= 1e5); vibration enters it only through the bed voidage. The
source multiplies the Nusselt number by a fitted efficiency f_c anyway ("even though h is
a perfectly defined variable, in the model, it is one of the adjustable parameters"), so
the level of h is set by the plant data, not by the correlation.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

import CoolProp.CoolProp as CP
import numpy as np
from scipy.optimize import brentq

GRAVITY = 9.81  # m/s^2

GeldartGroup = Literal["A", "B", "C", "D"]

#: Visible bubble flow ratio psi = (eps_b u_b) / (u - u_mf) of Hilligardt and Werther (1986)
#: for the Geldart groups their correlation covers.
VISIBLE_BUBBLE_FLOW_RATIO: dict[str, float] = {"B": 0.67, "D": 0.26}


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


def richardson_zaki_exponent(diameter: float, particle_density: float, gas: HumidAir) -> float:
    """Rowe (1987) fit of the Richardson-Zaki exponent:
    n = (4.7 + 0.41 Re_t^0.75) / (1 + 0.175 Re_t^0.75), Re_t on the terminal velocity."""
    re_t = gas.density * terminal_velocity(diameter, particle_density, gas) * diameter / gas.viscosity
    x = re_t**0.75
    return (4.7 + 0.41 * x) / (1.0 + 0.175 * x)


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


def bubble_rise_velocity(excess_velocity: float, bubble_diameter: float | np.ndarray,
                         psi: float) -> float | np.ndarray:
    """Hilligardt and Werther (1986): u_b = psi (u - u_mf) + 0.711 sqrt(g d_v), m/s.

    Their bed-geometry factor on the single-bubble term is taken as 1 (the Davidson and
    Harrison 1963 value): the cooler's bed is wide and shallow, far from the slugging limit
    that factor corrects for.
    """
    return psi * excess_velocity + 0.711 * np.sqrt(GRAVITY * bubble_diameter)


@dataclass(frozen=True)
class BedState:
    """The hydrodynamic state of one section of the bed (averaged over its height)."""

    geldart: GeldartGroup
    min_fluidization_velocity: float
    terminal_velocity: float
    richardson_zaki_n: float
    bubble_diameter: float
    bubble_rise_velocity: float
    bubble_fraction: float
    dense_phase_velocity: float
    dense_phase_voidage: float
    voidage: float
    bed_height: float


def bed_state(velocity: float, gas: HumidAir, diameter: float, particle_density: float,
              solids_flow: float, solids_velocity: float, width: float,
              orifice_area: float) -> BedState:
    """Hydrodynamics of a bubbling section, solved for the bed height that holds the solids.

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
        Distributor area per orifice A_t / n, m^2.

    Notes
    -----
    Bubble fraction eps_b = psi (u - u_mf) / u_b (visible bubble flow, Hilligardt and Werther
    1986), averaged over the bed height with the Darton bubble diameter at each height; the
    dense phase carries the rest of the gas, u_d = (u - psi (u - u_mf)) / (1 - eps_b)
    (Clift and Grace 1985), at the Richardson-Zaki voidage eps_d = (u_d / u_t)^(1/n); the
    hold-up is eps = eps_b + (1 - eps_b) eps_d (Lehmann et al. 2019) and the bed height
    H = S / (v B rho_p (1 - eps)) (Picado and Martinez 2012), solved with eps(H).

    Raises
    ------
    ValueError
        Outside the correlations' range (not fluidised, elutriated, Geldart A or C).
    """
    group = geldart_group(diameter, particle_density, gas.density)
    if group not in VISIBLE_BUBBLE_FLOW_RATIO:
        raise ValueError(f"Geldart group {group}: the bubble correlations (Hilligardt and "
                         "Werther 1986) cover groups B and D only")
    psi = VISIBLE_BUBBLE_FLOW_RATIO[group]
    u_mf = minimum_fluidization_velocity(diameter, particle_density, gas)
    u_t = terminal_velocity(diameter, particle_density, gas)
    n = richardson_zaki_exponent(diameter, particle_density, gas)
    if velocity <= u_mf:
        raise ValueError(f"superficial velocity {velocity:.3g} m/s is not above the minimum "
                         f"fluidisation velocity {u_mf:.3g} m/s")
    if velocity >= u_t:
        raise ValueError(f"superficial velocity {velocity:.3g} m/s is not below the particles' "
                         f"terminal velocity {u_t:.3g} m/s (the bed would be blown out)")
    excess = velocity - u_mf
    # Gauss-Legendre nodes for the height average of the bubble fraction.
    nodes, weights = np.polynomial.legendre.leggauss(16)

    def averages(height: float) -> tuple[float, float, float]:
        h = 0.5 * height * (nodes + 1.0)
        d_v = np.asarray(darton_bubble_diameter(excess, h, orifice_area))
        u_b = np.asarray(bubble_rise_velocity(excess, d_v, psi))
        eps_b = psi * excess / u_b
        w = 0.5 * weights
        return float(w @ eps_b), float(w @ d_v), float(w @ u_b)

    def voidage(height: float) -> tuple[float, float, float]:
        eps_b = averages(height)[0]
        u_d = (velocity - psi * excess) / (1.0 - eps_b)
        eps_d = min((u_d / u_t) ** (1.0 / n), 1.0)
        return eps_b + (1.0 - eps_b) * eps_d, u_d, eps_d

    def residual(height: float) -> float:
        eps = voidage(height)[0]
        return height * (1.0 - eps) - solids_flow / (solids_velocity * width * particle_density)

    height = float(brentq(residual, 1e-6, 1e3, xtol=1e-12, rtol=1e-12))
    eps, u_d, eps_d = voidage(height)
    eps_b, d_v, u_b = averages(height)
    return BedState(group, u_mf, u_t, n, d_v, u_b, eps_b, u_d, eps_d, eps, height)


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
    """Gunn (1978) gas-particle Nusselt number in fixed and fluidised beds:

    Nu = (7 - 10 eps + 5 eps^2)(1 + 0.7 Re^0.2 Pr^(1/3))
         + (1.33 - 2.4 eps + 1.2 eps^2) Re^0.7 Pr^(1/3),

    for 0.35 <= eps <= 1 and Re <= 1e5 (Re on the superficial velocity).
    """
    if not 0.35 <= voidage <= 1.0:
        raise ValueError(f"voidage {voidage:.3g} outside Gunn's range 0.35..1")
    pr3 = prandtl ** (1.0 / 3.0)
    return ((7.0 - 10.0 * voidage + 5.0 * voidage**2) * (1.0 + 0.7 * reynolds**0.2 * pr3)
            + (1.33 - 2.4 * voidage + 1.2 * voidage**2) * reynolds**0.7 * pr3)

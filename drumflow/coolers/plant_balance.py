"""The plant's measured outlets do not balance: what could close the gap, in kW.

With the paper's streams (Burgos-Florez et al. 2019, Table 1 and Section 3.1) the NPK gives
``m_s c_s (T_mi - T_mo)`` (about 885 kW from 90 to 46.5 C) and the air takes
``m_a c_a (T_ao - T_ai)`` (about 729 kW from 30 to 59 C): some 157 kW is unaccounted for. A
model that closes energy (the drum model does, to round-off) cannot match both outlets; the
NPK outlet is the prediction to compare, the air outlet a check. :func:`measured_balance`
puts a number on each candidate that could carry the gap:

* wall loss from the shell to ambient. Bounded above by the shell at the solids' mean
  temperature losing heat by natural convection (Churchill and Chu's horizontal-cylinder
  correlation, Incropera Eq. 9.34) and radiation (``4 eps sigma T_m^3``, the linearised
  grey-body exchange with surroundings at ambient): the shell is colder than the solids, so
  the real loss is below this, and wind would raise it;
* evaporation of part of the feed's moisture: its latent heat leaves with the air as vapour
  and does not warm it;
* a lower heat capacity of the NPK than the paper's 1465 J/(kg K);
* ambient air leaking in at the seals before the air outlet is measured (or an air flow above
  the measured one): the measured outlet would then be the mixed temperature of more air.

Each option gives what would close the gap alone and, where it has a bound, how many kW the
bound allows.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from drumflow.coolers.plant import PlantSpec
from drumflow.errors import DrumModelError
from drumflow.physics import air as air_properties

__all__ = [
    "BalanceOption",
    "LATENT_HEAT_J_KG",
    "PlantBalance",
    "measured_balance",
    "shell_loss_coefficient",
]

#: Latent heat of water near 40 C, J/kg (steam tables: 2.41 MJ/kg at 40 C).
LATENT_HEAT_J_KG = 2.4e6
_SIGMA = 5.670374419e-8  # Stefan-Boltzmann, W/(m2 K4)
_G = 9.81


def shell_loss_coefficient(diameter_m: float, shell_c: float, ambient_c: float,
                           emissivity: float = 0.9) -> float:
    """Outside loss coefficient of a horizontal cylinder in still air, W/(m2 K).

    Natural convection from Churchill and Chu (Incropera Eq. 9.34, any Rayleigh number) with
    the air properties at the film temperature (drumflow's Incropera Table A.4), plus the
    linearised radiation ``4 eps sigma T_m^3`` to surroundings at ambient.
    """
    if not shell_c > ambient_c:
        raise DrumModelError(f"shell_c = {shell_c}: must be above ambient_c = {ambient_c}")
    film = 0.5 * (shell_c + ambient_c)
    props = air_properties.air_properties(film, name="film temperature")
    nu = float(props.kinematic_viscosity)
    k = float(props.thermal_conductivity)
    pr = float(props.prandtl)
    alpha = nu / pr
    beta = 1.0 / (film + air_properties.KELVIN_OFFSET)
    rayleigh = _G * beta * (shell_c - ambient_c) * diameter_m**3 / (nu * alpha)
    nusselt = (0.60 + 0.387 * rayleigh ** (1 / 6)
               / (1 + (0.559 / pr) ** (9 / 16)) ** (8 / 27)) ** 2
    mean_k = film + air_properties.KELVIN_OFFSET
    return nusselt * k / diameter_m + 4.0 * emissivity * _SIGMA * mean_k**3


@dataclass(frozen=True)
class BalanceOption:
    """One way the gap could close.

    Attributes
    ----------
    name
        What it is.
    needed
        The value that closes the gap alone, in ``unit``.
    unit
        Unit of ``needed`` and ``bound``.
    bound
        A physical bound on the value (None when there is none to compute).
    heat_at_bound_w
        The heat the bound accounts for, W (None without a bound).
    note
        How the numbers are computed.
    """

    name: str
    needed: float
    unit: str
    bound: float | None
    heat_at_bound_w: float | None
    note: str

    def to_dict(self) -> dict[str, Any]:
        return {"name": self.name, "needed": self.needed, "unit": self.unit,
                "bound": self.bound, "heat_at_bound_W": self.heat_at_bound_w,
                "note": self.note}


@dataclass(frozen=True)
class PlantBalance:
    """The measured streams' heats and the options that could close their difference."""

    solids_heat_w: float
    air_heat_w: float
    options: list[BalanceOption]

    @property
    def gap_w(self) -> float:
        """Heat the NPK gives that the air does not take, W."""
        return self.solids_heat_w - self.air_heat_w

    def option(self, name: str) -> BalanceOption:
        return next(o for o in self.options if o.name == name)

    def to_dict(self) -> dict[str, Any]:
        return {"solids_heat_W": self.solids_heat_w, "air_heat_W": self.air_heat_w,
                "gap_W": self.gap_w, "options": [o.to_dict() for o in self.options]}


def measured_balance(plant: PlantSpec, ambient_c: float = 30.0, emissivity: float = 0.9,
                     evaporated_fraction: float = 0.005) -> PlantBalance:
    """The balance of the plant's measured outlets and what could close it (module notes).

    Parameters
    ----------
    plant
        The plant, with its measured outlets.
    ambient_c
        Ambient temperature (wall loss, leak air).
    emissivity
        Emissivity of the shell for the wall-loss bound.
    evaporated_fraction
        The share of the feed evaporated whose latent heat is reported as the evaporation
        option's "bound" (the issue's 0.5 %; not a measured value).

    Raises
    ------
    DrumModelError
        Without measured outlets, or when the air outlet is not above ambient.
    """
    t_mo, t_ao = plant.measured_material_outlet_c, plant.measured_air_outlet_c
    if t_mo is None or t_ao is None:
        raise DrumModelError("measured_material_outlet_c and measured_air_outlet_c: both needed "
                             "for the plant's balance")
    if not t_ao > ambient_c:
        raise DrumModelError(f"measured_air_outlet_c = {t_ao}: must be above ambient_c = "
                             f"{ambient_c} to weigh air leaking in")
    m_s, c_s = plant.feed_rate_kg_s, plant.particle_heat_capacity_j_kgk
    m_a, c_a = plant.air_mass_flow_kg_s, plant.air_heat_capacity_j_kgk
    drop = plant.material_inlet_temperature_c - t_mo
    solids = m_s * c_s * drop
    air = m_a * c_a * (t_ao - plant.air_inlet_temperature_c)
    gap = solids - air

    shell_area = math.pi * plant.diameter_m * plant.length_m
    solids_mean = 0.5 * (plant.material_inlet_temperature_c + t_mo)
    wall_dt = solids_mean - ambient_c
    u_bound = shell_loss_coefficient(plant.diameter_m, solids_mean, ambient_c, emissivity)
    wall = BalanceOption(
        name="wall loss",
        needed=gap / (shell_area * wall_dt),
        unit="W/(m2 K) over the shell",
        bound=u_bound,
        heat_at_bound_w=u_bound * shell_area * wall_dt,
        note=f"shell {shell_area:.0f} m2 at the solids' mean {solids_mean:.2f} C, ambient "
             f"{ambient_c:g} C; bound: still air, shell at the solids' temperature "
             f"(Churchill-Chu + radiation, emissivity {emissivity:g})",
    )
    evaporation = BalanceOption(
        name="evaporation",
        needed=gap / (m_s * LATENT_HEAT_J_KG),
        unit="fraction of the feed evaporated",
        bound=evaporated_fraction,
        heat_at_bound_w=evaporated_fraction * m_s * LATENT_HEAT_J_KG,
        note=f"latent heat {LATENT_HEAT_J_KG / 1e6:g} MJ/kg; 'bound' is the share quoted in "
             "issue 34, not a measurement",
    )
    capacity = BalanceOption(
        name="heat capacity",
        needed=air / (m_s * drop),
        unit="J/(kg K) of the NPK",
        bound=None,
        heat_at_bound_w=None,
        note=f"the NPK heat capacity at which its heat equals the air's; the paper uses {c_s:g}",
    )
    leak = BalanceOption(
        name="air leaking in",
        needed=gap / (c_a * (t_ao - ambient_c)),
        unit="kg/s of ambient air mixed in before the air outlet",
        bound=None,
        heat_at_bound_w=None,
        note=f"ambient air at {ambient_c:g} C warmed to the measured {t_ao:g} C; "
             f"{100 * gap / (c_a * (t_ao - ambient_c)) / m_a:.1f} % of the measured air flow "
             "(an air flow measured that much low reads the same)",
    )
    return PlantBalance(solids_heat_w=solids, air_heat_w=air,
                        options=[wall, evaporation, capacity, leak])

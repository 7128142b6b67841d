"""What a periodic slice's air around the bed tells a whole-cooler model (issue 32).

``drumflow bed-air --axial periodic --heat`` solves the drum's air with a bed state as porosity,
the slice as a piece of a long drum, and the air's temperature with the particles' heat. Its
folder holds ``split.json`` (the flow: how the axial air divides between bed, curtain and free
cells, and the air crossing into curtains and bed) and ``heat.json`` (the heat: the heat the air
took, the contact efficiency, and the **saturated flow**, the air per metre of drum that would
leave at the particles' mean temperature with that heat). Run with ``--mixing molecular`` and
``--mixing turbulent`` as well, it also holds ``heat_molecular.json`` and
``heat_turbulent.json``: the same solve with the air's own diffusivity everywhere and with the
mean turbulent one everywhere, the lower and upper bounds of the heat's mixing, which no
single snapshot removes.

:func:`read_air_closures` gathers those into :class:`AirClosures`, the slice's air closures as
the whole-cooler model (:mod:`drumflow.coolers.drum`) takes them: the through-curtain air (the
saturated flow, the closure declared when the bed-air heat was built, before any plant number)
with its mixing bounds; the contact efficiencies (all cells, bed cells, curtain cells: the heat
the air took over the heat if every particle had met fresh air at its cell's slip); the air
crossing into the curtains and into the bed; the axial air that bypasses both; the pressure
gradient of the long drum. They travel inside a closures file
(:attr:`drumflow.analysis.closures.SliceClosures.air`), so a later ``drumflow plant`` of that
file uses them without the slice's folders.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

from pydantic import BaseModel, ConfigDict, Field, ValidationError

from drumflow.errors import BadFileError
from drumflow.readers import field_problems, read_json_object

__all__ = ["MIXING_BOUNDS", "AirClosures", "read_air_closures"]

#: The mixing bounds' files beside ``heat.json``, by the bound they stand for.
MIXING_BOUNDS = {"molecular": "heat_molecular.json", "turbulent": "heat_turbulent.json"}

_Flow = Field(ge=0, allow_inf_nan=False)
# A contact efficiency is at most 1 up to the heat solve's enthalpy bookkeeping (1.5 % for
# model one's slice at its outer residual, `docs/air-around-the-bed.md`); 1.1 leaves room for
# that and still refuses a file that holds a heat in W where a ratio belongs.
_Efficiency = Field(ge=0, le=1.1, allow_inf_nan=False)


class AirClosures(BaseModel):
    """A periodic slice's air closures, per metre of drum (SI units; module notes).

    Attributes
    ----------
    source
        The ``heat.json`` they were read from.
    case_name, state_time_s
        The slice's case and the simulated time of its bed state.
    mixing
        The heat's diffusivity of ``source`` (``local``: each cell's own).
    curtain_air_m3_s_m
        The through-curtain air: the saturated flow, m3/s per metre of drum.
    curtain_air_molecular_m3_s_m, curtain_air_turbulent_m3_s_m
        The same with the air's own diffusivity everywhere (lower bound) and with the mean
        turbulent one everywhere (upper bound); None when that solve was not run.
    contact_efficiency, contact_efficiency_bed, contact_efficiency_curtain
        The heat the air took over the heat with fresh air at every particle: all cells, the
        bed cells, the curtain cells.
    curtain_inflow_m3_s_m, bed_inflow_m3_s_m
        Air crossing into the curtain cells from free air, and into the bed cells from the rest,
        m3/s per metre (lab-frame face fluxes).
    bypass_share
        The share of the axial air carried by free cells (neither bed nor curtain).
    pressure_gradient_Pa_m
        The long drum's axial pressure gradient with the bed in it, Pa/m.
    """

    model_config = ConfigDict(frozen=True, strict=True, extra="forbid")

    source: str
    case_name: str
    state_time_s: float = Field(ge=0, allow_inf_nan=False)
    mixing: str
    curtain_air_m3_s_m: float = _Flow
    curtain_air_molecular_m3_s_m: float | None = _Flow
    curtain_air_turbulent_m3_s_m: float | None = _Flow
    contact_efficiency: float = _Efficiency
    contact_efficiency_bed: float = _Efficiency
    contact_efficiency_curtain: float = _Efficiency
    curtain_inflow_m3_s_m: float = _Flow
    bed_inflow_m3_s_m: float = _Flow
    bypass_share: float = Field(ge=0, le=1, allow_inf_nan=False)
    pressure_gradient_Pa_m: float = Field(allow_inf_nan=False)

    def bounds(self) -> dict[str, float]:
        """The mixing bounds that were solved, by name (m3/s per metre)."""
        found = {"molecular": self.curtain_air_molecular_m3_s_m,
                 "turbulent": self.curtain_air_turbulent_m3_s_m}
        return {name: value for name, value in found.items() if value is not None}


def validate_air_closures(data: dict[str, Any], path: Path | str) -> AirClosures:
    """``data`` as :class:`AirClosures`, or a :class:`BadFileError` naming ``path`` and each
    field that is missing, not a number or out of its range."""
    try:
        return AirClosures.model_validate(data)
    except ValidationError as exc:
        raise BadFileError(path, f"invalid air closures: {'; '.join(field_problems(exc, data))}",
                           "a slice's air closures") from None


def _number(data: dict[str, Any], keys: tuple[str, ...], path: Path) -> Any:
    value: Any = data
    for key in keys:
        if not isinstance(value, dict) or key not in value:
            raise BadFileError(path, f"no {'.'.join(keys)} in it", "a drumflow bed-air result")
        value = value[key]
    return value


def read_air_closures(heat: Path | str) -> AirClosures:
    """The air closures of a ``drumflow bed-air --axial periodic --heat`` folder, from its
    ``heat.json`` (the file given), the ``split.json`` beside it and, where they exist, the
    mixing bounds' files (:data:`MIXING_BOUNDS`).

    Raises
    ------
    BadFileError
        A file missing, cut short or not JSON; an entry missing or out of range (named); a
        slice solved with the case's inlet and outlet (a 0.1 m slice's inlet forces fresh air
        through the bed: not a piece of a long drum); a bound's file of another state.
    """
    heat_path = Path(heat)
    split_path = heat_path.parent / "split.json"
    warm = read_json_object(heat_path, "a drumflow bed-air heat.json")
    split = read_json_object(split_path, "the split.json beside the heat.json")
    axial = split.get("axial")
    if axial != "periodic":
        raise BadFileError(split_path, f"axial = {axial}: allowed periodic (drumflow bed-air "
                           "--axial periodic --heat)", "the slice's air set-up")
    axial_flow = _number(split, ("bed", "axial_flow_m3_s"), split_path)
    try:
        total = float(axial_flow["total"])
        free = float(axial_flow["free"])
    except (KeyError, TypeError, ValueError):
        raise BadFileError(split_path, f"bed.axial_flow_m3_s = {axial_flow!r}: allowed an object "
                           "with numbers 'free' and 'total'", "a drumflow bed-air result") from None
    if not (math.isfinite(total) and total > 0):
        raise BadFileError(split_path, f"bed.axial_flow_m3_s.total = {total}: allowed > 0 m3/s",
                           "a drumflow bed-air result")
    bounds: dict[str, Any] = {}
    for name, file in MIXING_BOUNDS.items():
        path = heat_path.parent / file
        if path.is_file():
            other = read_json_object(path, f"the {name} mixing bound")
            if other.get("case_name") != warm.get("case_name"):
                raise BadFileError(path, f"case_name = {other.get('case_name')!r}, the heat.json's "
                                   f"is {warm.get('case_name')!r}: allowed the same slice",
                                   f"the {name} mixing bound")
            bounds[name] = _number(other, ("saturated_flow_m3_s_m",), path)
    data = {
        "source": str(heat_path),
        "case_name": _number(warm, ("case_name",), heat_path),
        "state_time_s": _number(split, ("state", "time_s"), split_path),
        "mixing": warm.get("mixing", "local"),
        "curtain_air_m3_s_m": _number(warm, ("saturated_flow_m3_s_m",), heat_path),
        "curtain_air_molecular_m3_s_m": bounds.get("molecular"),
        "curtain_air_turbulent_m3_s_m": bounds.get("turbulent"),
        "contact_efficiency": _number(warm, ("contact_efficiency",), heat_path),
        "contact_efficiency_bed": _number(warm, ("by_category", "bed", "contact_efficiency"),
                                          heat_path),
        "contact_efficiency_curtain": _number(
            warm, ("by_category", "curtain", "contact_efficiency"), heat_path),
        "curtain_inflow_m3_s_m": _number(split, ("bed", "inflow_m3_s_m", "curtain_from_free"),
                                         split_path),
        "bed_inflow_m3_s_m": _number(split, ("bed", "inflow_m3_s_m", "bed_from_other"),
                                     split_path),
        "bypass_share": free / total,
        "pressure_gradient_Pa_m": _number(split, ("bed", "pressure_gradient_Pa_m"), split_path),
    }
    return validate_air_closures(data, heat_path)

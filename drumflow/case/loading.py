"""Reading and validating input files: every problem named at once by field, value and allowed
range (:class:`drumflow.errors.CaseError`), for the drum case and every other input model.
"""

from __future__ import annotations

import tomllib
from pathlib import Path
from typing import Any, TypeVar

from pydantic import BaseModel, ValidationError

from drumflow.case.model import Case
from drumflow.errors import CaseError


def _format_error(err: dict[str, Any], loc: str) -> list[str]:
    msg: str = err.get("msg", "")
    value = err.get("input")
    etype = err.get("type", "")
    if etype == "value_error":
        # Our own model validators already name field, value and range, one per line.
        text = msg.removeprefix("Value error, ")
        return [line for line in text.splitlines() if line]
    if etype == "missing":
        return [f"{loc}: missing (required)"]
    if etype == "extra_forbidden":
        return [f"{loc} = {value!r}: unknown field (check the spelling)"]
    if etype in _TYPES and isinstance(value, str):
        # Strict input models (INPUT_MODEL_CONFIG): say what to write instead of the text.
        return [f"{loc} = {value!r}: text, not {_TYPES[etype]}; write the value without quotes"]
    if etype == "finite_number":
        return [f"{loc} = {value!r}: not a finite number; allowed: a finite number (not inf or nan)"]
    ctx = err.get("ctx") or {}
    bounds = [f"{word} {ctx[key]}" for key, word in _BOUNDS if key in ctx]
    allowed = f"; allowed: {' and '.join(bounds)}" if bounds else ""
    return [f"{loc} = {value!r}: {msg[:1].lower()}{msg[1:]}{allowed}"]


#: pydantic's type errors of the strict models and the type each one expects.
_TYPES = {"float_type": "a number", "int_type": "an integer", "bool_type": "true or false"}


_BOUNDS = (("gt", ">"), ("ge", ">="), ("lt", "<"), ("le", "<="))


def _clean_loc(err: dict[str, Any]) -> str:
    # pydantic appends the union member tag ("float", "literal['auto']") to the location.
    parts = [str(p) for p in err.get("loc", ())]
    return ".".join(
        p for p in parts
        if p not in {"float", "int"} and not p.startswith(("literal[", "constrained-"))
    )


def _merge_problems(errors: list[dict[str, Any]]) -> list[str]:
    """One line per mistake: a union field (float | "auto") fails once per member."""
    grouped: dict[str, list[dict[str, Any]]] = {}
    for err in errors:
        grouped.setdefault(_clean_loc(err), []).append(err)
    lines: list[str] = []
    for loc, errs in grouped.items():
        if len(errs) > 1 and all(e.get("type") != "value_error" for e in errs):
            # "must be > 0 or 'auto'": each member's own message and bounds, joined.
            parts = []
            for e in errs:
                text = _format_error(e, loc)[0].split(": ", 1)[-1]
                parts.append(text)
            lines.append(f"{loc} = {errs[0].get('input')!r}: " + " or ".join(sorted(set(parts))))
            continue
        for err in errs:
            lines.extend(_format_error(err, loc))
    return lines


_Model = TypeVar("_Model", bound=BaseModel)


def validate_model(model: type[_Model], data: dict[str, Any],
                   source: Path | str | None = None) -> _Model:
    """Validate nested dictionaries into any drumflow input model (drum case, cooler case,
    sweep file), with every problem named by field, value and allowed range.

    Raises
    ------
    CaseError
        Listing every problem.
    """
    try:
        return model.model_validate(data)
    except ValidationError as exc:
        raise CaseError(_merge_problems([dict(e) for e in exc.errors()]), source) from None


def read_toml(path: Path | str) -> dict[str, Any]:
    """Read a TOML input file.

    Raises
    ------
    CaseError
        When the file is missing or is not valid TOML.
    """
    from drumflow.errors import BadFileError
    from drumflow.readers import read_text

    path = Path(path)
    if not path.is_file():
        raise CaseError([f"case file {path}: not found"], path)
    try:
        text = read_text(path, "a TOML file")
    except BadFileError as exc:
        # A CaseError like every other problem of an input file; the message names the file.
        raise CaseError([exc.problem], path) from None
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise CaseError([f"not valid TOML: {exc}"], path) from None


def case_from_dict(data: dict[str, Any], source: Path | str | None = None) -> Case:
    """Validate a case given as nested dictionaries.

    Raises
    ------
    CaseError
        Listing every problem, each with field, value and allowed range.
    """
    return validate_model(Case, data, source)


def load_case(path: Path | str) -> Case:
    """Read and validate a TOML case file.

    Raises
    ------
    CaseError
        When the file is missing, is not valid TOML, or has invalid values.
    """
    data = read_toml(path)
    run = data.get("run")
    if isinstance(run, dict) and isinstance(run.get("start_state"), str):
        # Relative to the case file, as written; the case holds it resolved, so that the copy
        # of the case in a run directory still names the same file.
        run["start_state"] = _beside(path, run["start_state"])
    air = data.get("air")
    if isinstance(air, dict) and isinstance(air.get("bed_states"), list):
        # Relative to the case file, like run.start_state.
        air["bed_states"] = [_beside(path, s) if isinstance(s, str) else s
                             for s in air["bed_states"]]
    return case_from_dict(data, source=path)


def _beside(case_file: Path | str, name: str) -> str:
    """``name`` resolved against the case file's folder, unless absolute."""
    state = Path(name).expanduser()
    return str(state if state.is_absolute() else (Path(case_file).resolve().parent / state).resolve())


def case_to_toml(case: Case) -> str:
    """Write a case back as TOML (used for the copy kept in each run directory)."""
    import tomli_w

    data = case.model_dump(mode="json", exclude_none=True)
    if not data["air"].get("bed_states"):
        # The empty drum's air, as every case wrote it before the option existed.
        data["air"].pop("bed_states", None)
    return tomli_w.dumps(data)

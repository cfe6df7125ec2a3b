"""The review's grippers as typed rows: the checked-in transcription (grippers.yaml, tables.yaml) validated,
converted to SI and joined with Tables 1 and 2, with the provenance of every cell.

    load_tables() -> dict                         tables.yaml as transcribed
    expand_refs("[1,30–32]") -> [1, 30, 31, 32]   a reference list as printed
    table1_rows(tables, reading) -> list[dict]    Table 1, one row per (class, design, actuation, ref)
    curate(entries, tables, gravity) -> Curated   one row per cited gripper (COLUMNS) and one per cell

A malformed entry raises `MalformedEntry` naming the entry (its ref) and the field, in one line.
"""

from __future__ import annotations

import math
import re
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import yaml

HERE = Path(__file__).resolve().parent
GRIPPERS_FILE = HERE / "grippers.yaml"
TABLES_FILE = HERE / "tables.yaml"

CLASSES = ("completely constrained", "underconstrained", "deformable")
DESIGNS = ("compliant mechanism", "rigid links", "single mass gripper", "single mass finger",
           "square continuum robot")
ACTUATIONS = ("cable driven", "linear actuator", "rotary actuator", "electromagnet", "piezo actuator",
              "pneumatic/hydraulic", "dielectric elastomer", "SMA", "unspecified")
QUALIFIERS = ("=", "~", "<", "<=", ">", ">=")


@dataclass(frozen=True)
class Column:
    dtype: str          # pandas dtype of the exported column
    unit: str           # SI unit ("" for text, "count" for integers, "bool")
    meaning: str


# The dataset's columns, in order. Numbers are SI; `<quantity>_qualifier` says how the review states the
# number (= exactly, ~ about, <= up to, > more than).
COLUMNS: dict[str, Column] = {
    "ref": Column("int64", "", "reference number in the review's bibliography"),
    "name": Column("string", "", "the gripper, in the review's words (transcribed)"),
    "where": Column("string", "", "the section of the review that describes it (empty: only in Tables 1-2)"),
    "gripper_class": Column("string", "", "mobility class as the prose places it: " + ", ".join(CLASSES)),
    "design": Column("string", "", "design as the prose places it: " + ", ".join(DESIGNS)),
    "actuation": Column("string", "", "actuation as the prose describes it: " + ", ".join(ACTUATIONS)),
    "table1_class": Column("string", "", "class in Table 1 as reconstructed from the prose"),
    "table1_design": Column("string", "", "design in Table 1 as reconstructed"),
    "table1_actuation": Column("string", "", "actuation in Table 1 (as printed)"),
    "table1_reading": Column("string", "", "verbatim: Table 1 prints this placement; reconstructed: moved"),
    "table1_printed_class": Column("string", "", "class in Table 1 read as printed (garbled row-spans)"),
    "table1_printed_design": Column("string", "", "design in Table 1 read as printed"),
    "table2": Column("string", "", "Table 2 placements, `Type 1/Type 2/design`, separated by `; `"),
    "parallel_jaw": Column("boolean", "bool", "the prose describes parallel jaws or a moving finger against a "
                                              "fixed one"),
    "fingers": Column("Int64", "count", "number of fingers"),
    "joints_per_finger": Column("Int64", "count", "joints (DOF) per finger"),
    "phalanges": Column("Int64", "count", "phalanges per finger"),
    "joints_total": Column("Int64", "count", "joints of the whole hand"),
    "actuators": Column("Int64", "count", "actuated joints of the whole hand"),
    "grasp_force_n": Column("float64", "N", "grasp (fingertip or contact) force"),
    "grasp_force_tol_n": Column("float64", "N", "± of the grasp force"),
    "grasp_force_qualifier": Column("string", "", "how the grasp force is stated: " + " ".join(QUALIFIERS)),
    "payload_n": Column("float64", "N", "payload as a weight (a mass printed in g or kg times system.gravity)"),
    "payload_qualifier": Column("string", "", "how the payload is stated"),
    "object_size_min_m": Column("float64", "m", "smallest object (diameter, size or thickness) handled"),
    "object_size_max_m": Column("float64", "m", "largest object handled"),
    "opening_min_m": Column("float64", "m", "stroke, workspace or range: lower end"),
    "opening_max_m": Column("float64", "m", "stroke, workspace or range: upper end (the value when one is given)"),
    "motion_min_rad": Column("float64", "rad", "range of motion (finger angle or object orientation): lower end"),
    "motion_max_rad": Column("float64", "rad", "range of motion: upper end"),
    "torque_nm": Column("float64", "N*m", "a torque the review quotes (servo stall or joint load)"),
    "motor_power_w": Column("float64", "W", "rated power of the motor"),
    "length_m": Column("float64", "m", "actuator length"),
    "pressure_max_pa": Column("float64", "Pa", "maximum supply pressure"),
    "materials": Column("string", "", "materials named"),
    "hardware": Column("string", "", "actuators, sensors and mechanisms named"),
    "notes": Column("string", "", "what the review adds that has no column"),
}
# quantity in grippers.yaml -> (column stem, SI unit, kind): `count` (an integer), `value` (one number) or
# `range` (min and/or max)
QUANTITIES: dict[str, tuple[str, str, str]] = {
    "fingers": ("fingers", "count", "count"), "joints_per_finger": ("joints_per_finger", "count", "count"),
    "phalanges": ("phalanges", "count", "count"), "joints_total": ("joints_total", "count", "count"),
    "actuators": ("actuators", "count", "count"),
    "grasp_force": ("grasp_force_n", "N", "value"), "payload": ("payload_n", "N", "value"),
    "torque": ("torque_nm", "N*m", "value"), "motor_power": ("motor_power_w", "W", "value"),
    "length": ("length_m", "m", "value"),
    "object_size": ("object_size_{}_m", "m", "range"), "opening": ("opening_{}_m", "m", "range"),
    "motion": ("motion_{}_rad", "rad", "range"), "pressure": ("pressure_{}_pa", "Pa", "range"),
}
TEXT_FIELDS = ("materials", "hardware", "notes")
REQUIRED = ("ref", "name", "where", "class", "design", "actuation")
# printed unit -> (SI unit, factor); masses become weights with the gravity given to `curate`
UNITS: dict[str, tuple[str, float]] = {
    "mm": ("m", 1e-3), "cm": ("m", 1e-2), "m": ("m", 1.0), "mN": ("N", 1e-3), "N": ("N", 1.0),
    "g": ("N", 1e-3), "kg": ("N", 1.0), "deg": ("rad", math.pi / 180), "N m": ("N*m", 1.0), "W": ("W", 1.0),
    "MPa": ("Pa", 1e6),
}
MASS_UNITS = ("g", "kg")


class MalformedEntry(ValueError):
    """An entry of the transcription that cannot be typed (its ref and field are in the message)."""


@dataclass(frozen=True)
class Curated:
    rows: list[dict[str, Any]]    # one per gripper, keyed by COLUMNS
    cells: list[dict[str, Any]]   # one per transcribed cell: ref, column, printed, unit, where, quote, reading


def load_yaml(path: Path) -> Any:
    # libyaml's safe loader where PyYAML has it: the same values, ten times faster than the pure-Python one
    return yaml.load(Path(path).read_text(), Loader=getattr(yaml, "CSafeLoader", yaml.SafeLoader))


def load_tables(path: Path = TABLES_FILE) -> dict:
    return load_yaml(path)


def expand_refs(printed: str) -> list[int]:
    """`[5,9,12,13,55–62]` -> [5, 9, 12, 13, 55, ..., 62]; the review prints ranges with an en dash."""
    body = printed.strip()
    if not re.fullmatch(r"\[\d+(?:[–-]\d+)?(?:,\d+(?:[–-]\d+)?)*\]", body):
        raise MalformedEntry(f"reference list {printed!r} is not like [1,30–32]")
    refs = []
    for part in body[1:-1].split(","):
        low, _, high = part.replace("–", "-").partition("-")
        refs += range(int(low), int(high or low) + 1)
    return refs


def table1_rows(tables: dict, reading: str = "reconstructed") -> list[dict[str, Any]]:
    """Table 1 as (class, design, actuation, ref, reading) rows: the reconstruction, or the printed cells with
    their row-spans carried down (`printed`)."""
    rows = []
    if reading == "reconstructed":
        for cls, design, actuation, refs, how in tables["table1"]:
            rows += [{"class": cls, "design": design, "actuation": actuation, "ref": r, "reading": how}
                     for r in expand_refs(refs)]
        return rows
    above = ["", "", ""]
    for cells in tables["table1_printed"]:
        above = [c or a for c, a in zip(cells[:3], above, strict=True)]
        rows += [{"class": above[0], "design": above[1], "actuation": above[2], "ref": r, "reading": "printed"}
                 for r in expand_refs(cells[3])]
    return rows


def table2_rows(tables: dict) -> list[dict[str, Any]]:
    return [{"type1": t1, "type2": t2, "design": design, "ref": r, "attributes": attributes, "reading": how}
            for t1, t2, design, refs, attributes, how in tables["table2"] for r in expand_refs(refs)]


def _number(ref: Any, field: str, value: Any) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
        raise MalformedEntry(f"gripper [{ref}]: {field}={value!r} is not a finite number")
    return float(value)


def _quantity(ref: Any, field: str, spec: Any, gravity: float) -> tuple[dict[str, Any], list[dict[str, Any]]]:
    """One transcribed quantity -> its SI columns and its provenance cells."""
    stem, si_unit, kind = QUANTITIES[field]
    if not isinstance(spec, dict) or not spec.get("quote"):
        raise MalformedEntry(f"gripper [{ref}]: {field} must be a mapping with a `quote` (the review's sentence)")
    unknown = set(spec) - {"value", "min", "max", "unit", "quote", "qualifier", "tol"}
    if unknown:
        raise MalformedEntry(f"gripper [{ref}]: {field} has unknown keys {sorted(unknown)}")
    qualifier = spec.get("qualifier", "=")
    if qualifier not in QUALIFIERS:
        raise MalformedEntry(f"gripper [{ref}]: {field}.qualifier={qualifier!r} is not one of {' '.join(QUALIFIERS)}")
    cell = {"quote": spec["quote"], "qualifier": qualifier}
    if kind == "count":
        value = spec.get("value")
        if isinstance(value, bool) or not isinstance(value, int) or value < 1:
            raise MalformedEntry(f"gripper [{ref}]: {field}={value!r} must be a positive whole number")
        return {stem: value}, [{**cell, "column": stem, "printed": str(value), "unit": "count"}]
    unit = spec.get("unit")
    if unit not in UNITS:
        raise MalformedEntry(f"gripper [{ref}]: {field}.unit={unit!r} is not one of {', '.join(UNITS)}")
    target, factor = UNITS[unit]
    if target != si_unit:
        raise MalformedEntry(f"gripper [{ref}]: {field} in {unit} is not a {si_unit} quantity")
    if unit in MASS_UNITS:
        factor *= gravity  # a mass quoted as a payload: its weight
    out, cells = {}, []
    if kind == "value":
        ends = {"value": spec.get("value")}
    elif "value" in spec:  # a range stated by one number (a stroke, a workspace): its upper end
        ends = {"max": spec["value"]}
    else:
        ends = {k: spec.get(k) for k in ("min", "max")}
    if all(v is None for v in ends.values()):
        raise MalformedEntry(f"gripper [{ref}]: {field} needs " + ("a value" if kind == "value" else "a min or max"))
    for end, printed in ends.items():
        if printed is None:
            continue
        column = stem if kind == "value" else stem.format(end)
        out[column] = _number(ref, f"{field}.{end}", printed) * factor
        cells.append({**cell, "column": column, "printed": f"{printed:g}", "unit": unit})
    if kind == "range" and len(out) == 2 and min(out.values()) > max(out.values()):
        raise MalformedEntry(f"gripper [{ref}]: {field}.min > {field}.max")
    if f"{stem.removesuffix('_n')}_qualifier" in COLUMNS:
        out[f"{stem.removesuffix('_n')}_qualifier"] = qualifier
    if "tol" in spec:
        tol_column = f"{stem.removesuffix('_n')}_tol_n"
        if tol_column not in COLUMNS:
            raise MalformedEntry(f"gripper [{ref}]: {field} cannot carry a `tol`")
        out[tol_column] = _number(ref, f"{field}.tol", spec["tol"]) * factor
        cells.append({**cell, "column": tol_column, "printed": f"{spec['tol']:g}", "unit": unit})
    return out, cells


def _choice(ref: Any, field: str, value: Any, allowed: Iterable[str]) -> str:
    if value not in allowed:
        raise MalformedEntry(f"gripper [{ref}]: {field}={value!r} is not one of: {', '.join(allowed)}")
    return value


def curate(entries: list[dict], tables: dict, gravity: float) -> Curated:
    """One typed row per cited gripper: every entry of grippers.yaml, then every reference Tables 1-2 list
    that the prose does not describe."""
    if not isinstance(entries, list) or not entries:
        raise MalformedEntry("grippers.yaml must be a non-empty list of grippers")
    t1 = {r["ref"]: r for r in table1_rows(tables, "reconstructed")}
    t1_printed = {r["ref"]: r for r in table1_rows(tables, "printed")}
    t2: dict[int, list[str]] = {}
    for r in table2_rows(tables):
        t2.setdefault(r["ref"], []).append(f"{r['type1']}/{r['type2']}/{r['design']}")
    rows, cells, seen = [], [], set()
    for entry in entries:
        ref = entry.get("ref") if isinstance(entry, dict) else None
        if not isinstance(ref, int) or isinstance(ref, bool) or ref < 1:
            raise MalformedEntry(f"gripper entry {entry!r:.80}: `ref` must be a positive reference number")
        if ref in seen:
            raise MalformedEntry(f"gripper [{ref}] is listed twice")
        seen.add(ref)
        missing = [k for k in REQUIRED if not entry.get(k)]
        if missing:
            raise MalformedEntry(f"gripper [{ref}]: missing {', '.join(missing)}")
        unknown = set(entry) - {*REQUIRED, *QUANTITIES, *TEXT_FIELDS, "parallel_jaw"}
        if unknown:
            raise MalformedEntry(f"gripper [{ref}]: unknown fields {sorted(unknown)}; allowed: "
                                 f"{', '.join((*REQUIRED, *QUANTITIES, *TEXT_FIELDS, 'parallel_jaw'))}")
        row = {"ref": ref, "name": str(entry["name"]), "where": str(entry["where"]),
               "gripper_class": _choice(ref, "class", entry["class"], CLASSES),
               "design": _choice(ref, "design", entry["design"], DESIGNS),
               "actuation": _choice(ref, "actuation", entry["actuation"], ACTUATIONS),
               "parallel_jaw": bool(entry.get("parallel_jaw", False))}
        where = row["where"]
        for field in ("class", "design", "actuation"):
            cells.append({"ref": ref, "column": "gripper_class" if field == "class" else field,
                          "printed": entry[field], "unit": "", "where": where, "quote": "", "qualifier": "",
                          "reading": "placed by the section"})
        for field in QUANTITIES:
            if field in entry:
                values, quantity_cells = _quantity(ref, field, entry[field], gravity)
                row.update(values)
                cells += [{"ref": ref, "where": where, "reading": "transcribed", **c} for c in quantity_cells]
        for field in TEXT_FIELDS:
            if field in entry:
                row[field] = str(entry[field])
                cells.append({"ref": ref, "column": field, "printed": row[field], "unit": "", "where": where,
                              "quote": "", "qualifier": "", "reading": "transcribed"})
        rows.append(row)
    for ref in sorted((t1.keys() | t2.keys()) - seen):
        rows.append({"ref": ref, "name": "", "where": "", "parallel_jaw": False})
    for row in rows:
        ref = row["ref"]
        if ref in t1:
            row.update(table1_class=t1[ref]["class"], table1_design=t1[ref]["design"],
                       table1_actuation=t1[ref]["actuation"], table1_reading=t1[ref]["reading"],
                       table1_printed_class=t1_printed[ref]["class"], table1_printed_design=t1_printed[ref]["design"])
            cells += [{"ref": ref, "column": c, "printed": row[c], "unit": "", "where": "Table 1", "quote": "",
                       "qualifier": "", "reading": "printed" if "printed" in c else t1[ref]["reading"]}
                      for c in ("table1_class", "table1_design", "table1_actuation", "table1_printed_class",
                                "table1_printed_design")]
        if ref in t2:
            row["table2"] = "; ".join(t2[ref])
            cells.append({"ref": ref, "column": "table2", "printed": row["table2"], "unit": "", "where": "Table 2",
                          "quote": "", "qualifier": "", "reading": "transcribed"})
    rows.sort(key=lambda r: r["ref"])
    return Curated([{c: row.get(c) for c in COLUMNS} for row in rows], cells)

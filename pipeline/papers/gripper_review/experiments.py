"""The `dataset` experiment: the transcription checked and typed (curated.py), logged as records.

Topics (one record per row; the log time only orders the records, 1 ms apart):
    /grippers      repro.ReviewGripper   one per cited gripper, fields named with their SI unit
    /cells         repro.ReviewCell      one per transcribed cell: where in the review, the printed value
                                         and unit, the sentence quoted
    /review_tables repro.ReviewTableRow  one per row of Tables 1 (printed and reconstructed), 2, 3 and
                                         Table 2's size classes (SI)
"""

from __future__ import annotations

import math

from omegaconf import DictConfig

from pipeline.core import schemas
from pipeline.core.experiment import Case
from pipeline.core.runlog import RunWriter
from pipeline.papers.gripper_review import curated

_PROTO = {"int64": "int64", "string": "string", "boolean": "bool", "Int64": "double", "float64": "double"}


def _field(column: curated.Column) -> str:
    kind = _PROTO[column.dtype]
    if kind in ("string", "bool"):
        return kind
    return f"{kind} {'1' if column.unit in ('', 'count') else column.unit}"


ReviewGripper = schemas.define(
    "ReviewGripper",
    "One gripper the review cites. Numbers in SI, the unit in each field's name (_n N, _m m, _rad rad, _nm "
    "N·m, _w W, _pa Pa); counts (fingers, joints, phalanges, actuators) as doubles; NaN: the review states "
    "none. pipeline/papers/gripper_review/curated.py: COLUMNS says what each field means.",
    **{name: _field(column) for name, column in curated.COLUMNS.items()},
)
ReviewCell = schemas.define(
    "ReviewCell", "Provenance of one cell of /grippers: where the review prints it, as printed, and the quote.",
    ref="int64 1", column="string", printed="string", unit="string", qualifier="string", where="string",
    quote="string", reading="string",
)
ReviewTableRow = schemas.define(
    "ReviewTableRow", "One row of a table of the review; cells labelled by `name`, text as printed.",
    table="string", row="uint32 1", name="string[]", value="string[]",
)
RECORD_DT = 1e-3  # s between records: a table is a sequence of records, not a trajectory


def _gripper_fields(row: dict) -> dict:
    fields = {}
    for name, column in curated.COLUMNS.items():
        value = row[name]
        if column.dtype in ("float64", "Int64"):
            fields[name] = math.nan if value is None else float(value)
        elif column.dtype == "string":
            fields[name] = "" if value is None else value
        else:
            fields[name] = value
    return fields


def _table_rows(tables: dict, large_unit: str, gravity: float) -> list[tuple[str, list[str], list[str]]]:
    rows = []
    for cells in tables["table1_printed"]:
        rows.append(("table1_printed", ["class", "design", "actuation", "refs"], cells))
    for cells in tables["table1"]:
        rows.append(("table1", ["class", "design", "actuation", "refs", "reading"], cells))
    for cells in tables["table2"]:
        rows.append(("table2", ["type1", "type2", "design", "refs", "attributes", "reading"], cells))
    for entry in tables["table3"]:
        rows.append(("table3", list(entry), list(entry.values())))
    for size, ends in tables["table2_sizes"].items():  # in m, the missing unit as chosen
        si = [value * curated.UNITS[unit or large_unit][1] for value, unit in ends]
        rows.append(("table2_sizes", ["size", "min_m", "max_m"], [size, *(repr(v) for v in si)]))
    for cls, bounds in tables["table3_bounds"].items():
        for bound, (value, unit) in bounds.items():
            si = value * curated.UNITS[unit][1] * (gravity if unit in curated.MASS_UNITS else 1.0)
            rows.append(("table3_bounds", ["class", "bound", "value_si", "printed"], [cls, bound, repr(si),
                                                                                        f"{value:g} {unit}"]))
    for key, value in tables["stated"].items():
        for name, count in (value.items() if isinstance(value, dict) else [("", value)]):
            rows.append(("stated", ["quantity", "of", "count"], [key, name, str(count)]))
    return rows


def dataset(cfg: DictConfig) -> list[Case]:
    # read and checked before the run starts: a malformed transcription fails in one line, nothing written
    tables = curated.load_tables()
    data = curated.curate(curated.load_yaml(curated.GRIPPERS_FILE), tables, cfg.system.gravity)

    def simulate(log: RunWriter) -> None:
        for i, row in enumerate(data.rows):
            log.log("/grippers", i * RECORD_DT, ReviewGripper, **_gripper_fields(row))
        for i, cell in enumerate(data.cells):
            log.log("/cells", i * RECORD_DT, ReviewCell, **{k: cell[k] for k in ReviewCell.DESCRIPTOR.fields_by_name})
        counters: dict[str, int] = {}
        for i, (table, names, values) in enumerate(_table_rows(tables, cfg.scenario.table2_large_unit,
                                                                    cfg.system.gravity)):
            counters[table] = counters.get(table, 0) + 1
            log.log("/review_tables", i * RECORD_DT, ReviewTableRow, table=table, row=counters[table], name=names,
                    value=[str(v) for v in values])
        log.attach("grippers.yaml", curated.GRIPPERS_FILE.read_text(), "application/yaml")
        log.attach("tables.yaml", curated.TABLES_FILE.read_text(), "application/yaml")

    return [Case("review", simulate)]

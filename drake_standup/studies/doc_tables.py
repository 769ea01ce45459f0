"""The results tables of the docs, written from the campaigns' outputs, so that each number
has one source: a table lives in a Markdown file between `<!-- table:NAME -->` and
`<!-- /table:NAME -->`, and this module renders it from its CSV (a sweep's or a
comparison's results.csv).

    python -m drake_standup.studies.doc_tables [--check]

rewrites every table from its CSV (--check: writes nothing, exits 1 naming each table
that differs from what its CSV gives).
"""

from __future__ import annotations

import argparse
import csv
import sys
from dataclasses import dataclass
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]


@dataclass(frozen=True)
class Column:
    header: str
    key: str  # the CSV's column
    fmt: str = "{}"  # a format for a number; text as it is


@dataclass(frozen=True)
class Table:
    name: str
    csv: Path
    document: Path
    columns: tuple[Column, ...]
    where: tuple[tuple[str, tuple[str, ...]], ...] = ()  # (CSV column, values kept)


# The shipped scenarios, advancement, from the comparison the docs keep (docs/compare/).
SHIPPED = ("assisted", "reactive", "body", "lateral", "hindering")
TABLES = (
    Table(
        "shipped_scenarios",
        REPO / "docs" / "compare" / "results.csv",
        REPO / "docs" / "results.md",
        (
            Column("scenario", "helper"),
            Column("stood up", "success"),
            Column("stand-up (s)", "standup_time_s", "{:.2f}"),
            Column("waited (s)", "held_back_s", "{:.1f}"),
            Column("psi_final", "psi_final", "{:.2f}"),
            Column("psi_dot_max", "psi_dot_max", "{:.2f}"),
            Column("state 2, 3, 4 (s)", "state_entry_times_s[1..3]", "{:.2f}"),
            Column("CoM z at the end (m)", "com_final_m[2]", "{:.3f}"),
            Column("max abs tau (N m)", "max_abs_torque_Nm", "{:.0f}"),
            Column("QP failures", "qp_failures"),
            Column("sole chatter (N)", "sole_force_chatter_N", "{:.0f}"),
            Column("arms (rad/s)", "peak_joint_speed_arms_rad_per_s", "{:.2f}"),
        ),
        where=(("response", ("advancement",)), ("helper", SHIPPED)),
    ),
)


def _cell(row: dict[str, str], column: Column) -> str:
    key = column.key
    if key.endswith("]") and ".." in key:  # a range of a list's entries: base[i..j]
        base, span = key[:-1].split("[")
        first, last = (int(k) for k in span.split(".."))
        keys = [f"{base}[{k}]" for k in range(first, last + 1)]
        return ", ".join(_cell(row, Column(column.header, k, column.fmt)) for k in keys)
    value = row.get(key, "")
    if value in ("", "None", "nan"):
        return "-"
    if value in ("True", "False"):
        return "yes" if value == "True" else "no"
    try:
        return column.fmt.format(float(value)) if column.fmt != "{}" else value
    except ValueError:
        return value


def render(table: Table) -> str:
    """The table's Markdown from its CSV (its rows in the CSV's order)."""
    with open(table.csv, newline="") as f:
        rows = [r for r in csv.DictReader(f) if all(r.get(k) in v for k, v in table.where)]
    lines = [
        "| " + " | ".join(c.header for c in table.columns) + " |",
        "|" + "---|" * len(table.columns),
    ]
    lines += ["| " + " | ".join(_cell(r, c) for c in table.columns) + " |" for r in rows]
    source = table.csv.relative_to(REPO)
    return "\n".join(lines) + f"\n\n(Written from {source} by drake_standup/studies/doc_tables.py.)"


def _markers(name: str) -> tuple[str, str]:
    return f"<!-- table:{name} -->", f"<!-- /table:{name} -->"


def placed(text: str, table: Table) -> str:
    """text with the table's Markdown between its markers."""
    start, end = _markers(table.name)
    if start not in text or end not in text:
        raise ValueError(f"{table.document.name}: no {start} ... {end}")
    head, rest = text.split(start, 1)
    _, tail = rest.split(end, 1)
    return f"{head}{start}\n{render(table)}\n{end}{tail}"


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m drake_standup.studies.doc_tables",
        description="Write the docs' results tables from the campaigns' CSVs.",
    )
    parser.add_argument("--check", action="store_true", help="write nothing; exit 1 on a diff")
    args = parser.parse_args(argv)
    stale = []
    for table in TABLES:
        text = table.document.read_text()
        new = placed(text, table)
        if new != text:
            stale.append(table.name)
            if not args.check:
                table.document.write_text(new)
    if args.check and stale:
        print(f"tables not as their CSV gives: {', '.join(stale)}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())

"""Findings of ``hwfoc check`` as Arrow tables: :func:`check` on one source, and the schema the
fleet functions (:func:`hwfoc.dask.findings`, :func:`hwfoc.spark.findings`) share. Columns are
documented in docs/CHECKS.md (section "Python")."""

import json
import os
from typing import Any, Mapping, Optional, Union

import pyarrow as pa

from ._hwfoc import check_json

#: The columns of a findings table, one row per finding, in the command's order.
FINDINGS_SCHEMA = pa.schema([
    pa.field("recording", pa.string(), nullable=False),
    pa.field("esc", pa.int64()),
    pa.field("esc_label", pa.string()),
    pa.field("analyser", pa.string(), nullable=False),
    pa.field("severity", pa.string(), nullable=False),
    pa.field("start_s", pa.float64()),
    pa.field("end_s", pa.float64()),
    pa.field("values", pa.list_(pa.struct([
        pa.field("name", pa.string(), nullable=False),
        pa.field("value", pa.float64()),
        pa.field("unit", pa.string(), nullable=False),
    ])), nullable=False),
    pa.field("threshold_name", pa.string()),
    pa.field("threshold_value", pa.float64()),
    pa.field("threshold_unit", pa.string()),
    pa.field("message", pa.string(), nullable=False),
])

Toml = Union[None, str, "os.PathLike[str]", Mapping[str, Any]]


def _toml(value: Toml, what: str) -> Optional[str]:
    """A TOML file's path, or its table already parsed, as JSON text for the library."""
    if value is None:
        return None
    if isinstance(value, Mapping):
        return json.dumps(value)
    try:
        import tomllib  # type: ignore[import-not-found]
    except ImportError:  # Python < 3.11
        import tomli as tomllib  # type: ignore[import-not-found, no-redef]
    with open(value, "rb") as f:
        table = tomllib.load(f)
    if what == "config":
        table = table.get("check", {})
    return json.dumps(table)


def rows(findings: list) -> list:
    """The command's findings (``hwfoc check --json``'s ``findings``) as rows of
    :data:`FINDINGS_SCHEMA`."""
    out = []
    for f in findings:
        esc = f.get("esc") or {}
        window = f.get("window") or {}
        threshold = f.get("threshold") or {}
        out.append({
            "recording": f["recording"],
            "esc": esc.get("number"),
            "esc_label": esc.get("label"),
            "analyser": f["analyser"],
            "severity": f["severity"],
            "start_s": window.get("start_s"),
            "end_s": window.get("end_s"),
            "values": f["values"],
            "threshold_name": threshold.get("name"),
            "threshold_value": threshold.get("value"),
            "threshold_unit": threshold.get("unit"),
            "message": f["message"],
        })
    return out


def check(source: Any, *, config: Toml = None, baseline: Toml = None, **settings: Any) -> pa.Table:
    """The findings of ``hwfoc check --json`` on ``source`` (as :func:`hwfoc.read` takes it) as
    a ``pyarrow.Table`` of :data:`FINDINGS_SCHEMA`, a row per finding in the command's order.

    ``config``: the thresholds, as the configuration file's ``[check]`` table (a mapping) or a
    configuration file (its ``[check]`` table is taken); the documented defaults without it.
    ``baseline``: a baseline ``hwfoc check --fit-baseline`` wrote (a path, or the table
    parsed), for the drift analyser. ``settings``: ``current_scale``, ``pole_pairs``,
    ``gear_ratio``, ``settings`` as :func:`hwfoc.read`'s. Raises
    :class:`hwfoc.InputError` as :func:`hwfoc.read` does, ``ValueError`` for a config or
    baseline that does not fit."""
    text = check_json(source, config=_toml(config, "config"), baseline=_toml(baseline, "baseline"), **settings)
    return pa.Table.from_pylist(rows(json.loads(text)), schema=FINDINGS_SCHEMA)

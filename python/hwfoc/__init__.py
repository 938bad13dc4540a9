"""Hobbywing ESC telemetry as Arrow tables (HW-FOC, DataLink V2, Platinum V4 and V3, HW5).

The records are those of docs/RECORD-SCHEMA.md (the same names, types and units as every output of
the ``hwfoc`` command): one row per data frame, in physical units.

- :func:`read`: inputs read whole into a ``pyarrow.Table`` (raw bytes from the wire,
  logic-analyser CSV exports, pcapng recordings; paths, ``bytes`` or binary file objects);
- :func:`scan`: the same records as ``pyarrow.RecordBatch`` es, in bounded memory, for inputs
  larger than memory;
- :func:`summary`: what ``hwfoc summary --json`` prints, as Python objects;
- :func:`check`: the findings of ``hwfoc check`` (docs/CHECKS.md) as a ``pyarrow.Table``;
- :class:`Decoder`: a streaming decoder for live bytes; :class:`CanDecoder`: one for CAN frames
  already held (python-can messages); :func:`open_ports`: live records from
  serial ports, as ``hwfoc monitor`` reads them;
- :mod:`hwfoc.dask` and :mod:`hwfoc.spark`: fleets of recordings on Dask and Spark.

Every function and class that reads inputs takes ``protocol=``, a name of :data:`PROTOCOLS`
(as the command's ``--protocol``), to read that protocol only; by default every protocol is
recognised from the bytes.

Errors are raised as :class:`HwfocError` subclasses whose message is the one the ``hwfoc``
command prints after ``hwfoc:``.

Polars and pandas take the table as it is::

    import hwfoc, polars as pl
    table = hwfoc.read("flight.pcapng")
    df = pl.from_arrow(table)      # or table.to_pandas()
"""

from ._hwfoc import (
    DEFAULT_CURRENT_SCALE,
    DEFAULT_GEAR_RATIO,
    DEFAULT_POLE_PAIRS,
    DEFAULT_SETTINGS,
    PROTOCOLS,
    CanDecoder,
    Decoder,
    HwfocError,
    HwfocWarning,
    InputError,
    PortError,
    PortWarning,
    Ports,
    Scan,
    SelectionError,
    SettingsError,
    __version__,
    open_ports,
    read,
    record_schema,
    scan,
    summary,
)
from .findings import FINDINGS_SCHEMA, check

__all__ = [
    "FINDINGS_SCHEMA",
    "check",
    "DEFAULT_CURRENT_SCALE",
    "DEFAULT_GEAR_RATIO",
    "DEFAULT_POLE_PAIRS",
    "DEFAULT_SETTINGS",
    "PROTOCOLS",
    "CanDecoder",
    "Decoder",
    "HwfocError",
    "HwfocWarning",
    "InputError",
    "PortError",
    "PortWarning",
    "Ports",
    "Scan",
    "SelectionError",
    "SettingsError",
    "__version__",
    "open_ports",
    "read",
    "record_schema",
    "scan",
    "summary",
]

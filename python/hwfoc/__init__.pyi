"""Type stubs of ``hwfoc`` (the functions and classes of its extension module, ``hwfoc._hwfoc``)."""

import datetime
import os
from types import TracebackType
from typing import IO, Any, Dict, Iterable, Iterator, List, Mapping, Optional, Sequence, Tuple, Union

import pyarrow as pa

__version__: str

#: The default of every ``current_scale`` argument: raw current units per ampere (the library's,
#: as the ``hwfoc`` command's ``--current-scale``).
DEFAULT_CURRENT_SCALE: float
#: The default of every ``pole_pairs`` argument: the motor's pole pairs.
DEFAULT_POLE_PAIRS: int
#: The default of every ``gear_ratio`` argument: motor turns per output shaft turn.
DEFAULT_GEAR_RATIO: float
#: The formats' own settings, each key of every ``settings`` argument with its default, from the
#: formats' descriptions (the ``hwfoc`` command's ``--set KEY=VALUE``):
#: ``{"v4_volts_per_step": "8/910"}``, volts per voltage ADC step of a Platinum V4 ESC until its
#: info frame is adopted (``"N/D"``, ``"low"``: 8/910, or ``"hv"``: 11/650 for HV models).
DEFAULT_SETTINGS: Dict[str, str]
#: The names every ``protocol`` argument takes (``"hw-foc"``: an ESC's own wire, 19200 baud;
#: ``"datalink"``: a DataLink V2 hub, 115200 baud; ``"hw-v4"`` and ``"hw-v3"``: Platinum V4 and
#: V3, 19200 baud; ``"hw5"``: HW5, 115200 baud; ``"hw-can"`` and ``"dronecan"``: Hobbywing's
#: and standard DroneCAN ESCs on a CAN bus), as the command's ``--protocol``. A forced protocol
#: leaves a CAN bus's records of any other out (counted in a HwfocWarning); a CAN protocol
#: decodes nothing of serial bytes, and is a ValueError for a serial port. The default, None,
#: recognises every protocol from the bytes.
PROTOCOLS: Tuple[str, ...]

#: One input: a path, bytes in memory, or a binary file object.
Source = Union[str, "os.PathLike[str]", bytes, bytearray, memoryview, IO[bytes]]
#: Inputs read one after another, as the command reads the inputs named together.
Sources = Union[Source, Sequence[Source]]
#: A time as ``t_s`` has it (seconds; Unix time for recordings), or a datetime.
Time = Union[float, int, datetime.datetime]

class HwfocError(Exception):
    """Base class of the errors hwfoc raises; the message is the one the hwfoc command prints."""

class InputError(HwfocError):
    """An input could not be opened or read (missing file, directory, empty input, bad CSV row,
    classic pcap, raw bytes where times are needed, too many streams)."""

class PortError(HwfocError):
    """A serial port could not be opened (missing, permission denied, busy, not a port)."""

class SelectionError(HwfocError):
    """A selection that cannot hold any frame: ``start`` not before ``end``."""

class SettingsError(HwfocError):
    """A conversion setting out of range (current scale, pole pairs, gear ratio)."""

class HwfocWarning(UserWarning):
    """What the hwfoc command prints as ``hwfoc: warning: ...`` (or ``note: ...``): an input whose
    bytes hold no frame (:func:`read`), a damaged or foreign part of a recording skipped, a note
    written in a recording (:func:`read`, :func:`scan`, :func:`summary`). The message is the
    command's text after that prefix."""

class PortWarning(HwfocWarning):
    """A serial port was lost (unplugged: it is retried) or is back."""

def read(
    source: Sources,
    *,
    esc: Union[int, Sequence[int], None] = None,
    start: Optional[Time] = None,
    end: Optional[Time] = None,
    current_scale: float = ...,
    pole_pairs: int = ...,
    gear_ratio: float = ...,
    settings: Optional[Mapping[str, str]] = None,
    protocol: Optional[str] = None,
    join: bool = False,
) -> pa.Table:
    """Reads telemetry whole into a ``pyarrow.Table`` of docs/RECORD-SCHEMA.md's records.

    ``source``: a path (raw bytes from the wire, a logic-analyser CSV export or a pcapng
    recording: the format is detected from the content), ``bytes``/``bytearray``/``memoryview``,
    a binary file object, or a list of these read one after another (the files of one
    recording, such as a rotated one, continue each port's stream; other files are ESCs of their
    own, however their ports are named, unless ``join=True`` reads them as one recording, as the
    command's ``--join``; a file given twice is read once). ``esc``, ``start`` and ``end`` select as the
    command's ``--esc``, ``--from`` (inclusive) and ``--to`` (exclusive); a time window needs
    inputs with receive times. The settings convert currents and RPM; ``settings`` sets the formats' own
    settings by the keys of :data:`DEFAULT_SETTINGS`, each value as the command's ``--set
    KEY=VALUE`` takes it (``{"v4_volts_per_step": "hv"}`` converts a Platinum V4 ESC's voltage
    until its info frame is adopted). ``protocol``: a name of
    :data:`PROTOCOLS`, to read that protocol's frames only (the bytes of any other are skipped
    bytes), as the command's ``--protocol``; None reads every protocol.

    The columns are record schema version 2's: ``protocol`` a dictionary of strings (a name of
    :data:`PROTOCOLS`: a categorical in pandas and polars), ``packet`` uint32, and every
    measurement, ``status`` and ``faults`` nullable (null where the ESC's format does not carry
    it: ``motor_temp_c``, ``bec_temp_c``, ``bec_voltage_v`` and ``bec_current_a`` in every
    HW-FOC and DataLink record; all but throttle, eRPM and RPM in a V3 record; ``packet``,
    output throttle, phase current and ``cap_temp_c`` in an HW5 record, whose ``faults`` are
    HW5's fault names).

    The schema's metadata holds what ``hwfoc decode --format parquet`` writes in its file:
    ``hwfoc_version``, ``record_schema_version`` (``4``), ``current_scale``, ``pole_pairs``,
    ``gear_ratio``, each key of :data:`DEFAULT_SETTINGS`, ``inputs`` and ``escs`` (JSON) and ``filter`` when records were selected;
    each field has its ``unit``.

    Raises InputError (also for a serial port's path: read ports with :func:`open_ports`; and,
    after the warnings, when no input held a data frame, as ``hwfoc decode`` fails), SelectionError, SettingsError (also for a ``settings`` key no format has: the message lists
    the keys); TypeError for a source of another type; ValueError for a
    ``protocol`` not in :data:`PROTOCOLS` or a ``settings`` value the setting does not take. Warns HwfocWarning
    for inputs without frames and for a recording's damage and notes.
    """

def scan(
    sources: Sources,
    *,
    batch_rows: int = 65536,
    esc: Union[int, Sequence[int], None] = None,
    start: Optional[Time] = None,
    end: Optional[Time] = None,
    current_scale: float = ...,
    pole_pairs: int = ...,
    gear_ratio: float = ...,
    settings: Optional[Mapping[str, str]] = None,
    protocol: Optional[str] = None,
    join: bool = False,
) -> "Scan":
    """The records of ``sources`` as ``pyarrow.RecordBatch``es of at most ``batch_rows`` rows,
    in bounded memory whatever the size of the inputs (read a block at a time on a thread of
    its own, at most two batches ahead).

    Arguments as :func:`read`. Errors opening the inputs are raised by ``scan`` itself; an
    error part-way is raised by the iterator after the batches of the records before it. The
    batches' schema metadata is :func:`read`'s without ``escs`` (known only at the end).
    Warnings as :func:`read`'s: a recording's damage and notes as they are met, inputs without
    frames once all are read.
    """

class Scan(Iterator[pa.RecordBatch]):
    """An iterator of ``pyarrow.RecordBatch``: see :func:`scan`."""

    def __iter__(self) -> "Scan": ...
    def __next__(self) -> pa.RecordBatch: ...
    def close(self) -> None:
        """Stops the decoding thread; the iterator then ends."""

FINDINGS_SCHEMA: pa.Schema

def check(
    source: Sources,
    *,
    config: Union[None, str, "os.PathLike[str]", Mapping[str, Any]] = None,
    baseline: Union[None, str, "os.PathLike[str]", Mapping[str, Any]] = None,
    current_scale: float = ...,
    pole_pairs: int = ...,
    gear_ratio: float = ...,
    settings: Optional[Mapping[str, str]] = None,
) -> pa.Table:
    """The findings of ``hwfoc check --json`` on ``source`` as a table of
    :data:`FINDINGS_SCHEMA` (docs/CHECKS.md, "Python")."""
    ...

def summary(
    source: Sources,
    *,
    current_scale: float = ...,
    pole_pairs: int = ...,
    gear_ratio: float = ...,
    settings: Optional[Mapping[str, str]] = None,
    protocol: Optional[str] = None,
    join: bool = False,
) -> Dict[str, Any]:
    """What ``hwfoc summary --json`` prints for ``source``, as Python objects: the settings,
    the inputs (format, bytes, ESCs) and per ESC its link statistics, field ranges, faults and
    fault episodes. ``protocol`` as :func:`read`'s. Raises InputError and ValueError as
    :func:`read`."""

def record_schema(
    *,
    current_scale: float = ...,
    pole_pairs: int = ...,
    gear_ratio: float = ...,
    settings: Optional[Mapping[str, str]] = None,
) -> pa.Schema:
    """The Arrow schema of the records (units in the fields' metadata, settings in the
    schema's)."""

class CanDecoder:
    """A streaming decoder of one CAN bus's frames that the caller already holds (python-can
    ``Message`` objects, or ``(timestamp, arbitration_id, data, is_extended)`` tuples), read
    as ``hwfoc.read`` reads a CAN log: DroneCAN transfers, then a record per ESC status. An ESC
    at slot ``s`` of the bus (its throttle channel - 1, or its node id until an ESC id answer,
    as on a live bus) is ESC ``esc + s``; every other column is as ``hwfoc.read`` of the
    candump log of the same frames gives it."""

    def __init__(
        self,
        *,
        esc: int = 0,
        current_scale: float = ...,
        pole_pairs: int = ...,
        gear_ratio: float = ...,
        settings: Optional[Mapping[str, str]] = None,
    ) -> None: ...
    def feed(
        self,
        frames: Union[
            Iterable[Any],
            Tuple[float, int, Union[bytes, bytearray, memoryview, List[int]], bool],
            Any,
        ],
    ) -> pa.RecordBatch:
        """Decodes the next frames in the order received: an iterable of python-can
        ``Message`` objects (duck-typed: ``timestamp``, ``arbitration_id``, ``data``,
        ``is_extended_id``) or tuples ``(timestamp, arbitration_id, data, is_extended)``, or
        one of them. ``timestamp``: Unix seconds. Raises ValueError for a frame that is no
        classic CAN data frame. Returns the records of the ESC statuses completed; a Hobbywing
        node heard before its GetEscID answer has its records held (up to 1 s of the bus's
        clock) until the answer places it."""

    def finish(self) -> pa.RecordBatch:
        """Ends the bus's stream: the records still held, a node that never answered placed by
        its node id, as ``hwfoc decode -`` gives them."""

    @property
    def stats(self) -> Dict[str, Any]:
        """The bus's statistics, as :attr:`Decoder.stats`."""

    @property
    def schema(self) -> pa.Schema:
        """The schema of the batches."""

class Decoder:
    """A streaming decoder of one ESC's bytes as they arrive (a frame split between two
    ``feed`` calls is decoded whole), or of a DataLink hub's (told from the content, at
    ``baud=115200``): then channel ``c`` is ESC ``esc + c``."""

    def __init__(
        self,
        *,
        esc: int = 0,
        baud: Optional[int] = None,
        current_scale: float = ...,
        pole_pairs: int = ...,
        gear_ratio: float = ...,
        settings: Optional[Mapping[str, str]] = None,
        protocol: Optional[str] = None,
    ) -> None:
        """``esc``: the ``esc`` column of the records; ``baud``: the line's rate, for the time of
        each byte (by default that of ``protocol``, else 19200); ``protocol``: a name of
        :data:`PROTOCOLS` to decode that protocol only (None: every one, from the bytes).
        Raises ValueError for another name, for ``esc`` outside 0 to 255 or ``baud`` below 1;
        SettingsError for ``pole_pairs`` outside 1 to 65535."""

    def feed(
        self, data: Union[bytes, bytearray, memoryview], t: Optional[float] = None
    ) -> pa.RecordBatch:
        """Decodes the next bytes; ``t``: Unix time (s) the first was received (the others
        follow at the baud rate), or None for no ``t_s``. Returns the records of the data
        frames completed (``.to_pylist()`` gives dicts). Raises ValueError for ``t`` outside 0
        to 18446744073 (1970 to 2554); InputError when the first bytes fed are a candump log
        (decode its frames with :class:`CanDecoder`, or read the log with :func:`read`)."""

    def finish(self) -> pa.RecordBatch:
        """Ends the stream: records of frames still held (a frame cut off is dropped)."""

    @property
    def stats(self) -> Dict[str, Any]:
        """Link statistics: ``bytes``, ``frames``, ``info_frames``, then the link figures under
        the names of :func:`summary`'s ``link`` (``checksum_failures``, ``rejected_candidates``,
        ``lost_packets``, ``duplicate_packets``, ``restarts``, ``bytes_skipped``,
        ``delivery_ratio``: ``None`` where the format does not count one, as for HW5's packets
        or a checksum V3 and V4 do not have), and ``last_packet``. ``frames`` counts the data
        frames of every format the stream carried (the rows given); the other figures are of its
        current format."""

    @property
    def schema(self) -> pa.Schema:
        """The schema of the batches."""

def open_ports(
    ports: Sequence[str],
    *,
    baud: Optional[int] = None,
    current_scale: float = ...,
    pole_pairs: int = ...,
    gear_ratio: float = ...,
    settings: Optional[Mapping[str, str]] = None,
    protocol: Optional[str] = None,
) -> "Ports":
    """Opens serial ports (8N1) at ``baud`` (by default that of ``protocol``, else 19200), one
    ESC each in the order given, read as ``hwfoc monitor`` reads them: a reader thread per
    port, a port that is unplugged retried (a :class:`PortWarning` says so). ``protocol``: a
    name of :data:`PROTOCOLS` to read that protocol only (None: every one, from the bytes).
    Iterate for the records, as dicts with the schema's keys (``t_s`` is Unix time); Ctrl-C
    raises KeyboardInterrupt and closes the ports. Raises PortError; ValueError for an unknown
    ``protocol``."""

class Ports(Iterator[Dict[str, Any]]):
    """Live records of serial ports: see :func:`open_ports`. A context manager that closes
    the ports."""

    def __iter__(self) -> "Ports": ...
    def __next__(self) -> Dict[str, Any]: ...
    @property
    def ports(self) -> List[str]:
        """The ports, in the order given (the ``esc`` of their records)."""

    @property
    def stats(self) -> List[Dict[str, Any]]:
        """Each port's link statistics so far (as :attr:`Decoder.stats`)."""

    def close(self) -> None:
        """Stops reading and closes the ports; the iterator then gives the records the streams
        held (a CAN node's, awaiting its GetEscID answer) and ends."""

    def __enter__(self) -> "Ports": ...
    def __exit__(
        self,
        exc_type: Optional[type],
        exc: Optional[BaseException],
        tb: Optional[TracebackType],
    ) -> bool: ...

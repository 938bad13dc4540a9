"""Fleets of recordings on Dask: one partition per recording.

::

    import hwfoc.dask
    ddf = hwfoc.dask.read("fleet/*.pcapng", path_column="recording", frame_column="frame")
    per_esc = hwfoc.dask.esc_aggregates(ddf).compute()

Each partition is :func:`hwfoc.read` of one recording, as pandas (``table.to_pandas()``: the
schema's numeric dtypes, ``faults`` as ``pd.ArrowDtype(list<string>)``); the meta is the empty
table of the schema, so Dask knows the dtypes without reading anything.
"""

import glob as _glob
import os
from typing import Any, List, Optional, Sequence, Union

import pandas as pd
import pyarrow as pa

import hwfoc

__all__ = ["read", "esc_aggregates", "findings", "paths", "to_pandas", "add_columns"]


def paths(paths_or_glob: Union[str, "os.PathLike[str]", Sequence[Union[str, "os.PathLike[str]"]]]) -> List[str]:
    """The files of ``paths_or_glob``: a glob pattern (sorted matches; a path without
    wildcards is kept as it is, so that a missing file is reported by :func:`hwfoc.read`), or a
    list of paths kept in order. Raises :class:`hwfoc.InputError` if a pattern matches nothing."""
    if isinstance(paths_or_glob, (str, os.PathLike)):
        pattern = os.fspath(paths_or_glob)
        if _glob.has_magic(pattern):
            found = sorted(_glob.glob(pattern))
            if not found:
                raise hwfoc.InputError(f"{pattern}: no file matches")
            return found
        return [pattern]
    found = [os.fspath(p) for p in paths_or_glob]
    if not found:
        raise hwfoc.InputError("no recording given: the list is empty")
    return found


def _types(t: pa.DataType) -> Optional[Any]:
    # Lists stay Arrow-backed in pandas: Dask would otherwise take an object column of lists
    # for strings.
    return pd.ArrowDtype(t) if pa.types.is_list(t) else None


def add_columns(table: pa.Table, path: Optional[str], path_column: Optional[str], frame_column: Optional[str]) -> pa.Table:
    """``table`` with, where asked, a column naming its recording and a column numbering each
    ESC's data frames from 0 in order (the summary's frame index, which orders fault episodes
    in engines that do not keep row order)."""
    if frame_column is not None:
        esc = table.column("esc").to_numpy()
        frame = pd.Series(esc).groupby(esc).cumcount().to_numpy(dtype="uint64")
        table = table.append_column(pa.field(frame_column, pa.uint64(), nullable=False), pa.array(frame, pa.uint64()))
    if path_column is not None:
        table = table.append_column(
            pa.field(path_column, pa.string(), nullable=False),
            pa.array([path] * table.num_rows, pa.string()),
        )
    return table


def to_pandas(table: pa.Table) -> pd.DataFrame:
    """A table of records as pandas, with the dtypes of the Dask meta."""
    return table.to_pandas(types_mapper=_types)


def _partition(path: str, path_column: Optional[str], frame_column: Optional[str], options: dict) -> pd.DataFrame:
    table = hwfoc.read(path, **options)
    return to_pandas(add_columns(table, path, path_column, frame_column))


def read(
    paths_or_glob: Union[str, "os.PathLike[str]", Sequence[Union[str, "os.PathLike[str]"]]],
    *,
    path_column: Optional[str] = None,
    frame_column: Optional[str] = None,
    **options: Any,
) -> Any:
    """A Dask DataFrame of the records of recordings, one partition per file.

    ``paths_or_glob``: a glob pattern or a list of files (see :func:`paths`). ``path_column``:
    the name of a string column holding each record's file (ESC numbers restart at 0 in each
    recording, so a fleet's ESC is the pair of the two); ``frame_column``: the name of a
    ``uint64`` column numbering each ESC's data frames in its recording. ``options`` are
    :func:`hwfoc.read`'s (``esc``, ``start``, ``end``, the settings, ``protocol``). Errors surface when the
    partitions are computed, as the :class:`hwfoc.HwfocError` :func:`hwfoc.read` raises.
    """
    import dask.dataframe as dd

    files = paths(paths_or_glob)
    settings = {k: options[k] for k in ("current_scale", "pole_pairs", "gear_ratio", "settings") if k in options}
    empty = hwfoc.record_schema(**settings).empty_table()
    meta = to_pandas(add_columns(empty, None, path_column, frame_column))
    return dd.from_map(
        _partition,
        files,
        path_column=path_column,
        frame_column=frame_column,
        options=options,
        meta=meta,
        label="hwfoc-read",
        enforce_metadata=False,
    )


def _esc_aggregates(df: pd.DataFrame, by: List[str]) -> pd.DataFrame:
    """Per ESC of one recording (rows in order): rows, max MOSFET temperature, min voltage,
    fault episodes (runs of consecutive records of one ESC with a nonzero status)."""
    if df.empty:
        return _empty_aggregates(df, by)
    faulty = df["status"] != 0
    before = faulty.groupby(df["esc"]).shift(1, fill_value=False)
    starts = faulty & ~before
    g = df.assign(_start=starts).groupby(by, sort=True)
    out = g.agg(
        rows=("esc", "size"),
        max_mos_temp_c=("mos_temp_c", "max"),
        min_voltage_v=("voltage_v", "min"),
        fault_episodes=("_start", "sum"),
    )
    out["rows"] = out["rows"].astype("int64")
    out["fault_episodes"] = out["fault_episodes"].astype("int64")
    return out.reset_index()


def _empty_aggregates(df: pd.DataFrame, by: List[str]) -> pd.DataFrame:
    out = df[by].iloc[:0].copy()
    out["rows"] = pd.Series(dtype="int64")
    out["max_mos_temp_c"] = pd.Series(dtype="float32")
    out["min_voltage_v"] = pd.Series(dtype="float32")
    out["fault_episodes"] = pd.Series(dtype="int64")
    return out


def esc_aggregates(ddf: Any, path_column: str = "recording") -> Any:
    """Per ESC of a fleet (a :func:`read` with ``path_column``): ``rows``, ``max_mos_temp_c``,
    ``min_voltage_v`` and ``fault_episodes`` (as the summary counts them: runs of consecutive
    records of one ESC with a nonzero status). Computed partition by partition (a recording is
    one partition, its rows in order), so no shuffle is needed."""
    by = [path_column, "esc"]
    meta = _empty_aggregates(ddf._meta, by)
    return ddf.map_partitions(_esc_aggregates, by, meta=meta)


def _findings(path: str, path_column: str, options: dict) -> pd.DataFrame:
    table = hwfoc.check(path, **options)
    return to_pandas(add_columns(table, path, path_column, None))


def findings(
    paths_or_glob: Union[str, "os.PathLike[str]", Sequence[Union[str, "os.PathLike[str]"]]],
    *,
    path_column: str = "path",
    **options: Any,
) -> Any:
    """A Dask DataFrame of the findings of ``hwfoc check`` on each recording (one partition per
    file, each :func:`hwfoc.check` of it: the command's findings on that file), with the file
    in ``path_column``. ``options`` are :func:`hwfoc.check`'s (``config``, ``baseline``, the
    settings)."""
    import dask.dataframe as dd

    empty = hwfoc.FINDINGS_SCHEMA.empty_table()
    return dd.from_map(
        _findings,
        paths(paths_or_glob),
        path_column=path_column,
        options=options,
        meta=to_pandas(add_columns(empty, None, path_column, None)),
        label="hwfoc-check",
        enforce_metadata=False,
    )

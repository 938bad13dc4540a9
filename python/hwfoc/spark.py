"""Fleets of recordings on Spark: the list of files is a DataFrame of paths, and
``mapInArrow`` turns each into its records on the executors (which must have ``hwfoc``
installed).

::

    import hwfoc.spark
    df = hwfoc.spark.read(spark, paths, path_column="recording", frame_column="frame")
    hwfoc.spark.esc_aggregates(df).show()

Spark has no unsigned integers: ``esc`` (uint8) becomes ``short``, ``status`` (uint16)
``int``, ``packet`` and ``erpm`` (uint32) and the frame column (uint64) ``long``; every value
fits. Nor has it dictionaries: ``protocol`` (a dictionary of strings) becomes ``string``.
Floats, nulls and the ``faults`` list are kept; each field's unit is in its metadata.
"""

import os
from typing import Any, Iterator, List, Optional, Sequence, Union

import pyarrow as pa

import hwfoc
from hwfoc.dask import add_columns, paths as _paths

__all__ = ["read", "arrow_schema", "spark_schema", "esc_aggregates", "findings"]

_WIDER = {
    pa.uint8(): pa.int16(),
    pa.uint16(): pa.int32(),
    pa.uint32(): pa.int64(),
    pa.uint64(): pa.int64(),
}


def _spark_type(t: pa.DataType) -> pa.DataType:
    """An Arrow type as Spark takes it: a dictionary as its values, unsigned integers wider."""
    if pa.types.is_dictionary(t):
        t = t.value_type
    return _WIDER.get(t, t)


def arrow_schema(path_column: Optional[str] = None, frame_column: Optional[str] = None, **settings: Any) -> pa.Schema:
    """The record schema as Spark takes it from Arrow: unsigned integers widened to signed."""
    empty = add_columns(hwfoc.record_schema(**settings).empty_table(), None, path_column, frame_column)
    fields = [f.with_type(_spark_type(f.type)) for f in empty.schema]
    return pa.schema(fields, metadata=empty.schema.metadata)


def spark_schema(path_column: Optional[str] = None, frame_column: Optional[str] = None, **settings: Any) -> Any:
    """The Spark ``StructType`` of :func:`read`'s DataFrame (units in the fields' metadata)."""
    from pyspark.sql import types as T

    simple = {
        pa.float64(): T.DoubleType(),
        pa.float32(): T.FloatType(),
        pa.int16(): T.ShortType(),
        pa.int32(): T.IntegerType(),
        pa.int64(): T.LongType(),
        pa.string(): T.StringType(),
    }
    fields = []
    for f in arrow_schema(path_column, frame_column, **settings):
        if pa.types.is_list(f.type):
            spark_type = T.ArrayType(T.StringType(), containsNull=False)
        elif pa.types.is_timestamp(f.type):
            # `time`: a UTC instant, which Spark's TimestampType is (shown in the session's zone).
            spark_type = T.TimestampType()
        else:
            spark_type = simple[f.type]
        metadata = {k.decode(): v.decode() for k, v in (f.metadata or {}).items()}
        fields.append(T.StructField(f.name, spark_type, f.nullable, metadata))
    return T.StructType(fields)


def _records(batches: Iterator[pa.RecordBatch], column: str, name_column: str, path_column: Optional[str], frame_column: Optional[str], options: dict) -> Iterator[pa.RecordBatch]:
    schema = arrow_schema(path_column, frame_column, **_settings(options))
    for batch in batches:
        for path, name in zip(batch.column(column).to_pylist(), batch.column(name_column).to_pylist()):
            table = add_columns(hwfoc.read(path, **options), name, path_column, frame_column)
            for b in table.cast(schema).to_batches(max_chunksize=1 << 16):
                yield b


def _settings(options: dict) -> dict:
    return {k: options[k] for k in ("current_scale", "pole_pairs", "gear_ratio", "settings") if k in options}


def read(
    spark: Any,
    paths_or_glob: Union[str, "os.PathLike[str]", Sequence[Union[str, "os.PathLike[str]"]]],
    *,
    path_column: Optional[str] = None,
    frame_column: Optional[str] = None,
    **options: Any,
) -> Any:
    """A Spark DataFrame of the records of recordings, one partition per file (a glob pattern
    is expanded on the driver, see :func:`hwfoc.dask.paths`). ``path_column``,
    ``frame_column`` and ``options`` as :func:`hwfoc.dask.read`. Errors surface when an action
    runs, as the Python worker's :class:`hwfoc.HwfocError` with the command's message.
    The workers read each file by its absolute path (they may run elsewhere than the
    driver's working directory); ``path_column`` names it as given, as :func:`hwfoc.dask.read`
    does."""
    names: List[str] = _paths(paths_or_glob)
    column, name_column = "_hwfoc_path", "_hwfoc_name"
    listing = spark.createDataFrame(
        [(os.path.abspath(p), p) for p in names], f"{column} string, {name_column} string"
    ).repartition(len(names), column)
    schema = spark_schema(path_column, frame_column, **_settings(options))

    def records(batches: Iterator[pa.RecordBatch]) -> Iterator[pa.RecordBatch]:
        return _records(batches, column, name_column, path_column, frame_column, options)

    return listing.mapInArrow(records, schema)


def esc_aggregates(df: Any, path_column: str = "recording", frame_column: str = "frame") -> Any:
    """Per ESC of a fleet (a :func:`read` with ``path_column`` and ``frame_column``):
    ``rows``, ``max_mos_temp_c``, ``min_voltage_v`` and ``fault_episodes`` (runs of
    consecutive records of one ESC with a nonzero status, ordered by the frame column)."""
    from pyspark.sql import Window
    from pyspark.sql import functions as F

    by = [path_column, "esc"]
    order = Window.partitionBy(*by).orderBy(frame_column)
    faulty = F.col("status") != 0
    before = F.coalesce(F.lag("status").over(order) != 0, F.lit(False))
    starts = df.withColumn("_start", (faulty & ~before).cast("long"))
    return starts.groupBy(*by).agg(
        F.count(F.lit(1)).alias("rows"),
        F.max("mos_temp_c").alias("max_mos_temp_c"),
        F.min("voltage_v").alias("min_voltage_v"),
        F.sum("_start").alias("fault_episodes"),
    )


def findings(
    spark: Any,
    paths_or_glob: Union[str, "os.PathLike[str]", Sequence[Union[str, "os.PathLike[str]"]]],
    *,
    path_column: str = "path",
    **options: Any,
) -> Any:
    """A Spark DataFrame of the findings of ``hwfoc check`` on each recording (one partition
    per file, each :func:`hwfoc.check` of it on an executor), with the file as given in
    ``path_column``; ``options`` as :func:`hwfoc.check`'s. Columns: those of
    :data:`hwfoc.FINDINGS_SCHEMA` (``values`` an array of structs)."""
    names: List[str] = _paths(paths_or_glob)
    column, name_column = "_hwfoc_path", "_hwfoc_name"
    listing = spark.createDataFrame(
        [(os.path.abspath(p), p) for p in names], f"{column} string, {name_column} string"
    ).repartition(len(names), column)
    schema = add_columns(hwfoc.FINDINGS_SCHEMA.empty_table(), "", path_column, None).schema

    def check(batches: Iterator[pa.RecordBatch]) -> Iterator[pa.RecordBatch]:
        for batch in batches:
            for path, name in zip(batch.column(column).to_pylist(), batch.column(name_column).to_pylist()):
                table = add_columns(hwfoc.check(path, **options), name, path_column, None)
                yield from table.cast(schema).to_batches()

    from pyspark.sql.pandas.types import from_arrow_schema

    return listing.mapInArrow(check, from_arrow_schema(schema))

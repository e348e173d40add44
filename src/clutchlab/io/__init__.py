"""File input and output: every format clutchlab reads or writes lives here."""

from .files import atomic_write_text, atomic_write_bytes, atomic_to_csv, check_writable, read_table
from .channels import ChannelMap, ChannelSpec, canonical_unit, unit_conversion
from .dialect import CsvDialect, read_csv
from .mdf import BusDatabase
from .measurements import Measurement, MeasurementSource, ChannelOrigin, read_measurement, resample, write_measurement

__all__ = ["atomic_write_text", "atomic_write_bytes", "atomic_to_csv", "check_writable", "read_table",
           "ChannelMap", "ChannelSpec", "canonical_unit", "unit_conversion", "CsvDialect", "read_csv", "BusDatabase",
           "Measurement", "MeasurementSource", "ChannelOrigin", "read_measurement", "write_measurement", "resample"]

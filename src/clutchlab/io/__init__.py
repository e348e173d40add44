"""File input and output: every format clutchlab reads or writes lives here."""

from .files import atomic_write_text, atomic_write_bytes, atomic_to_csv, check_writable, read_table

__all__ = ["atomic_write_text", "atomic_write_bytes", "atomic_to_csv", "check_writable", "read_table"]

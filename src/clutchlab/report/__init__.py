"""Self-contained HTML reports (figures embedded, tables, parameters, provenance)."""

from .html import Figure, Table, Text, Section, check_report_folder, write_report

__all__ = ["Figure", "Table", "Text", "Section", "write_report", "check_report_folder"]

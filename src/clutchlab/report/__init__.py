"""Self-contained HTML reports (figures embedded, tables, parameters, provenance)."""

from .html import Figure, Table, Text, Section, write_report

__all__ = ["Figure", "Table", "Text", "Section", "write_report"]

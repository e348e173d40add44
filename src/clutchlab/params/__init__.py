"""Parameter sets: frozen, validated, unit-annotated dataclasses."""

from .base import ParameterSet, quantity, load_toml

__all__ = ["ParameterSet", "quantity", "load_toml"]

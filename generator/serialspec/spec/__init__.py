"""The spec language: loading YAML with positions, validating, resolving into the immutable model."""

from serialspec.spec.errors import SpecError, SpecErrors
from serialspec.spec.resolve import load_protocol

__all__ = ["SpecError", "SpecErrors", "load_protocol"]

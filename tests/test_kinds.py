"""Every field kind of the model has its behaviour registered with each target that asks kinds instead of switching."""

from typing import get_args

from serialspec.emit.python.kinds import KINDS
from serialspec.spec.model import Field


def test_every_model_field_kind_is_registered_with_the_python_target() -> None:
    assert set(KINDS) == set(get_args(Field))

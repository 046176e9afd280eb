"""Every field kind of the model has its behaviour registered with each target that asks kinds instead of switching."""

from typing import get_args

import pytest
from serialspec.backends.common.kinds import Registry
from serialspec.backends.markdown import kinds as markdown_kinds
from serialspec.backends.python import kinds as python_kinds
from serialspec.lang.model import Field, Scalar


@pytest.mark.parametrize("registry", [python_kinds.kind, markdown_kinds.kind], ids=["python", "markdown"])
def test_every_model_field_kind_is_registered(registry: Registry[object]) -> None:
    assert set(registry.by_model) == set(get_args(Field))


def test_a_target_missing_a_field_kind_is_refused_naming_it() -> None:
    class Base:
        pass

    class OnlyScalars(Base):
        model = Scalar

    with pytest.raises(AssertionError, match="no behaviour for .*'Array'"):
        Registry(Base)

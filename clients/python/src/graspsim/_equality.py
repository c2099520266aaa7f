"""== for the dataclasses that hold numpy arrays: a dataclass's own __eq__ compares its fields as tuples, which asks
numpy for the truth of an element-wise comparison and raises. "Is the scene unchanged?" must be a plain ==."""
from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np


def same_values(a: Any, b: Any) -> bool:
    """Equal field by field through dataclasses, lists and tuples; arrays by shape and elements."""
    if dataclasses.is_dataclass(a) and not isinstance(a, type):
        return type(a) is type(b) and all(same_values(getattr(a, f.name), getattr(b, f.name))
                                          for f in dataclasses.fields(a))
    if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
        return isinstance(a, np.ndarray) and isinstance(b, np.ndarray) and bool(np.array_equal(a, b))
    if isinstance(a, (list, tuple)):
        return type(a) is type(b) and len(a) == len(b) and all(same_values(x, y) for x, y in zip(a, b))
    return bool(a == b)


class ValueEquality:
    """Mixin of a @dataclass(eq=False): == compares the values of every field, arrays element by element. Defining
    __eq__ makes Python set __hash__ to None: such objects are not hashable, as the arrays they hold are not."""

    def __eq__(self, other: object) -> bool:
        return same_values(self, other)

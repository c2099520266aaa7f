"""Where the API expects a scene id, the object that carries it is accepted too (the SceneSummary create_scene
returns, a Scene from get_scene, a Replay, a RecordingInfo); anything else is a TypeError naming the parameter,
not an error from deep inside protobuf."""
from __future__ import annotations

import functools
import inspect
from typing import Any, Callable, Sequence, Union

# What names a scene: its id, or an object that carries it.
SceneLike = Union[str, Any]

# The parameters of Client methods that name a scene.
SCENE_PARAMETERS = ("scene_id", "add_to_scene_id", "scene")


def scene_id_of(scene: SceneLike, parameter: str = "scene") -> str:
    """The scene id of a str, or of an object with .scene_id (Replay, RecordingInfo), .id (SceneSummary) or
    .summary.id (Scene)."""
    if isinstance(scene, str):
        return scene
    for value in (getattr(scene, "scene_id", None), getattr(scene, "id", None),
                  getattr(getattr(scene, "summary", None), "id", None)):
        if isinstance(value, str):
            return value
    raise TypeError(f"{parameter}: a scene id (str) or an object carrying one (.scene_id, .id, .summary.id) "
                    f"is expected, got {type(scene).__name__}")


def accept_scene_objects(cls: type) -> type:
    """Wraps every public method of `cls` with a scene parameter so that it takes a scene object as well (None
    stays None where the method allows it)."""
    for name, method in inspect.getmembers(cls, inspect.isfunction):
        if name.startswith("_"):
            continue
        signature = inspect.signature(method)
        names = [p for p in SCENE_PARAMETERS if p in signature.parameters]
        if names:
            setattr(cls, name, _converting(method, signature, names))
    return cls


def _converting(method: Callable[..., Any], signature: inspect.Signature, names: Sequence[str]) -> Callable[..., Any]:
    @functools.wraps(method)
    def wrapper(*args: Any, **kwargs: Any) -> Any:
        bound = signature.bind(*args, **kwargs)
        for name in names:
            value = bound.arguments.get(name)
            if value is not None and not isinstance(value, str):
                bound.arguments[name] = scene_id_of(value, name)
        return method(*bound.args, **bound.kwargs)
    return wrapper

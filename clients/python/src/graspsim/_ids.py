"""Where the API expects the id of a scene or of a body, the object that carries it is accepted too, so that a reply
is passed on as it came: a SceneSummary (create_scene, import_scene, list_scenes), a Scene (get_scene), a Replay or
RecordingInfo (their .scene_id) for a scene; a Body (add_object, get_scene's bodies) for a body. Anything else is a
TypeError naming the parameter, not an error from deep inside protobuf. A Body is no scene (and a scene no body),
although both carry an .id: the types say which id is which."""
from __future__ import annotations

from typing import Protocol, Union

from graspsim._body import Body
from graspsim._scene import Scene, SceneSummary
from graspsim.v1 import common_pb2, scene_pb2


class CarriesSceneId(Protocol):
    """An object naming its scene by .scene_id: Replay, RecordingInfo."""

    @property
    def scene_id(self) -> str: ...


# What names a scene: its id, or an object that carries it.
SceneLike = Union[str, SceneSummary, Scene, CarriesSceneId]
# What names a body: its id, or the Body itself.
BodyLike = Union[str, Body]


def scene_id_of(scene: SceneLike, parameter: str = "scene_id") -> str:
    """The scene id of a str, a SceneSummary, a Scene or an object with .scene_id; TypeError naming `parameter`
    otherwise. The generated SceneSummary and Scene messages (of the raw stubs) are taken as well."""
    if isinstance(scene, str):
        return scene
    if isinstance(scene, (SceneSummary, scene_pb2.SceneSummary)):
        return scene.id
    if isinstance(scene, (Scene, scene_pb2.Scene)):
        return scene.summary.id
    value = getattr(scene, "scene_id", None)
    if isinstance(value, str):
        return value
    raise TypeError(f"{parameter}: a scene id (str) or an object carrying one (SceneSummary, Scene, Replay, "
                    f"RecordingInfo) is expected, got {type(scene).__name__}")


def body_id_of(body: BodyLike, parameter: str = "body_id") -> str:
    """The body id of a str or a Body (or the generated Body message); TypeError naming `parameter` otherwise."""
    if isinstance(body, str):
        return body
    if isinstance(body, (Body, common_pb2.Body)):
        return body.id
    raise TypeError(f"{parameter}: a body id (str) or a Body is expected, got {type(body).__name__}")

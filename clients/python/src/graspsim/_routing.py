"""The graspsim-scene-id metadata header: a fleet's load balancer routes every call of a scene to the replica
that holds it by this header (docs/scaling.md). The client sets it on every call whose request names a scene."""
from __future__ import annotations

import itertools
from typing import TYPE_CHECKING, Any, Callable, Dict, Iterable, Iterator, Optional, Tuple

import grpc
from google.protobuf.descriptor import Descriptor, FieldDescriptor
from google.protobuf.message import Message

if TYPE_CHECKING:
    # grpc-stubs makes the interceptor classes generic (request, response); grpc's own classes are not subscriptable
    # at run time, hence the aliases. Requests and responses are Any: the generated stubs are untyped.
    UnaryUnaryInterceptor = grpc.UnaryUnaryClientInterceptor[Any, Any]
    UnaryStreamInterceptor = grpc.UnaryStreamClientInterceptor[Any, Any]
    StreamUnaryInterceptor = grpc.StreamUnaryClientInterceptor[Any, Any]
    StreamStreamInterceptor = grpc.StreamStreamClientInterceptor[Any, Any]
else:
    UnaryUnaryInterceptor = grpc.UnaryUnaryClientInterceptor
    UnaryStreamInterceptor = grpc.UnaryStreamClientInterceptor
    StreamUnaryInterceptor = grpc.StreamUnaryClientInterceptor
    StreamStreamInterceptor = grpc.StreamStreamClientInterceptor

# continuation(details, request or request iterator) of an interceptor: the call (a future or a response iterator)
Continuation = Callable[[grpc.ClientCallDetails, Any], Any]

SCENE_HEADER = "graspsim-scene-id"
_SCENE_FIELDS = ("scene_id", "add_to_scene_id")

# message full name -> where its scene id is: a tuple of field names, e.g. ("object", "scene_id"); () = nowhere.
_paths: Dict[str, Tuple[str, ...]] = {}


def _find_path(descriptor: Descriptor, depth: int = 0) -> Tuple[str, ...]:
    for name in _SCENE_FIELDS:
        field = descriptor.fields_by_name.get(name)
        if field is not None and field.type == FieldDescriptor.TYPE_STRING and field.label != FieldDescriptor.LABEL_REPEATED:
            return (name,)
    if depth < 2:  # GraspTarget in PlanGraspsRequest.object, PlanArmPathsRequest.problems[0].scene_id
        for field in descriptor.fields:
            if field.message_type is not None and not field.message_type.GetOptions().map_entry:
                inner = _find_path(field.message_type, depth + 1)
                if inner:
                    return (field.name, *inner)
    return ()


def scene_id_of(request: Message) -> Optional[str]:
    """The scene a request is about ("" fields skipped): its scene_id or add_to_scene_id, or that of a nested
    message (the first element of a repeated one: a PlanArmPaths call goes where its first problem's scene is)."""
    name = request.DESCRIPTOR.full_name
    path = _paths.get(name)
    if path is None:
        path = _paths[name] = _find_path(request.DESCRIPTOR)
    value = request
    for field in path:
        value = getattr(value, field)
        if isinstance(value, str):
            return value or None
        if not isinstance(value, Message):  # a repeated field: its first element
            if len(value) == 0:
                return None
            value = value[0]
    return None


class CallDetails(grpc.ClientCallDetails):
    def __init__(self, method: str, timeout: Optional[float], metadata: Any,
                 credentials: Optional[grpc.CallCredentials], wait_for_ready: Optional[bool],
                 compression: Optional[grpc.Compression]) -> None:
        self.method, self.timeout, self.metadata = method, timeout, metadata
        self.credentials, self.wait_for_ready, self.compression = credentials, wait_for_ready, compression


class SceneRouting(UnaryUnaryInterceptor, UnaryStreamInterceptor, StreamUnaryInterceptor, StreamStreamInterceptor):
    """Adds "graspsim-scene-id: <id>" to each call whose (first) request names a scene."""

    @staticmethod
    def _details(details: grpc.ClientCallDetails, request: object) -> grpc.ClientCallDetails:
        scene_id = scene_id_of(request) if isinstance(request, Message) else None
        if not scene_id:
            return details
        metadata = tuple(details.metadata or ()) + ((SCENE_HEADER, scene_id),)
        fields: Dict[str, Any] = {name: getattr(details, name, None) for name in
                  ("method", "timeout", "credentials", "wait_for_ready", "compression")}
        return CallDetails(metadata=metadata, **fields)

    def intercept_unary_unary(self, continuation: Continuation, details: grpc.ClientCallDetails, request: Any) -> Any:
        return continuation(self._details(details, request), request)

    def intercept_unary_stream(self, continuation: Continuation, details: grpc.ClientCallDetails, request: Any) -> Any:
        return continuation(self._details(details, request), request)

    def intercept_stream_unary(self, continuation: Continuation, details: grpc.ClientCallDetails,
                               requests: Iterator[Any]) -> Any:
        first, requests = _peek(requests)
        return continuation(self._details(details, first), requests)

    def intercept_stream_stream(self, continuation: Continuation, details: grpc.ClientCallDetails,
                                requests: Iterator[Any]) -> Any:
        first, requests = _peek(requests)
        return continuation(self._details(details, first), requests)


def _peek(requests: Iterable[Any]) -> Tuple[Optional[Message], Iterator[Any]]:
    """The first message of a request stream (read ahead, then given back in front)."""
    iterator = iter(requests)
    first = next(iterator, None)
    return first, (iterator if first is None else itertools.chain((first,), iterator))

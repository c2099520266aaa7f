"""Credentials of a connection (TLS, bearer token) and the AuthService methods of Client (docs/security.md)."""
from __future__ import annotations

import os
from dataclasses import dataclass
from typing import Any, Dict, Iterator, Optional, Sequence, Tuple, Union

import grpc
from google.protobuf.message import Message

from graspsim._errors import translated_errors
from graspsim._ids import SceneLike, scene_id_of
from graspsim._routing import (CallDetails, Continuation, SceneRouting, StreamStreamInterceptor, StreamUnaryInterceptor,
                               UnaryStreamInterceptor, UnaryUnaryInterceptor)
from graspsim.v1 import auth_pb2, auth_pb2_grpc

PemLike = Union[bytes, str, "os.PathLike[str]", None]


def _pem(value: PemLike) -> Optional[bytes]:
    """PEM bytes as given, or read from a file path."""
    if value is None or isinstance(value, bytes):
        return value
    with open(value, "rb") as f:
        return f.read()


class _BearerToken(UnaryUnaryInterceptor, UnaryStreamInterceptor, StreamUnaryInterceptor, StreamStreamInterceptor):
    """Adds "authorization: Bearer <token>" to every call. An interceptor rather than call credentials, so that
    a token also reaches a plaintext loopback server (gRPC sends call credentials over TLS only)."""

    def __init__(self, token: str) -> None:
        self._metadata = (("authorization", f"Bearer {token}"),)

    def _details(self, details: grpc.ClientCallDetails) -> grpc.ClientCallDetails:
        metadata = tuple(details.metadata or ()) + self._metadata
        fields: Dict[str, Any] = {name: getattr(details, name, None) for name in
                  ("method", "timeout", "credentials", "wait_for_ready", "compression")}
        return CallDetails(metadata=metadata, **fields)

    def intercept_unary_unary(self, continuation: Continuation, details: grpc.ClientCallDetails, request: Any) -> Any:
        return continuation(self._details(details), request)

    def intercept_unary_stream(self, continuation: Continuation, details: grpc.ClientCallDetails, request: Any) -> Any:
        return continuation(self._details(details), request)

    def intercept_stream_unary(self, continuation: Continuation, details: grpc.ClientCallDetails,
                               requests: Iterator[Any]) -> Any:
        return continuation(self._details(details), requests)

    def intercept_stream_stream(self, continuation: Continuation, details: grpc.ClientCallDetails,
                                requests: Iterator[Any]) -> Any:
        return continuation(self._details(details), requests)


def open_channel(target: str, options: Sequence[Tuple[str, Any]], *, token: Optional[str] = None, tls: bool = False,
                 root_certificates: PemLike = None, private_key: PemLike = None,
                 certificate_chain: PemLike = None) -> grpc.Channel:
    """A channel to target: TLS when tls is true or any certificate is given (root_certificates: the CA that
    signed the server's certificate, default the system's; private_key + certificate_chain: a client
    certificate), plaintext otherwise; with a bearer token on every call when token is given, and the
    graspsim-scene-id header on every call of a scene (a fleet routes by it, docs/scaling.md)."""
    if tls or root_certificates is not None or certificate_chain is not None:
        credentials = grpc.ssl_channel_credentials(_pem(root_certificates), _pem(private_key), _pem(certificate_chain))
        channel = grpc.secure_channel(target, credentials, options=options)
    else:
        channel = grpc.insecure_channel(target, options=options)
    interceptors = [SceneRouting()] + ([_BearerToken(token)] if token else [])
    return grpc.intercept_channel(channel, *interceptors)


@dataclass(frozen=True)
class Identity:
    """whoami's reply: the caller's token name and role (viewer, scripter, gateway or admin); both "" when the
    server checks no tokens."""

    name: str
    role: str


class AuthMethods:
    """AuthService: who the caller is, tokens and device grants (admin), sharing a scene (its owner)."""

    channel: grpc.Channel  # set by Client
    call_timeout: float

    def _auth(self, method: str, request: Message) -> Any:
        with translated_errors():
            stub = auth_pb2_grpc.AuthServiceStub(self.channel)
            return getattr(stub, method)(request, timeout=self.call_timeout)

    def whoami(self) -> Identity:
        """The caller's token name and role (both empty when the server checks no tokens)."""
        response = self._auth("WhoAmI", auth_pb2.WhoAmIRequest())
        return Identity(response.name, response.role)

    def add_token(self, role: str, name: str, token: str) -> None:
        """Adds a token (admin): role viewer, scripter, gateway or admin; token the secret (>= 16 characters)."""
        self._auth("AddToken", auth_pb2.AddTokenRequest(role=role, name=name, token=token))

    def revoke_token(self, name: str) -> None:
        """Revokes the token of that name (admin); its calls are UNAUTHENTICATED from then on."""
        self._auth("RevokeToken", auth_pb2.RevokeTokenRequest(name=name))

    def grant_device(self, device_id: str, name: str) -> None:
        """Lets the token `name` send commands to the device (admin)."""
        self._auth("GrantDevice", auth_pb2.GrantDeviceRequest(device_id=device_id, name=name))

    def share_scene(self, scene_id: SceneLike, name: str) -> None:
        """Lets the token `name` read the scene (its owner or an admin)."""
        self._auth("ShareScene", auth_pb2.ShareSceneRequest(scene_id=scene_id_of(scene_id), name=name))

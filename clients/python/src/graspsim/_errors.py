"""The one exception type of the client: every failed RPC becomes a GraspsimError."""
from __future__ import annotations

import contextlib
from typing import Iterator

import grpc


class GraspsimError(Exception):
    """A request the server refused or could not serve.

    Attributes:
        code: the gRPC status code (e.g. grpc.StatusCode.INVALID_ARGUMENT).
        message: the server's explanation, naming the offending field and value.
    """

    def __init__(self, code: grpc.StatusCode, message: str):
        super().__init__(code, message)
        self.code = code
        self.message = message

    def __str__(self) -> str:
        return f"{self.code.name}: {self.message}"


def from_rpc_error(err: grpc.RpcError) -> GraspsimError:
    """Converts a failed gRPC call (a grpc.RpcError that is also a grpc.Call) into a GraspsimError."""
    code = err.code() if hasattr(err, "code") else grpc.StatusCode.UNKNOWN
    details = err.details() if hasattr(err, "details") else str(err)
    return GraspsimError(code, details or "")


def error_for_code(code: int, message: str) -> GraspsimError:
    """A GraspsimError from a numeric status code carried in a message (PlanArmPaths' per-problem results)."""
    by_value = {c.value[0]: c for c in grpc.StatusCode}
    return GraspsimError(by_value.get(code, grpc.StatusCode.UNKNOWN), message)


@contextlib.contextmanager
def translated_errors() -> Iterator[None]:
    """Re-raises any grpc.RpcError raised in the block as a GraspsimError."""
    try:
        yield
    except grpc.RpcError as err:
        raise from_rpc_error(err) from None

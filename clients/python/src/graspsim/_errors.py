"""The client's exceptions: every failed RPC becomes a GraspsimError, of the subclass of its status (NotFound,
InvalidArgument, ...), so a caller catches what it can handle and still catches everything as GraspsimError."""
from __future__ import annotations

import contextlib
from typing import ClassVar, Iterator

import grpc


class GraspsimError(Exception):
    """A request the server refused or could not serve.

    Attributes:
        code: the gRPC status code (e.g. grpc.StatusCode.INVALID_ARGUMENT).
        message: the server's explanation, naming the offending field and value.
    """

    status: ClassVar[grpc.StatusCode]  # each subclass's own code (GraspsimError itself has none)

    def __init__(self, code: grpc.StatusCode, message: str):
        super().__init__(code, message)
        self.code = code
        self.message = message

    def __str__(self) -> str:
        return f"{self.code.name}: {self.message}"

    @staticmethod
    def for_code(code: grpc.StatusCode, message: str) -> "GraspsimError":
        """The error of a status: an instance of its subclass (GraspsimError itself for a code without one)."""
        return _BY_CODE.get(code, GraspsimError)(code, message)


class Cancelled(GraspsimError):
    """CANCELLED: the call was cancelled (by the client, or a stream the server ended)."""
    status = grpc.StatusCode.CANCELLED


class InvalidArgument(GraspsimError):
    """INVALID_ARGUMENT: the request is wrong: the message names the field and the value."""
    status = grpc.StatusCode.INVALID_ARGUMENT


class DeadlineExceeded(GraspsimError):
    """DEADLINE_EXCEEDED: no answer within the call's deadline."""
    status = grpc.StatusCode.DEADLINE_EXCEEDED


class NotFound(GraspsimError):
    """NOT_FOUND: a scene, body, joint, sensor, device, grasp set or recording that does not exist."""
    status = grpc.StatusCode.NOT_FOUND


class AlreadyExists(GraspsimError):
    """ALREADY_EXISTS: a name already taken."""
    status = grpc.StatusCode.ALREADY_EXISTS


class PermissionDenied(GraspsimError):
    """PERMISSION_DENIED: the token's role or the scene's sharing does not allow the call."""
    status = grpc.StatusCode.PERMISSION_DENIED


class ResourceExhausted(GraspsimError):
    """RESOURCE_EXHAUSTED: a server limit (scenes, bodies, upload size, points ...) would be passed."""
    status = grpc.StatusCode.RESOURCE_EXHAUSTED


class FailedPrecondition(GraspsimError):
    """FAILED_PRECONDITION: the scene is not in a state the call needs."""
    status = grpc.StatusCode.FAILED_PRECONDITION


class Aborted(GraspsimError):
    """ABORTED: the call was aborted by a conflict."""
    status = grpc.StatusCode.ABORTED


class OutOfRange(GraspsimError):
    """OUT_OF_RANGE: a value beyond its range."""
    status = grpc.StatusCode.OUT_OF_RANGE


class Unimplemented(GraspsimError):
    """UNIMPLEMENTED: a method not built (yet)."""
    status = grpc.StatusCode.UNIMPLEMENTED


class Internal(GraspsimError):
    """INTERNAL: a server fault: please report it with the message."""
    status = grpc.StatusCode.INTERNAL


class Unavailable(GraspsimError):
    """UNAVAILABLE: no server (or gateway) reachable."""
    status = grpc.StatusCode.UNAVAILABLE


class DataLoss(GraspsimError):
    """DATA_LOSS: data lost or corrupted on the way."""
    status = grpc.StatusCode.DATA_LOSS


class Unauthenticated(GraspsimError):
    """UNAUTHENTICATED: no valid token."""
    status = grpc.StatusCode.UNAUTHENTICATED


# The subclass of each status code, for GraspsimError.for_code.
_BY_CODE = {cls.status: cls for cls in GraspsimError.__subclasses__()}
STATUS_ERRORS = tuple(GraspsimError.__subclasses__())


def from_rpc_error(err: grpc.RpcError) -> GraspsimError:
    """Converts a failed gRPC call (a grpc.RpcError that is also a grpc.Call) into a GraspsimError."""
    code = err.code() if hasattr(err, "code") else grpc.StatusCode.UNKNOWN
    details = err.details() if hasattr(err, "details") else str(err)
    return GraspsimError.for_code(code, details or "")


def error_for_code(code: int, message: str) -> GraspsimError:
    """A GraspsimError from a numeric status code carried in a message (PlanArmPaths' per-problem results)."""
    by_value = {c.value[0]: c for c in grpc.StatusCode}
    return GraspsimError.for_code(by_value.get(code, grpc.StatusCode.UNKNOWN), message)


@contextlib.contextmanager
def translated_errors() -> Iterator[None]:
    """Re-raises any grpc.RpcError raised in the block as a GraspsimError."""
    try:
        yield
    except grpc.RpcError as err:
        raise from_rpc_error(err) from None

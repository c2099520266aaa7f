"""Server streams that end on the server as soon as the client stops reading: server_stream() for the calls that
read a stream to its end, CancellableStream (SceneWatch, SensorStream, pick_and_place_stream) for the ones that
hand it to the caller."""
from __future__ import annotations

import contextlib
from typing import Any, Callable, Generic, Iterator, Protocol, TypeVar

import grpc

from graspsim._errors import from_rpc_error, translated_errors

T = TypeVar("T")


class StreamCall(Protocol):
    """What a server-streaming stub call returns (grpc's rendezvous): an iterator of the response messages that is
    also the call, cancellable. The generated stubs are untyped, so the messages are Any here."""

    def __iter__(self) -> Iterator[Any]: ...

    def __next__(self) -> Any: ...

    def cancel(self) -> bool: ...


@contextlib.contextmanager
def server_stream(call: StreamCall) -> Iterator[StreamCall]:
    """The block that reads `call`: its gRPC errors are raised as GraspsimError, and however the block is left (the
    stream's end, a return, any exception: a callback's, KeyboardInterrupt, GeneratorExit) the call is cancelled.
    Cancelling an ended call does nothing; otherwise the server stops the work nobody reads any more at once,
    rather than when the call object is garbage-collected (never, while a traceback holds this frame)."""
    try:
        with translated_errors():
            yield call
    finally:
        call.cancel()


class CancellableStream(Generic[T]):
    """Iterator over a server-streaming call, each message converted by `convert`; cancel() (or close(), or
    leaving a with-block) ends it.

    Iteration blocks until the next message; after cancel() it stops cleanly (StopIteration). Server errors are
    raised as GraspsimError.
    """

    def __init__(self, call: StreamCall, convert: Callable[[Any], T]) -> None:
        self._call = call
        self._convert = convert
        self._cancelled = False

    def __iter__(self) -> Iterator[T]:
        return self

    def __next__(self) -> T:
        try:
            return self._convert(next(self._call))
        except grpc.RpcError as err:
            if self._cancelled and err.code() == grpc.StatusCode.CANCELLED:
                raise StopIteration from None
            raise from_rpc_error(err) from None

    def cancel(self) -> None:
        """Ends the stream; safe to call from another thread and more than once."""
        self._cancelled = True
        self._call.cancel()

    close = cancel

    def __enter__(self) -> CancellableStream[T]:
        return self

    def __exit__(self, *exc: object) -> None:
        self.cancel()

    def __del__(self) -> None:
        # A stream dropped unfinished (a loop left by break or an exception, outside a with-block) ends on the
        # server too, even while someone still holds the underlying call.
        self.cancel()

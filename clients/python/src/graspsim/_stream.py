"""A server stream as a cancellable iterator: the shape of SceneWatch and SensorStream."""
from __future__ import annotations

from typing import Callable, Generic, Iterator, TypeVar

import grpc

from graspsim._errors import from_rpc_error

T = TypeVar("T")


class CancellableStream(Generic[T]):
    """Iterator over a server-streaming call, each message converted by `convert`; cancel() (or close(), or
    leaving a with-block) ends it.

    Iteration blocks until the next message; after cancel() it stops cleanly (StopIteration). Server errors are
    raised as GraspsimError.
    """

    def __init__(self, call: grpc.Call, convert: Callable[[object], T]):
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

    def __enter__(self):
        return self

    def __exit__(self, *exc) -> None:
        self.cancel()

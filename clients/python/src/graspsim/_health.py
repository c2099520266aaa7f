"""grpc.health.v1 Check by hand (no grpcio-health-checking needed): HealthCheckRequest{} is b"", and SERVING
answers b"\\x08\\x01"."""
import grpc

_CHECK = "/grpc.health.v1.Health/Check"


def serving(address: str, timeout: float = 1.0) -> bool:
    """The server at address (plaintext) answers its whole-server health check with SERVING."""
    try:
        with grpc.insecure_channel(address) as channel:
            check = channel.unary_unary(_CHECK, request_serializer=bytes, response_deserializer=bytes)
            response: bytes = check(b"", timeout=timeout)
            return response == b"\x08\x01"
    except grpc.RpcError:
        return False

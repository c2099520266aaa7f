"""Every method GraspService declares is built (PickAndPlace was the last to answer UNIMPLEMENTED): an empty
request to each unary or server-streaming method answers some other status (bad input named, or an answer)."""
import grpc
import pytest
from google.protobuf import message_factory

from graspsim.v1 import grasp_pb2

SERVICE = grasp_pb2.DESCRIPTOR.services_by_name["GraspService"]


@pytest.mark.parametrize("method", [m.name for m in SERVICE.methods if not m.client_streaming])
def test_grasp_service_methods_are_built(client, method):
    descriptor = SERVICE.methods_by_name[method]
    request = message_factory.GetMessageClass(descriptor.input_type)()
    response = message_factory.GetMessageClass(descriptor.output_type)
    path = f"/{SERVICE.full_name}/{method}"
    if descriptor.server_streaming:
        call = client.channel.unary_stream(path, request_serializer=type(request).SerializeToString,
                                           response_deserializer=response.FromString)
        invoke = lambda: list(call(request, timeout=30))
    else:
        call = client.channel.unary_unary(path, request_serializer=type(request).SerializeToString,
                                          response_deserializer=response.FromString)
        invoke = lambda: call(request, timeout=30)
    try:
        invoke()
    except grpc.RpcError as err:
        assert err.code() != grpc.StatusCode.UNIMPLEMENTED, f"{method}: {err.details()}"
        assert err.details(), f"{method}: {err.code()} without a message"

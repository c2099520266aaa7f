"""Declared but not yet implemented: these methods answer UNIMPLEMENTED, with a message."""
import grpc
import pytest

from graspsim.v1 import grasp_pb2, grasp_pb2_grpc

CALLS = {
    "GraspService.PickAndPlace": lambda ch: list(grasp_pb2_grpc.GraspServiceStub(ch).PickAndPlace(
        grasp_pb2.PickAndPlaceRequest(scene_id="s", arm_id="a"), timeout=10)),
}


@pytest.mark.parametrize("method", list(CALLS))
def test_other_services_are_unimplemented(client, method):
    with pytest.raises(grpc.RpcError) as info:
        CALLS[method](client.channel)
    assert info.value.code() == grpc.StatusCode.UNIMPLEMENTED
    assert info.value.details(), f"{method}: UNIMPLEMENTED without a message"


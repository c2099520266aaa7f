"""A shape completion added to a recorded scene: what the camera saw is in the recording as a Foxglove PointCloud
(decoded by the independent foxglove-schemas-protobuf classes) and in its ROS 2 bag as a sensor_msgs/PointCloud2
(read by rosbags), point for point; the completed object arrives as an edit, so a replay has it."""
from pathlib import Path

import numpy as np
from foxglove_schemas_protobuf.PointCloud_pb2 import PointCloud
from mcap.reader import make_reader
from rosbags.highlevel import AnyReader
from rosbags.typesys import Stores, get_typestore

from graspsim.testing import partial_view

from _support import VIEW_INTRINSICS, cylinder_view

TOPIC = "/completion/points"


def seen_points():
    """The cylinder of _support.cylinder_view: its camera pose and its seen points, world."""
    camera, depth, mask = cylinder_view()
    return camera, partial_view.depth_to_points(depth, camera, *VIEW_INTRINSICS, mask=mask)


def test_completion_input_is_recorded_as_point_clouds(client):
    scene = client.create_scene("recorded completion").id
    camera, points = seen_points()
    with client.record(scene, name="completion.mcap") as info:
        shape = client.complete_shape(camera, points=points, orientations=1, add_to_scene_id=scene,
                                      object_name="seen")
    assert shape.body_id == "seen"
    expected = points.astype(np.float32)

    with open(info.path, "rb") as f:
        clouds = [(channel, message) for _, channel, message in make_reader(f).iter_messages(topics=[TOPIC])]
    assert len(clouds) == 1
    channel, message = clouds[0]
    assert channel.message_encoding == "protobuf"
    cloud = PointCloud.FromString(message.data)
    assert cloud.frame_id == "world" and cloud.point_stride == 12
    assert [(f.name, f.offset, f.type) for f in cloud.fields] == [("x", 0, 7), ("y", 4, 7), ("z", 8, 7)]
    np.testing.assert_array_equal(np.frombuffer(cloud.data, dtype="<f4").reshape(-1, 3), expected)

    typestore = get_typestore(Stores.ROS2_HUMBLE)
    with AnyReader([Path(info.ros2_path)], default_typestore=typestore) as reader:
        connections = [c for c in reader.connections if c.topic == TOPIC]
        assert [c.msgtype for c in connections] == ["sensor_msgs/msg/PointCloud2"]
        messages = [reader.deserialize(raw, c.msgtype) for c, _, raw in reader.messages(connections=connections)]
    assert len(messages) == 1
    ros_cloud = messages[0]
    assert ros_cloud.header.frame_id == "world" and ros_cloud.height == 1 and ros_cloud.width == len(points)
    assert [(f.name, f.offset, f.datatype, f.count) for f in ros_cloud.fields] == [
        ("x", 0, 7, 1), ("y", 4, 7, 1), ("z", 8, 7, 1)]
    assert not ros_cloud.is_bigendian and ros_cloud.point_step == 12 and ros_cloud.is_dense
    np.testing.assert_array_equal(np.frombuffer(ros_cloud.data.tobytes(), dtype="<f4").reshape(-1, 3), expected)

    # The completed object is an edit of the scene: the replay's last frame has it where the scene has it.
    replay = client.replay_recording(info.name)
    client.seek_replay(replay.scene_id, info.name, len(replay.frame_times) - 1)
    assert "seen" in client.get_body_poses(replay.scene_id)
    np.testing.assert_array_equal(client.get_body_poses(replay.scene_id, ["seen"])["seen"].position,
                                  client.get_body_poses(scene, ["seen"])["seen"].position)

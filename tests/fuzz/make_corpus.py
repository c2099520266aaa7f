#!/usr/bin/env python3
"""Writes the seed corpora of tests/fuzz/corpus/<target>/ (small real inputs; docs/fuzzing.md).

Re-run after changing it: python3 tests/fuzz/make_corpus.py. Deterministic: the same files every time.
Protobuf messages are encoded by hand (a few fields each) so this needs nothing beyond Python.
"""
import hashlib
import pathlib
import shutil
import struct

ROOT = pathlib.Path(__file__).resolve().parents[2]
CORPUS = ROOT / "tests" / "fuzz" / "corpus"


def write(target, name, data):
    d = CORPUS / target
    d.mkdir(parents=True, exist_ok=True)
    (d / name).write_bytes(data if isinstance(data, bytes) else data.encode())


# --- protobuf wire format -------------------------------------------------------------------------------------
def varint(n):
    out = bytearray()
    while True:
        b = n & 0x7F
        n >>= 7
        out.append(b | (0x80 if n else 0))
        if not n:
            return bytes(out)


def f_varint(field, n):
    return varint(field << 3) + varint(n)


def f_double(field, x):
    return varint(field << 3 | 1) + struct.pack("<d", x)


def f_bytes(field, b):
    b = b.encode() if isinstance(b, str) else b
    return varint(field << 3 | 2) + varint(len(b)) + b


def vec3(x, y, z):
    return f_double(1, x) + f_double(2, y) + f_double(3, z)


def pose(position, wxyz=(1, 0, 0, 0)):
    q = b"".join(f_double(i + 1, v) for i, v in enumerate(wxyz))
    return f_bytes(1, vec3(*position)) + f_bytes(2, q)


def floats(values):
    return struct.pack("<%df" % len(values), *values)


# --- meshes ---------------------------------------------------------------------------------------------------
TETRA = [((0, 0, 0), (0, 1, 0), (1, 0, 0)), ((0, 0, 0), (1, 0, 0), (0, 0, 1)),
         ((0, 0, 0), (0, 0, 1), (0, 1, 0)), ((1, 0, 0), (0, 1, 0), (0, 0, 1))]


def stl_ascii():
    s = "solid t\n"
    for tri in TETRA:
        s += " facet normal 0 0 0\n  outer loop\n"
        s += "".join("   vertex %g %g %g\n" % v for v in tri)
        s += "  endloop\n endfacet\n"
    return s + "endsolid t\n"


def stl_binary():
    out = b"\0" * 80 + struct.pack("<I", len(TETRA))
    for tri in TETRA:
        out += floats([0, 0, 0] + [c for v in tri for c in v]) + b"\0\0"
    return out


OBJ = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n"
PLY_ASCII = ("ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
             "element face 4\nproperty list uchar int vertex_indices\nend_header\n"
             "0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n")
PLY_BINARY = ("ply\nformat binary_little_endian 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
              "property float z\nelement face 4\nproperty list uchar int vertex_indices\nend_header\n").encode() + \
    floats([0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1]) + \
    b"".join(bytes([3]) + struct.pack("<3i", *f) for f in [(0, 2, 1), (0, 1, 3), (0, 3, 2), (1, 2, 3)])
DAE = """<?xml version="1.0" encoding="utf-8"?>
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
 <asset><unit name="meter" meter="1"/><up_axis>Z_UP</up_axis></asset>
 <library_geometries><geometry id="g"><mesh>
  <source id="p"><float_array id="pa" count="12">0 0 0 1 0 0 0 1 0 0 0 1</float_array>
   <technique_common><accessor source="#pa" count="4" stride="3"><param name="X" type="float"/>
    <param name="Y" type="float"/><param name="Z" type="float"/></accessor></technique_common></source>
  <vertices id="v"><input semantic="POSITION" source="#p"/></vertices>
  <triangles count="4"><input semantic="VERTEX" source="#v" offset="0"/><p>0 2 1 0 1 3 0 3 2 1 2 3</p></triangles>
 </mesh></geometry></library_geometries>
 <library_visual_scenes><visual_scene id="s"><node id="n"><instance_geometry url="#g"/></node></visual_scene>
 </library_visual_scenes>
 <scene><instance_visual_scene url="#s"/></scene>
</COLLADA>
"""

URDF_MESH = """<?xml version="1.0"?>
<robot name="tetra_arm">
  <link name="base">
    <inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><geometry><mesh filename="package://fuzz/meshes/tetra.stl" scale="0.1 0.1 0.1"/></geometry></collision>
  </link>
  <link name="finger">
    <inertial><mass value="0.1"/><inertia ixx="0.001" iyy="0.001" izz="0.001" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><origin xyz="0 0 0.05"/><geometry><box size="0.01 0.02 0.1"/></geometry></collision>
  </link>
  <link name="mirror">
    <inertial><mass value="0.1"/><inertia ixx="0.001" iyy="0.001" izz="0.001" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><geometry><cylinder radius="0.01" length="0.05"/></geometry></collision>
  </link>
  <joint name="slide" type="prismatic"><parent link="base"/><child link="finger"/><axis xyz="1 0 0"/>
    <limit lower="0" upper="0.03" effort="100" velocity="0.1"/></joint>
  <joint name="mimic" type="revolute"><parent link="base"/><child link="mirror"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/><mimic joint="slide" multiplier="-1" offset="0"/></joint>
</robot>
"""


def meshes():
    write("mesh", "tetra_ascii.stl", b"\0" + stl_ascii().encode())
    write("mesh", "tetra_binary.stl", b"\0" + stl_binary())
    write("mesh", "tetra.obj", b"\1" + OBJ.encode())
    write("mesh", "tetra_ascii.ply", b"\2" + PLY_ASCII.encode())
    write("mesh", "tetra_binary.ply", b"\2" + PLY_BINARY)
    write("mesh", "tetra.dae", b"\3" + DAE.encode())


# What the import repairs (docs/import.md): zero masses, an unphysical tensor, PyBullet's plane, a capsule, a
# spherical joint, a limit with lower above upper, numbers PyBullet's parser reads liberally, a name with a space.
URDF_REPAIRS = """<?xml version="1.0"?>
<robot name="repairs">
  <link name="world base"><inertial><mass value="0"/><inertia ixx="0" ixy="0" ixz="0" iyy="0" iyz="0" izz="0"/>
    </inertial><collision><geometry><plane normal="0 0 1"/></geometry></collision></link>
  <link name="arm"><inertial><mass value="1"/><inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0"/></inertial>
    <collision><geometry><capsule radius="0.05" length="0.3"/></geometry></collision></link>
  <link name="tip"><inertial><mass value="0"/><inertia ixx="0" ixy="0" ixz="0" iyy="0" iyz="0" izz="0"/></inertial>
    <collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision></link>
  <link name="head"><collision><geometry><sphere radius="0.1"/></geometry></collision></link>
  <joint name="shoulder" type="revolute"><parent link="world base"/><child link="arm"/><origin xyz="0 0 0.5,"/>
    <limit lower="1" upper="-1"/></joint>
  <joint name="wrist" type="fixed"><parent link="arm"/><child link="tip"/><origin xyz="0 0 0.3 0" rpy="0 0 0"/></joint>
  <joint name="neck" type="spherical"><parent link="tip"/><child link="head"/><limit upper="0.5"/></joint>
</robot>
"""


def urdfs():
    for path in sorted((ROOT / "server" / "models").glob("*.urdf")):
        shutil.copyfile(path, (CORPUS / "urdf").joinpath(path.name))
    write("urdf", "tetra_arm.urdf", URDF_MESH)
    write("urdf", "repairs.urdf", URDF_REPAIRS)


# --- perception -------------------------------------------------------------------------------------------------
def perception():
    camera = pose((0, 0, 0.5), (0, 1, 0, 0))  # looking down from 0.5 m (x by 180 deg: z forward = world -z)
    # A 6 x 5 depth image of a box top 0.45 m away with a mask, and the same without a mask.
    w, h = 6, 5
    depth = [0.45 if 1 <= u <= 4 and 1 <= v <= 3 else 0.0 for v in range(h) for u in range(w)]
    mask = bytes(1 if d > 0 else 0 for d in depth)
    intr = f_varint(1, w) + f_varint(2, h) + f_double(3, 5.0) + f_double(4, 5.0) + f_double(5, 2.5) + f_double(6, 2.0)
    image = f_bytes(1, intr) + f_bytes(2, floats(depth))
    write("perception", "depth_image_masked", b"\0" + f_bytes(1, image + f_bytes(3, mask)) + f_bytes(3, camera))
    write("perception", "depth_image_delaunay",
          b"\0" + f_bytes(1, image) + f_bytes(3, camera) + f_varint(10, 1) + f_varint(5, 3) + f_double(12, 0.005) +
          f_bytes(4, pose((0, 0, 0))))
    # A cloud: the top and one side of a 5 cm cube.
    pts = []
    for i in range(5):
        for j in range(5):
            pts += [-0.025 + 0.0125 * i, -0.025 + 0.0125 * j, 0.05]
            pts += [-0.025 + 0.0125 * i, -0.025, 0.0125 * j]
    write("perception", "cloud", b"\0" + f_bytes(2, f_bytes(1, floats(pts))) + f_bytes(3, camera))
    # SegmentScene: a table (z = 0, 10 x 10 grid) and a small cluster above it.
    seg = []
    for i in range(10):
        for j in range(10):
            seg += [0.02 * i - 0.1, 0.02 * j - 0.1, 0.0]
    for i in range(4):
        for j in range(4):
            seg += [0.005 * i, 0.005 * j, 0.03]
    write("perception", "segment_scene", b"\1" + f_bytes(1, f_bytes(1, floats(seg))) + f_varint(4, 5))
    write("perception", "segment_scene_params",
          b"\1" + f_bytes(1, f_bytes(1, floats(seg))) + f_double(2, 0.01) + f_double(3, 0.005) + f_varint(4, 3))


# --- uploads ----------------------------------------------------------------------------------------------------
def upload():
    def chunk(header=None, data=b""):
        msg = b""
        if header is not None:
            path, total, sha = header
            msg += f_bytes(1, f_bytes(1, "scene-x") + f_bytes(2, path) + f_varint(3, total) + f_bytes(4, sha))
        if data:
            msg += f_bytes(2, data)
        assert len(msg) < 256
        return bytes([len(msg)]) + msg

    body = stl_ascii().encode()[:200]
    parts = [body[:90], body[90:180], body[180:]]
    sha = hashlib.sha256(body).hexdigest()
    # flags 7: the live scene, the real hash and size (an upload that is stored); 1: as sent (a wrong hash)
    write("upload", "three_chunks", bytes([7]) + chunk(("meshes/a.stl", len(body), sha)) +
          b"".join(chunk(data=p) for p in parts))
    write("upload", "header_with_data", bytes([7]) + chunk(("b.obj", 0, "0" * 64), OBJ.encode()[:60]))
    write("upload", "wrong_hash", bytes([1]) + chunk(("c.ply", 16, "a" * 64)) + chunk(data=b"0123456789abcdef"))
    write("upload", "cancelled", bytes([15]) + chunk(("d.stl", 10, "0" * 64)) + chunk(data=b"01234"))
    write("upload", "no_header", bytes([0]) + chunk(data=b"data before any header"))


# --- HTTP/JSON --------------------------------------------------------------------------------------------------
def methods():
    order = ["scene", "perception", "grasp", "tactile", "gateway", "auth"]
    names = []
    for f in order:
        service = None
        for line in (ROOT / "proto" / "graspsim" / "v1" / (f + ".proto")).read_text().splitlines():
            line = line.strip()
            if line.startswith("service "):
                service = line.split()[1]
            elif line.startswith("rpc ") and service:
                names.append(service + "/" + line.split()[1].split("(")[0])
    return names


def http_json():
    m = methods()
    idx = lambda name: m.index(name)
    json, form, none = 0, 1, 2
    write("http_json", "create_scene", bytes([idx("SceneService/CreateScene"), json]) + b'{"name": "web"}')
    write("http_json", "create_scene_form", bytes([idx("SceneService/CreateScene"), form]) +
          b"payload=%7B%22name%22%3A+%22octave%22%7D&x=1")
    write("http_json", "watch_scene", bytes([idx("SceneService/WatchScene"), none]) + b'{"scene_id": "scene-1"}')
    write("http_json", "upload_stream", bytes([idx("SceneService/UploadFile"), json]) +
          b'[{"header": {"scene_id": "scene-1", "path": "a.stl", "total_size": "4", "sha256": "00"}},'
          b' {"data": "AAECAw=="}]')
    write("http_json", "add_object", bytes([idx("SceneService/AddObject"), json]) +
          b'{"scene_id": "scene-1", "name": "cube", "geometry": {"box": {"size": {"x": 0.05, "y": 0.05, "z": 0.05}}},'
          b' "pose": {"position": {"x": 0, "y": 0, "z": 0.8}, "orientation": {"w": 1}}}')
    write("http_json", "complete_shape", bytes([idx("PerceptionService/CompleteShape"), json]) +
          b'{"cloud": {"points": "AACAPwAAAEAAAEBA"}, "camera_pose": {"position": {"z": 1}}, "method": "COMPLETION_METHOD_DELAUNAY"}')
    write("http_json", "empty_body", bytes([idx("SceneService/ListScenes"), json]))
    write("http_json", "find_method", bytes([0, 3]) + b"graspsim.v1.SceneService/GetScene")
    write("http_json", "count", bytes([0, 3]) + b"25")
    write("http_json", "seconds", bytes([0, 3]) + b"1.5e-1")


# --- gateway frames ---------------------------------------------------------------------------------------------
def crc16(data):
    crc = 0xFFFF
    for b in data:
        crc ^= b
        for _ in range(8):
            crc = (crc >> 1) ^ 0xA001 if crc & 1 else crc >> 1
    return crc


def rtu(unit, pdu):
    frame = bytes([unit]) + pdu
    c = crc16(frame)
    return frame + bytes([c & 0xFF, c >> 8])


def modbus():
    # The Robotiq manual's example: close at full speed and force (unit 9, write 3 registers at 0x03E8).
    write("modbus", "robotiq_close", bytes([9]) + bytes.fromhex("091003E8000306090000FFFFFF4229"))
    write("modbus", "robotiq_status", bytes([9]) + rtu(9, bytes.fromhex("0306F900000EFF1C")))
    write("modbus", "read_request", bytes([9]) + rtu(9, bytes.fromhex("0307D00003")))
    write("modbus", "exception", bytes([9]) + rtu(9, bytes([0x83, 0x02])))
    write("modbus", "write_answer", bytes([9]) + rtu(9, bytes.fromhex("1003E80003")))
    write("modbus", "bad_crc", bytes([9]) + bytes.fromhex("0903060000000000000000"))


def smp_frames(message):
    """Message → 10-byte fuzz frames (mode 7, dlc, 8 data bytes), fragmented as smp_codec.h describes."""
    def frame(dlc, data):
        return bytes([7, dlc]) + bytes(data).ljust(8, b"\0")
    if len(message) <= 7:
        return frame(1 + len(message), [len(message)] + list(message))
    out = frame(8, [len(message), 0x84] + list(message[:6]))
    rest = message[6:]
    while len(rest) > 6:
        out += frame(8, [len(rest), 0x85] + list(rest[:6]))
        rest = rest[6:]
    return out + frame(2 + len(rest), [len(rest), 0x86] + list(rest))


def smp():
    state = bytes([0x95]) + struct.pack("<3f", 10.0, 0.0, 0.5) + bytes([0x02, 0x00])
    write("smp", "get_state_answer", smp_frames(state))
    write("smp", "move_pos_answer", smp_frames(bytes([0xB0]) + struct.pack("<f", 8.3)))
    write("smp", "ok_and_error", smp_frames(bytes([0x91, 0x4F, 0x4B])) + smp_frames(bytes([0x88, 0xD9])))
    write("smp", "move_pos_profile", smp_frames(bytes([0xB0]) + struct.pack("<4f", 20.0, 50.0, 100.0, 2.0)))
    write("smp", "refusal_then_reached", smp_frames(bytes([0xB5, 0x04])) + smp_frames(bytes([0x94]) + struct.pack("<f", 3.0)))


def device_spec():
    for name, text in [("robotiq_tcp", "robotiq-tcp:127.0.0.1:5020\nmax_speed=0.05,max_force=100"),
                       ("robotiq_rtu", "left=robotiq-rtu:/dev/ttyUSB0\nmin_opening=0.01"),
                       ("pg70_can", "pg70-can:can0:12\nmax_speed=0.02,min_force=40,max_current=1"),
                       ("pg70_fd", "right=pg70-fd:5\n"),
                       ("ipv6", "robotiq-tcp:[::1]:502")]:
        write("device_spec", name, text)


if __name__ == "__main__":
    if CORPUS.exists():
        shutil.rmtree(CORPUS)
    (CORPUS / "urdf").mkdir(parents=True)
    meshes()
    urdfs()
    perception()
    upload()
    http_json()
    modbus()
    smp()
    device_spec()
    for d in sorted(CORPUS.iterdir()):
        print(d.name, len(list(d.iterdir())), "files")

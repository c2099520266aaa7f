"""Build hooks of the graspsim client: the gRPC stubs are generated from the API's .proto files.

The protos import each other as "graspsim/v1/x.proto", so protoc writes graspsim/v1/x_pb2.py, whose imports
("from graspsim.v1 import common_pb2") resolve inside this package: no sys.path tricks are needed.
- regular build (pip install clients/python): stubs go into build_lib, the source tree stays clean;
- editable build (pip install -e): stubs go into src/graspsim/v1 (git-ignored), where the editable import finds them;
- sdist: the protos are copied into the archive (proto/graspsim/v1), since ../../proto is outside this directory.
"""
import pathlib
import shutil

from setuptools import setup
from setuptools.command.build_py import build_py
from setuptools.command.sdist import sdist

HERE = pathlib.Path(__file__).parent.resolve()
API = pathlib.Path("graspsim") / "v1"


def proto_root() -> pathlib.Path:
    """The directory holding graspsim/v1/*.proto: a copy inside an sdist, else the repository's proto/."""
    for root in (HERE / "proto", HERE.parent.parent / "proto"):
        if (root / API).is_dir():
            return root
    raise RuntimeError(f"graspsim: no {API}/*.proto under {HERE / 'proto'} or {HERE.parent.parent / 'proto'}")


def generate_stubs(out_dir: pathlib.Path) -> None:
    """Runs grpc_tools.protoc on every API proto, writing *_pb2.py, *_pb2.pyi and *_pb2_grpc.py under out_dir."""
    import grpc_tools
    from grpc_tools import protoc

    root = proto_root()
    protos = sorted(str(p) for p in (root / API).glob("*.proto"))
    well_known = pathlib.Path(grpc_tools.__file__).parent / "_proto"
    (out_dir / API).mkdir(parents=True, exist_ok=True)
    out = str(out_dir)
    args = ["grpc_tools.protoc", f"-I{root}", f"-I{well_known}",
            f"--python_out={out}", f"--pyi_out={out}", f"--grpc_python_out={out}", *protos]
    if protoc.main(args) != 0:
        raise RuntimeError(f"graspsim: protoc failed on {protos}")


class BuildPyWithStubs(build_py):
    """build_py that generates the gRPC stubs first."""

    def run(self):
        if self.editable_mode:
            generate_stubs(HERE / "src")
            super().run()
        else:
            super().run()
            generate_stubs(pathlib.Path(self.build_lib))


class SdistWithProtos(sdist):
    """sdist that carries the API protos, so that the archive builds away from the repository."""

    def make_release_tree(self, base_dir, files):
        super().make_release_tree(base_dir, files)
        target = pathlib.Path(base_dir) / "proto" / API
        target.mkdir(parents=True, exist_ok=True)
        for proto in (proto_root() / API).glob("*.proto"):
            shutil.copyfile(proto, target / proto.name)


setup(cmdclass={"build_py": BuildPyWithStubs, "sdist": SdistWithProtos})

"""Grasp planning results as numpy structured arrays (GraspService.PlanGrasps / GetGraspSet / EvaluateGrasp), and
the GraspCandidate that evaluate_grasp simulates."""
from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Dict, List, Optional, Sequence, Tuple, Union

import numpy as np
from numpy.typing import ArrayLike, NDArray

from graspsim._equality import ValueEquality
from graspsim._ids import BodyLike, SceneLike, body_id_of, scene_id_of
from graspsim.v1 import common_pb2, grasp_pb2

# an object given as a mesh: (vertices (n, 3) m, triangles (m, 3) vertex indices)
MeshLike = Tuple[ArrayLike, ArrayLike]
# {(material_a, material_b): μ} or a sequence of (material_a, material_b, μ)
FrictionPairs = Union[Dict[Tuple[str, str], float], Sequence[Tuple[str, str, float]]]


def grasp_dtype(joint_count: int) -> np.dtype[np.void]:
    """One row per grasp; every vector in the object's frame (m, unit directions, quaternion w x y z)."""
    return np.dtype([
        ("candidate_index", np.uint32), ("outcome", "U9"), ("preshape", "U16"),
        ("approach", np.float64, 3), ("target", np.float64, 3), ("reference", np.float64, 3),
        ("roll", np.float64), ("standoff", np.float64),
        ("hand_pose", np.float64, 7), ("joint_positions", np.float64, max(joint_count, 0)),
        ("epsilon", np.float64), ("volume", np.float64), ("force_closure", np.bool_), ("contact_count", np.uint32),
    ])


CONTACT_DTYPE = np.dtype([("grasp", np.uint32), ("point", np.float64, 3), ("normal", np.float64, 3),
                          ("link", "U64")])


def _vec(v: common_pb2.Vec3) -> List[float]:
    return [v.x, v.y, v.z]


def _pose(p: common_pb2.Pose) -> List[float]:
    q = p.orientation
    return _vec(p.position) + ([q.w, q.x, q.y, q.z] if p.HasField("orientation") else [1.0, 0.0, 0.0, 0.0])


def grasps_to_arrays(grasps: Sequence[grasp_pb2.Grasp], joint_count: int) -> Tuple[NDArray[np.void], NDArray[np.void]]:
    """(grasps, contacts): structured arrays; contacts["grasp"] indexes rows of grasps."""
    rows = np.zeros(len(grasps), dtype=grasp_dtype(joint_count))
    contacts = np.zeros(sum(len(g.contacts) for g in grasps), dtype=CONTACT_DTYPE)
    k = 0
    for i, g in enumerate(grasps):
        c = g.candidate
        rows[i] = (g.candidate_index, g.outcome, c.preshape, _vec(c.approach), _vec(c.target), _vec(c.reference),
                   c.roll, c.standoff, _pose(g.hand_pose), list(g.joint_positions)[:joint_count] +
                   [0.0] * max(0, joint_count - len(g.joint_positions)), g.epsilon, g.volume, g.force_closure,
                   len(g.contacts))
        for contact in g.contacts:
            contacts[k] = (i, _vec(contact.point), _vec(contact.normal), contact.link)
            k += 1
    return rows, contacts


@dataclass
class GraspSetResult:
    """A planned (or stored) grasp set: the force-closure grasps, best ε first, and the run's counts."""
    set_id: str
    hand: str
    mesh_sha256: str
    from_store: bool
    candidates: int
    missed: int
    collisions: int
    simulated: int
    force_closure: int
    seconds: float          # s, simulating and scoring every candidate when the set was planned
    joint_ids: List[str]
    preshapes: List[str]
    params: str
    grasps: NDArray[np.void]    # grasp_dtype(len(joint_ids))
    contacts: NDArray[np.void]  # CONTACT_DTYPE
    cpu_seconds: float = 0.0  # s, the planner threads' CPU time over `seconds` (0 when from the store)

    @classmethod
    def from_proto(cls, message: grasp_pb2.GraspSet) -> "GraspSetResult":
        grasps, contacts = grasps_to_arrays(message.grasps, len(message.joint_ids))
        return cls(message.set_id, message.hand, message.mesh_sha256, message.from_store, message.candidates,
                   message.missed, message.collisions, message.simulated, message.force_closure, message.seconds,
                   list(message.joint_ids), list(message.preshapes), message.params, grasps, contacts,
                   message.cpu_seconds)

    @property
    def candidates_per_s(self) -> float:
        return self.candidates / self.seconds if self.seconds > 0 else float("inf")


def set_materials(request: Union[grasp_pb2.PlanGraspsRequest, grasp_pb2.EvaluateGraspRequest],
                  object_material: Optional[str], link_materials: Optional[Dict[str, str]],
                  friction_pairs: Optional[FrictionPairs]) -> None:
    """Fills the material fields of a PlanGraspsRequest or EvaluateGraspRequest. friction_pairs: a mapping
    {(material_a, material_b): μ} or a sequence of (material_a, material_b, μ)."""
    if object_material is not None:
        request.object_material = object_material
    for link, material in (link_materials or {}).items():
        request.link_materials[link] = material
    if isinstance(friction_pairs, dict):
        triples: Sequence[Tuple[str, str, float]] = [(a, b, mu) for (a, b), mu in friction_pairs.items()]
    else:
        triples = [(pair[0], pair[1], pair[2]) for pair in (friction_pairs or ())]
    for a, b, mu in triples:
        request.friction_pairs.add(material_a=a, material_b=b, friction=float(mu))


def target_proto(scene_id: Optional[SceneLike], body_id: Optional[BodyLike],
                 mesh: Optional[MeshLike]) -> grasp_pb2.GraspTarget:
    """The object: a scene's body, or a mesh (vertices (n, 3) m, triangles (m, 3) indices)."""
    if mesh is not None:
        vertices, triangles = mesh
        return grasp_pb2.GraspTarget(mesh=common_pb2.MeshData(
            vertices=np.ascontiguousarray(vertices, dtype="<f4").tobytes(),
            triangles=np.ascontiguousarray(triangles, dtype="<u4").tobytes()))
    return grasp_pb2.GraspTarget(scene_id="" if scene_id is None else scene_id_of(scene_id),
                                 body_id="" if body_id is None else body_id_of(body_id))


@dataclass(frozen=True, eq=False)
class GraspCandidate(ValueEquality):
    """A placement of the hand to simulate (evaluate_grasp), in the object's frame.

    Attributes:
        approach: (3,) unit: the direction the hand moves (the hand's +z).
        target: (3,) m: a point of the approach line.
        reference: (3,) unit, perpendicular to approach: the hand's +x at roll 0.
        roll: rad about the approach; standoff: m (0..0.2), backed off after the first contact.
        preshape: one of the hand's pre-shapes ("power", "pinch", "spherical"); "" = its first.
    """

    approach: NDArray[np.float64]
    target: NDArray[np.float64]
    reference: NDArray[np.float64]
    roll: float = 0.0
    standoff: float = 0.0
    preshape: str = ""

    if TYPE_CHECKING:  # the generated __init__ takes any 3 values: __post_init__ makes float64 arrays of them
        def __init__(self, approach: ArrayLike, target: ArrayLike, reference: ArrayLike, roll: float = ...,
                     standoff: float = ..., preshape: str = ...) -> None: ...

    def __post_init__(self) -> None:
        for name in ("approach", "target", "reference"):
            values = np.array(getattr(self, name), dtype=np.float64).reshape(-1)
            if values.shape != (3,):
                raise ValueError(f"GraspCandidate.{name} needs 3 values, got {values.size}")
            object.__setattr__(self, name, values)  # frozen: how __post_init__ may still set a field

    @classmethod
    def from_row(cls, row: np.void) -> GraspCandidate:
        """The candidate of a planned or evaluated grasp (a row of GraspSetResult.grasps, grasp_dtype)."""
        return cls(row["approach"], row["target"], row["reference"], float(row["roll"]), float(row["standoff"]),
                   str(row["preshape"]))

    def to_proto(self) -> grasp_pb2.GraspCandidate:
        def vec(v: NDArray[np.float64]) -> common_pb2.Vec3:
            return common_pb2.Vec3(x=float(v[0]), y=float(v[1]), z=float(v[2]))
        return grasp_pb2.GraspCandidate(approach=vec(self.approach), target=vec(self.target),
                                        reference=vec(self.reference), roll=float(self.roll),
                                        standoff=float(self.standoff), preshape=self.preshape)


# A candidate: a GraspCandidate, or a row of a grasp set (GraspSetResult.grasps[i]) to simulate again.
CandidateLike = Union[GraspCandidate, np.void]


def candidate_proto(candidate: CandidateLike) -> grasp_pb2.GraspCandidate:
    """The GraspCandidate message of a candidate (the generated message itself is taken as it is)."""
    if isinstance(candidate, grasp_pb2.GraspCandidate):
        return candidate
    if isinstance(candidate, np.void):
        candidate = GraspCandidate.from_row(candidate)
    if not isinstance(candidate, GraspCandidate):
        raise TypeError(f"candidate: a GraspCandidate or a row of GraspSetResult.grasps is expected, got "
                        f"{type(candidate).__name__}")
    return candidate.to_proto()

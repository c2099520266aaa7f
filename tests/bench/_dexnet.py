"""Dex-Net's Ferrari–Canny ε, run from graspnetAPI's own source: the grasp bench's independent ε check.

graspnetAPI (PyPI, 1.2.11) carries Dex-Net's grasp quality code (graspnetAPI/utils/dexnet/grasping: contacts.py
builds each contact's friction cone and torques, quality.py the grasp matrix, the hull (pyhull) and the min-norm
QPs (cvxopt)). Its package cannot be installed here: it pins numpy==1.20.3 (no Python 3.11 build, and it would
replace the venv's numpy 2) and pulls open3d, autolab_core, opencv, … So tests/bench/run downloads its sdist
(no dependencies) into build/bench-data, and this module imports those three files from it unchanged, with
stand-ins only for the modules they import but the ε path never calls (plotting, IPython, SDF and mesh classes,
surface-window helpers). Its real dependencies for ε, pyhull and cvxopt, are the client's "ycb" extra.

Dex-Net's conventions against the server's (docs/grasp.md, "Quality"), and how they are matched:
- contact: a point, an outward surface normal (the server reports the inward one: negated here), Coulomb μ, the
  cone linearised by num_cone_faces edges f = n_in + μ (cos θ t1 + sin θ t2), θ = 2πk/m: the server's formula;
- torque: (p − c) × f with c = graspable.moment_arm's reference (Dex-Net: the mesh's centre of mass; here the
  server's area-weighted surface centroid), times params.torque_scaling (Dex-Net's default: 1 / the median of
  the bounding box's max corner; here 1/λ, the server's characteristic length);
- L1 wrench space: the hull of the primitive wrenches, ε the distance from the origin to the nearest facet
  (Dex-Net: min-norm QP per facet), soft_fingers False (no torsion wrench: the server has none);
- the tangent basis (t1, t2) differs and no parameter sets it: Dex-Net takes the SVD of the normal, then turns
  t1 toward the object's x axis (sampled at 1000 angles); the server takes t1 = n × the axis least aligned with
  n. Given `tangents` (the server's rule), epsilon() replaces the one method that chooses them
  (Contact3D.tangents), so everything else is Dex-Net's; without it the cones are Dex-Net's own (rotated about
  each normal).
load() fills sys.modules with those stand-ins: call it in a process of its own (the bench uses worker processes).
"""
import importlib.util
import sys
import types
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[2]
SOURCE = REPO / "build" / "bench-data" / "graspnetAPI-1.2.11" / "graspnetAPI" / "utils" / "dexnet"


def _stub(name, **attrs):
    module = types.ModuleType(name)
    module.__dict__.update(attrs)
    sys.modules[name] = module


def _load(name, path, package_path=None):
    spec = importlib.util.spec_from_file_location(name, path, submodule_search_locations=package_path)
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    spec.loader.exec_module(module)
    return module


def load():
    """(contacts, quality, grasp_quality_config) modules of Dex-Net, from graspnetAPI's sdist."""
    if "dexnet.grasping.quality" in sys.modules:
        return (sys.modules["dexnet.grasping.contacts"], sys.modules["dexnet.grasping.quality"],
                sys.modules["dexnet.grasping.grasp_quality_config"])
    if not (SOURCE / "grasping" / "quality.py").is_file():
        raise FileNotFoundError(f"{SOURCE}: run tests/bench/run grasp, which fetches graspnetAPI's sdist")
    placeholder = type("Placeholder", (), {})
    # Imported at module level by the three files, never called on the ε path.
    for name in ("IPython", "matplotlib", "mpl_toolkits"):
        _stub(name)
    _stub("matplotlib.pyplot")
    _stub("mpl_toolkits.mplot3d", Axes3D=placeholder)
    _stub("skimage")
    _stub("skimage.restoration", denoise_bilateral=None)
    _stub("autolab_core", RigidTransform=placeholder)
    _stub("sklearn")
    _stub("sklearn.decomposition", PCA=placeholder)
    _load("dexnet", SOURCE / "__init__.py", [str(SOURCE)])
    _load("dexnet.grasping", SOURCE / "grasping" / "__init__.py", [str(SOURCE / "grasping")])
    _stub("dexnet.grasping.grasp", PointGrasp=placeholder)
    _stub("dexnet.grasping.graspable_object", GraspableObject3D=placeholder)
    _stub("dexnet.grasping.meshpy")
    _stub("dexnet.grasping.meshpy.mesh")
    _stub("dexnet.grasping.meshpy.sdf")
    _load("dexnet.constants", SOURCE / "constants.py")
    config = _load("dexnet.grasping.grasp_quality_config", SOURCE / "grasping" / "grasp_quality_config.py")
    contacts = _load("dexnet.grasping.contacts", SOURCE / "grasping" / "contacts.py")
    quality = _load("dexnet.grasping.quality", SOURCE / "grasping" / "quality.py")
    return contacts, quality, config


class _SurfacePoint:
    """The graspable object a Dex-Net Contact3D asks for its normal and moment arm: its SDF lookups answer with
    the contact's reported normal (identity grid transform, always on the surface); the torque reference is c."""

    def __init__(self, outward_normal, centroid):
        self.normal, self.centroid = outward_normal, centroid
        self.sdf = self

    def transform_pt_obj_to_grid(self, p, direction=False):
        return p

    transform_pt_grid_to_obj = transform_pt_obj_to_grid

    def on_surface(self, p):
        return True, 0.0

    def surface_normal(self, p):
        return self.normal

    def moment_arm(self, p):
        return p - self.centroid


def epsilon(points, normals, frictions, centroid, length, cone_edges, tangents=None):
    """Dex-Net's ferrari_canny_L1 of contacts (points (n, 3) m, inward unit normals (n, 3), μ per contact), torque
    reference `centroid`, torques scaled by 1/`length`. tangents(n) -> (t1, t2): the server's basis for inward
    normal n, replacing Dex-Net's (None: Dex-Net's own)."""
    contacts_module, quality, config_module = load()
    forces, torques, inward = np.zeros((3, 0)), np.zeros((3, 0)), np.zeros((3, 0))
    for p, n, mu in zip(points, normals, frictions):
        contact = contacts_module.Contact3D(_SurfacePoint(-np.asarray(n, float), np.asarray(centroid, float)),
                                            np.asarray(p, float))
        if tangents is not None:
            contact.tangents = lambda direction=None, align_axes=True, n=np.asarray(n, float): (n, *tangents(n))
        ok, cone, outward = contact.friction_cone(cone_edges, mu)
        ok_torque, contact_torques = contact.torques(cone)
        assert ok and ok_torque
        scale = contact.normal_force_magnitude()  # 1: no approach direction given, as in Dex-Net's grasp_quality
        forces = np.c_[forces, scale * cone]
        torques = np.c_[torques, scale * contact_torques]
        inward = np.c_[inward, scale * -outward]
    params = config_module.QuasiStaticGraspQualityConfig({
        # friction_coef serves only the soft-finger torsion (off); each cone above took its contact's μ
        "quality_method": "ferrari_canny_L1", "friction_coef": float(np.mean(frictions)),
        "num_cone_faces": cone_edges, "soft_fingers": False, "quality_type": "quasi_static",
        "check_approach": False, "all_contacts_required": True, "torque_scaling": 1.0 / length})
    # pyhull writes the points with repr(): numpy 2's np.float64 repr ("np.float64(0.1)") would reach qhull as
    # text it cannot parse (no hull, ε 0); numpy's 1.25 print mode restores plain numbers.
    with np.printoptions(legacy="1.25"):
        return quality.PointGraspMetrics3D.ferrari_canny_L1(forces, torques, inward, soft_fingers=False,
                                                            params=params)
